#pragma once
// Every registered object declares its parameters here: name, type, required or default,
// allowed range, unit and a one-line doc. The same schema drives validation of the scene,
// `frostmpm describe` and the generated config reference.
#include <map>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"

namespace frostmpm {

enum class ParamType { Real, Integer, Boolean, String, Choice, RealList };
std::string to_string(ParamType type);

using ParamValue = std::variant<double, long, bool, std::string, std::vector<double>>;

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::Real;
  /// Of a Real or RealList: a UDUNITS-2 unit (absolute temperatures "degC", differences "K"),
  /// "-" for a pure number; values given with another unit are converted to it (units.hpp).
  std::string unit;
  std::string doc;
  std::optional<ParamValue> default_value;  ///< empty: required (unless optional_meaning is set)
  /// Set by optional(): the parameter may be left out and then has no value at all (ParamSet::has
  /// is false); the text says what the model does without it ("the peak value").
  std::string optional_meaning;
  std::optional<double> lower, upper;
  bool lower_open = false, upper_open = false;
  std::vector<std::string> choices;  ///< for Choice
  std::size_t list_size = 0;         ///< for RealList; 0 = any length

  bool required() const { return !default_value.has_value() && optional_meaning.empty(); }

  // Fluent setters used by schema declarations.
  // Defaults are stored in the parameter's own type: `defaults_to(0)` on a real is 0.0, and a
  // string literal can never turn into the bool alternative.
  ParamSpec& defaults_to(double value);
  ParamSpec& defaults_to(int value) { return defaults_to(static_cast<double>(value)); }
  ParamSpec& defaults_to(long value) { return defaults_to(static_cast<double>(value)); }
  ParamSpec& defaults_to(bool value);
  ParamSpec& defaults_to(const char* text) { return defaults_to(std::string(text)); }
  ParamSpec& defaults_to(std::string text);
  ParamSpec& defaults_to(std::vector<double> values);
  ParamSpec& at_least(double v) { lower = v; lower_open = false; return *this; }
  ParamSpec& above(double v) { lower = v; lower_open = true; return *this; }
  ParamSpec& at_most(double v) { upper = v; upper_open = false; return *this; }
  ParamSpec& below(double v) { upper = v; upper_open = true; return *this; }
  ParamSpec& size(std::size_t n) { list_size = n; return *this; }
  /// Optional with no default value: left out, the model falls back on `meaning` itself (a
  /// residual strength that is the peak one unless given).
  ParamSpec& optional(std::string meaning) { optional_meaning = std::move(meaning); return *this; }

  /// Whether `v` lies within the declared bounds (always, when unbounded).
  bool in_range(double v) const;
  /// "(0, 1]" style text for docs and messages; "" when unbounded.
  std::string range_text() const;
  /// Default as YAML text, "optional: <meaning>", or "required".
  std::string default_text() const;
};

class ParamSchema {
 public:
  ParamSpec& real(const std::string& name, const std::string& unit, const std::string& doc);
  ParamSpec& integer(const std::string& name, const std::string& doc);
  ParamSpec& boolean(const std::string& name, const std::string& doc);
  ParamSpec& string(const std::string& name, const std::string& doc);
  ParamSpec& choice(const std::string& name, std::vector<std::string> choices, const std::string& doc);
  ParamSpec& reals(const std::string& name, const std::string& unit, const std::string& doc);

  const std::vector<ParamSpec>& params() const { return params_; }
  const ParamSpec* find(const std::string& name) const;
  std::vector<std::string> names() const;
  /// Throws an InputError for the first default outside its own parameter's range (or not one
  /// of its choices), naming `owner` (e.g. "sfcc model 'x'"), the parameter, default and range.
  /// Checked at registration: the fluent setters may give the default before the bounds.
  void check_defaults(const std::string& owner) const;

 private:
  ParamSpec& add(ParamSpec spec);
  std::vector<ParamSpec> params_;
};

/// Validated parameter values (defaults filled in), each remembering where it came from.
class ParamSet {
 public:
  double real(const std::string& name) const;
  long integer(const std::string& name) const;
  bool boolean(const std::string& name) const;
  const std::string& string(const std::string& name) const;
  const std::vector<double>& reals(const std::string& name) const;
  bool has(const std::string& name) const { return values_.count(name) != 0; }
  /// True when the scene gave the value (false: the schema's default filled it in).
  bool given(const std::string& name) const { return values_.count(name) != 0 && !defaulted_.count(name); }

  SourceLocation where(const std::string& name) const;
  /// Error about one parameter (cross-parameter checks in a model's constructor use this).
  InputError error(const std::string& name, const std::string& message) const;
  /// Where the section itself was given (set by parse_params), for an error about the section as
  /// a whole (a physics missing a boundary condition it needs).
  const SourceLocation& section() const { return section_; }
  InputError section_error(const std::string& message) const { return InputError(section_, message); }
  void set_section(SourceLocation where) { section_ = std::move(where); }

  /// The resolved values as YAML, in schema order (for `frostmpm check` and run.json).
  YAML::Node to_yaml() const;

  void set(const std::string& name, ParamValue value, SourceLocation where);
  /// The schema's default, at the section's location.
  void set_default(const std::string& name, ParamValue value, SourceLocation where);

 private:
  std::vector<std::string> order_;
  std::map<std::string, ParamValue> values_;
  std::map<std::string, SourceLocation> where_;
  std::set<std::string> defaulted_;
  SourceLocation section_;
  const ParamValue& get(const std::string& name) const;
};

/// Reads every schema parameter from `node`, checks types and ranges, fills defaults, and
/// rejects unknown keys (keys listed in `also_allowed` are left for the caller).
ParamSet parse_params(const ParamSchema& schema, const ConfigNode& node,
                      const std::vector<std::string>& also_allowed = {});

YAML::Node to_yaml(const ParamValue& value);

/// A number as messages print it: shortest form, `precision` significant digits.
std::string number_text(double v, int precision = 12);

}  // namespace frostmpm
