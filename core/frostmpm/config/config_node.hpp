#pragma once
// Strict view over a YAML scene: every key read is marked consumed, and finish() rejects the
// rest with the closest valid name. All conversions report the YAML path and line on failure.
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/input_error.hpp"

namespace frostmpm {

class ConfigNode {
 public:
  ConfigNode(YAML::Node node, std::string file, std::string path = "");

  /// Parses a scene file; a missing file, one that is not a regular file or is over 16 MB,
  /// malformed YAML and a key given twice in one mapping are InputErrors.
  static ConfigNode load_file(const std::string& file);
  /// The text of a scene file; an InputError when it is missing or cannot be read.
  static std::string read_file(const std::string& file);
  static ConfigNode load_string(const std::string& text, const std::string& name = "<string>");

  /// The `--set PATH=VALUE` assignments applied to this tree (apply_override), in order:
  /// errors in a value that came from one name it ("--set time.dt=abc: at 'time.dt': ...")
  /// instead of a line of the scene file. Children inherit them.
  void set_overrides(std::vector<std::string> assignments);

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  SourceLocation where() const;
  InputError error(const std::string& message) const { return InputError(where(), message); }

  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }
  bool is_null() const { return !node_ || node_.IsNull(); }

  // ---- maps (keys read here count as consumed) ----
  bool has(const std::string& key) const;
  ConfigNode child(const std::string& key) const;  ///< required key
  std::optional<ConfigNode> optional_child(const std::string& key) const;
  std::vector<std::string> keys() const;
  /// Throws for the first key nobody read, naming the closest entry of `valid_keys`.
  void finish(const std::vector<std::string>& valid_keys) const;
  /// Throws for the first key not in `valid_keys`, read or not (a typo reported before the
  /// "missing parameter" it causes).
  void reject_unknown(const std::vector<std::string>& valid_keys) const;

  // ---- sequences ----
  std::vector<ConfigNode> elements() const;

  // ---- scalars ----
  /// A number in `unit` (a UDUNITS-2 unit, "-" for a pure number, "" for a bare number only;
  /// see units.hpp). A bare number is taken as given, in `unit`; "<number> <unit>" ("90 d",
  /// "-2 degC") is converted to `unit`, and then replaced in the scene tree by that number, so
  /// that what copies the tree afterwards (the resolved scene of `check` and run.json) holds the
  /// declared unit's numbers.
  double as_real(const std::string& unit) const;
  long as_integer() const;
  bool as_bool() const;
  std::string as_string() const;
  /// One number or a list of numbers, each as_real(unit).
  std::vector<double> as_reals(const std::string& unit) const;
  /// A list of exactly `units.size()` numbers, element i in units[i] (a table row [time, value]);
  /// `what` names the row in the error about its length ("a row [time, value]").
  std::vector<double> as_row(const std::vector<std::string>& units, const std::string& what) const;

  const YAML::Node& raw() const { return node_; }

 private:
  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::shared_ptr<std::set<std::string>> consumed_;
  std::shared_ptr<std::set<std::string>> asked_;  ///< keys has() was asked about: valid here
  std::shared_ptr<const std::vector<std::string>> overrides_;

  ConfigNode with(YAML::Node node, std::string path) const;  ///< a child sharing file and overrides
  std::string child_path(const std::string& key) const;
};

/// Applies "a.b.c=value" to a scene tree. The parent of the leaf must exist (a list index
/// is a number: "regions.0.material"); a wrong path is an InputError listing valid keys.
void apply_override(YAML::Node& root, const std::string& assignment);

}  // namespace frostmpm
