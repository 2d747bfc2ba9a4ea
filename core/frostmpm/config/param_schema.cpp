#include "frostmpm/config/param_schema.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

namespace frostmpm {

std::string to_string(ParamType type) {
  switch (type) {
    case ParamType::Real: return "real";
    case ParamType::Integer: return "integer";
    case ParamType::Boolean: return "boolean";
    case ParamType::String: return "string";
    case ParamType::Choice: return "choice";
    case ParamType::RealList: return "list of reals";
  }
  return "?";
}

std::string number_text(double v, int precision) {
  std::ostringstream os;
  os.precision(precision);
  os << v;
  return os.str();
}

namespace {
/// Shortest text that reads back as the same double ("1e-12", "0.6", "86400"); YAML's .inf
/// and .nan for the rest.
YAML::Node real_node(double v) {
  if (!std::isfinite(v)) return YAML::Node(v);
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return YAML::Node(std::string(buf, result.ptr));
}
}  // namespace

YAML::Node to_yaml(const ParamValue& value) {
  YAML::Node node;
  std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::vector<double>>) {
          node = YAML::Node(YAML::NodeType::Sequence);
          for (double x : v) node.push_back(real_node(x));
          node.SetStyle(YAML::EmitterStyle::Flow);
        } else if constexpr (std::is_same_v<T, double>) {
          node = real_node(v);
        } else {
          node = v;
        }
      },
      value);
  return node;
}

ParamSpec& ParamSpec::defaults_to(double value) {
  if (type == ParamType::Integer) default_value = static_cast<long>(value);
  else if (type == ParamType::Real) default_value = value;
  else throw std::logic_error("parameter '" + name + "' is not numeric; its default cannot be a number");
  return *this;
}
ParamSpec& ParamSpec::defaults_to(bool value) {
  if (type != ParamType::Boolean) throw std::logic_error("parameter '" + name + "' is not a boolean");
  default_value = value;
  return *this;
}
ParamSpec& ParamSpec::defaults_to(std::string text) {
  if (type != ParamType::String && type != ParamType::Choice)
    throw std::logic_error("parameter '" + name + "' does not take text");
  default_value = std::move(text);
  return *this;
}
ParamSpec& ParamSpec::defaults_to(std::vector<double> values) {
  if (type != ParamType::RealList) throw std::logic_error("parameter '" + name + "' is not a list");
  default_value = std::move(values);
  return *this;
}

bool ParamSpec::in_range(double v) const {
  const bool low_bad = lower && (lower_open ? v <= *lower : v < *lower);
  const bool high_bad = upper && (upper_open ? v >= *upper : v > *upper);
  return !low_bad && !high_bad && !std::isnan(v);
}

std::string ParamSpec::range_text() const {
  if (!lower && !upper) return "";
  std::string out = lower ? (lower_open ? "(" : "[") + number_text(*lower) : "(-inf";
  out += ", ";
  out += upper ? number_text(*upper) + (upper_open ? ")" : "]") : "inf)";
  return out;
}

std::string ParamSpec::default_text() const {
  if (!default_value) return optional_meaning.empty() ? "required" : "optional: " + optional_meaning;
  YAML::Emitter out;
  out << to_yaml(*default_value);
  return out.c_str();
}

ParamSpec& ParamSchema::add(ParamSpec spec) {
  for (const auto& p : params_)
    if (p.name == spec.name) throw std::logic_error("schema declares '" + spec.name + "' twice");
  params_.push_back(std::move(spec));
  return params_.back();
}

ParamSpec& ParamSchema::real(const std::string& name, const std::string& unit, const std::string& doc) {
  return add(ParamSpec{name, ParamType::Real, unit, doc});
}
ParamSpec& ParamSchema::integer(const std::string& name, const std::string& doc) {
  return add(ParamSpec{name, ParamType::Integer, "", doc});
}
ParamSpec& ParamSchema::boolean(const std::string& name, const std::string& doc) {
  return add(ParamSpec{name, ParamType::Boolean, "", doc});
}
ParamSpec& ParamSchema::string(const std::string& name, const std::string& doc) {
  return add(ParamSpec{name, ParamType::String, "", doc});
}
ParamSpec& ParamSchema::choice(const std::string& name, std::vector<std::string> choices,
                               const std::string& doc) {
  ParamSpec spec{name, ParamType::Choice, "", doc};
  spec.choices = std::move(choices);
  return add(std::move(spec));
}
ParamSpec& ParamSchema::reals(const std::string& name, const std::string& unit, const std::string& doc) {
  return add(ParamSpec{name, ParamType::RealList, unit, doc});
}

const ParamSpec* ParamSchema::find(const std::string& name) const {
  for (const auto& p : params_)
    if (p.name == name) return &p;
  return nullptr;
}

std::vector<std::string> ParamSchema::names() const {
  std::vector<std::string> out;
  for (const auto& p : params_) out.push_back(p.name);
  return out;
}

void ParamSchema::check_defaults(const std::string& owner) const {
  for (const auto& p : params_) {
    if (!p.default_value) continue;
    std::vector<double> numbers;
    if (const auto* v = std::get_if<double>(&*p.default_value)) numbers = {*v};
    if (const auto* v = std::get_if<long>(&*p.default_value)) numbers = {static_cast<double>(*v)};
    if (const auto* v = std::get_if<std::vector<double>>(&*p.default_value)) numbers = *v;
    const bool numbers_ok = std::all_of(numbers.begin(), numbers.end(), [&](double x) { return p.in_range(x); });
    const bool choice_ok = p.type != ParamType::Choice ||
                           std::find(p.choices.begin(), p.choices.end(), std::get<std::string>(*p.default_value)) !=
                               p.choices.end();
    if (!numbers_ok || !choice_ok)
      throw InputError(owner + ": the default " + p.default_text() + " of parameter '" + p.name +
                       "' is outside its own range " +
                       (p.type == ParamType::Choice ? "{" + join(p.choices) + "}" : p.range_text()));
  }
}

// ---------------------------------------------------------------------------------------------

const ParamValue& ParamSet::get(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) throw std::logic_error("parameter '" + name + "' was never declared");
  return it->second;
}

double ParamSet::real(const std::string& name) const { return std::get<double>(get(name)); }
long ParamSet::integer(const std::string& name) const { return std::get<long>(get(name)); }
bool ParamSet::boolean(const std::string& name) const { return std::get<bool>(get(name)); }
const std::string& ParamSet::string(const std::string& name) const {
  return std::get<std::string>(get(name));
}
const std::vector<double>& ParamSet::reals(const std::string& name) const {
  return std::get<std::vector<double>>(get(name));
}

SourceLocation ParamSet::where(const std::string& name) const {
  const auto it = where_.find(name);
  return it == where_.end() ? SourceLocation{} : it->second;
}

InputError ParamSet::error(const std::string& name, const std::string& message) const {
  return InputError(where(name), message);
}

void ParamSet::set(const std::string& name, ParamValue value, SourceLocation where) {
  if (!values_.count(name)) order_.push_back(name);
  values_[name] = std::move(value);
  where_[name] = std::move(where);
  defaulted_.erase(name);
}

void ParamSet::set_default(const std::string& name, ParamValue value, SourceLocation where) {
  set(name, std::move(value), std::move(where));
  defaulted_.insert(name);
}

YAML::Node ParamSet::to_yaml() const {
  YAML::Node node(YAML::NodeType::Map);
  for (const auto& name : order_) node[name] = frostmpm::to_yaml(values_.at(name));
  return node;
}

namespace {

void check_range(const ParamSpec& spec, double v, const ConfigNode& node) {
  if (!spec.in_range(v)) {
    std::string message = "value " + number_text(v) + " is out of range; allowed " + spec.range_text();
    if (!spec.unit.empty()) message += " " + spec.unit;
    throw node.error(message);
  }
}

ParamValue read_value(const ParamSpec& spec, const ConfigNode& node) {
  switch (spec.type) {
    case ParamType::Real: {
      const double v = node.as_real(spec.unit);
      check_range(spec, v, node);
      return v;
    }
    case ParamType::Integer: {
      const long v = node.as_integer();
      check_range(spec, static_cast<double>(v), node);
      return v;
    }
    case ParamType::Boolean: return node.as_bool();
    case ParamType::String: return node.as_string();
    case ParamType::Choice: {
      const std::string v = node.as_string();
      for (const auto& c : spec.choices)
        if (c == v) return v;
      throw node.error("'" + v + "' is not a valid choice" + did_you_mean(v, spec.choices) +
                       " Valid: " + join(spec.choices));
    }
    case ParamType::RealList: {
      std::vector<double> v = node.as_reals(spec.unit);
      if (spec.list_size && v.size() != spec.list_size)
        throw node.error("expected a list of " + std::to_string(spec.list_size) + " numbers, got " +
                         std::to_string(v.size()));
      for (double x : v) check_range(spec, x, node);
      return v;
    }
  }
  throw std::logic_error("unhandled parameter type");
}

}  // namespace

ParamSet parse_params(const ParamSchema& schema, const ConfigNode& node,
                      const std::vector<std::string>& also_allowed) {
  if (!node.is_map() && !node.is_null())
    throw node.error("expected a mapping of parameters (" + join(schema.names()) + ")");
  std::vector<std::string> valid = schema.names();
  valid.insert(valid.end(), also_allowed.begin(), also_allowed.end());
  node.reject_unknown(valid);
  ParamSet set;
  set.set_section(node.where());
  for (const auto& spec : schema.params()) {
    if (node.has(spec.name)) {
      const ConfigNode value = node.child(spec.name);
      set.set(spec.name, read_value(spec, value), value.where());
    } else if (spec.default_value) {
      set.set_default(spec.name, *spec.default_value, node.where());
    } else if (!spec.required()) {
      continue;  // optional: absent
    } else {
      std::string message = "missing required parameter '" + spec.name + "' (" + spec.doc;
      if (!spec.unit.empty()) message += ", " + spec.unit;
      throw node.error(message + ")");
    }
  }
  for (const auto& key : also_allowed)
    if (node.has(key)) (void)node.child(key);  // the caller reads these itself
  node.finish(valid);
  return set;
}

}  // namespace frostmpm
