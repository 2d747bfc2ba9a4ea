#include "frostmpm/scene/time_function.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>

#include "frostmpm/config/units.hpp"

namespace frostmpm {

struct TimeFunction::Impl {
  // Table
  std::vector<double> times, values;
  Interpolation interpolation = Interpolation::Linear;
  Extrapolation extrapolation = Extrapolation::Hold;
  SourceLocation where;  ///< the table in the scene, for out-of-range errors
  // Expression
  frostmpm::Expression expression;
};

namespace {

/// Shortest text that reads back as the same double ("5", "0.1", "86400", "1e-07").
std::string number_text(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

const char* to_string(TimeFunction::Interpolation i) {
  return i == TimeFunction::Interpolation::Linear ? "linear" : "step";
}
const char* to_string(TimeFunction::Extrapolation e) {
  return e == TimeFunction::Extrapolation::Hold ? "hold" : "error";
}

std::string collapse_spaces(const std::string& text) {
  std::string out;
  for (char c : text)
    if (c != ' ' && c != '\t' && c != '\n' && c != '\r') out += c;
  return out;
}

}  // namespace

std::string TimeFunction::forms_help() {
  return "a time function is a number (5.0), {table: [[t0, v0], [t1, v1], ...]} with optional "
         "interpolation: linear|step and extrapolation: hold|error, or {expression: \"5 + "
         "2*sin(2*pi*t/86400)\"} of time t in seconds";
}

TimeFunction TimeFunction::scaled(double factor) const {
  TimeFunction out = *this;
  if (kind_ == Kind::Constant) out.value_ = factor * value_;
  else out.scale_ = factor * scale_;
  return out;
}

TimeFunction TimeFunction::constant(double v) {
  TimeFunction f;
  f.kind_ = Kind::Constant;
  f.value_ = v;
  return f;
}

TimeFunction TimeFunction::table(std::vector<double> times, std::vector<double> values,
                                 Interpolation interpolation, Extrapolation extrapolation) {
  if (times.empty()) throw InputError("time function table needs at least one row [time, value]");
  if (times.size() != values.size())
    throw InputError("time function table has " + std::to_string(times.size()) + " times but " +
                     std::to_string(values.size()) + " values");
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]) || !std::isfinite(values[i]))
      throw InputError("time function table row " + std::to_string(i) + " is not finite");
    if (i > 0 && !(times[i] > times[i - 1]))
      throw InputError("time function table times must be strictly increasing: row " + std::to_string(i) +
                       " (t = " + number_text(times[i]) + ") does not come after row " +
                       std::to_string(i - 1) + " (t = " + number_text(times[i - 1]) + ")");
  }
  auto impl = std::make_shared<Impl>();
  impl->times = std::move(times);
  impl->values = std::move(values);
  impl->interpolation = interpolation;
  impl->extrapolation = extrapolation;
  TimeFunction f;
  f.kind_ = Kind::Table;
  f.impl_ = std::move(impl);
  return f;
}

TimeFunction TimeFunction::expression(const std::string& text) {
  auto impl = std::make_shared<Impl>();
  impl->expression = Expression::compile(text, {"t"});
  TimeFunction f;
  f.kind_ = Kind::Expression;
  f.impl_ = std::move(impl);
  return f;
}

TimeFunction TimeFunction::read(const ConfigNode& node, const std::string& unit, double max_magnitude,
                                double end_time) {
  const TimeFunction f = read(node, unit);
  constexpr int kSamples = 16;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = end_time * i / kSamples;
    const double v = f(t);
    if (!std::isfinite(v) || std::abs(v) > max_magnitude)
      throw node.error("the value at t = " + number_text(t) + " s is " + number_text(v) +
                       (std::isfinite(v) ? " " + unit + ", beyond the plausible magnitude " + number_text(max_magnitude)
                                         : std::string(", not a finite number")));
    if (f.is_constant()) break;
  }
  return f;
}

TimeFunction TimeFunction::read(const ConfigNode& node, const std::string& unit) {
  if (node.is_scalar()) {
    const std::string text = node.as_string();
    double v = 0;
    if (!YAML::convert<double>::decode(node.raw(), v) && !units::split(text))
      throw node.error("expected a time function, got '" + text + "'; " + forms_help());
    return constant(node.as_real(unit));  // as_real rejects inf and nan
  }
  if (!node.is_map()) throw node.error("expected a time function; " + forms_help());

  const bool has_table = node.has("table"), has_expression = node.has("expression");
  if (has_table && has_expression)
    throw node.error("give either 'table' or 'expression', not both; " + forms_help());

  if (has_expression) {
    const ConfigNode expr = node.child("expression");
    node.finish({"expression"});
    if (!expr.is_scalar()) throw expr.error("expected the expression as a string, e.g. \"5 + 2*sin(t)\"");
    const std::string text = expr.as_string();
    try {
      return expression(text);
    } catch (const ExpressionError& e) {
      throw expr.error("expression '" + text + "' : " + e.what());
    }
  }

  if (has_table) {
    const ConfigNode table_node = node.child("table");
    Interpolation interpolation = Interpolation::Linear;
    Extrapolation extrapolation = Extrapolation::Hold;
    if (const auto c = node.optional_child("interpolation")) {
      const std::string s = c->as_string();
      if (s == "linear") interpolation = Interpolation::Linear;
      else if (s == "step") interpolation = Interpolation::Step;
      else throw c->error("unknown interpolation '" + s + "'; valid: linear, step");
    }
    if (const auto c = node.optional_child("extrapolation")) {
      const std::string s = c->as_string();
      if (s == "hold") extrapolation = Extrapolation::Hold;
      else if (s == "error") extrapolation = Extrapolation::Error;
      else throw c->error("unknown extrapolation '" + s + "'; valid: hold, error");
    }
    node.finish({"table", "interpolation", "extrapolation"});

    if (!table_node.is_sequence())
      throw table_node.error("expected a list of rows [time, value], e.g. [[0, 5], [3600, 7]]");
    const std::vector<ConfigNode> rows = table_node.elements();
    if (rows.empty()) throw table_node.error("table needs at least one row [time, value]");
    std::vector<double> times, values;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const ConfigNode& row = rows[i];
      const auto pair = row.as_row({"s", unit}, "table row " + std::to_string(i) + " to be a pair [time, value]");
      const double t = pair[0], v = pair[1];
      if (i > 0 && !(t > times.back()))
        throw row.error("table times must be strictly increasing: row " + std::to_string(i) + " (t = " +
                        number_text(t) + ") does not come after row " + std::to_string(i - 1) +
                        " (t = " + number_text(times.back()) + ")");
      times.push_back(t);
      values.push_back(v);
    }
    TimeFunction f = table(std::move(times), std::move(values), interpolation, extrapolation);
    auto impl = std::make_shared<Impl>(*f.impl_);
    impl->where = table_node.where();
    f.impl_ = std::move(impl);
    return f;
  }

  // Neither form: point out a likely typo, then list the forms.
  std::string message = "expected a time function";
  const std::vector<std::string> valid{"table", "interpolation", "extrapolation", "expression"};
  for (const auto& key : node.keys()) {
    const std::string hint = closest_match(key, valid);
    message += "; unknown key '" + key + "'" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)");
    break;
  }
  throw node.error(message + "; " + forms_help());
}

double TimeFunction::evaluate(double t) const {
  const Impl& impl = *impl_;
  if (kind_ == Kind::Expression) return impl.expression(t);

  const std::vector<double>& times = impl.times;
  const std::vector<double>& values = impl.values;
  const std::size_t n = times.size();
  if (std::isnan(t)) return t;
  if (t < times.front() || t > times.back()) {
    if (impl.extrapolation == Extrapolation::Error)
      throw InputError(impl.where, "time t = " + number_text(t) + " s is outside the table's range [" +
                                       number_text(times.front()) + ", " + number_text(times.back()) +
                                       "] s and extrapolation is 'error' (use extrapolation: hold or extend "
                                       "the table)");
    return t < times.front() ? values.front() : values.back();
  }
  // Row i with times[i] <= t < times[i+1]; the last row when t is the last time.
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  if (i + 1 >= n || impl.interpolation == Interpolation::Step) return values[i];
  const double w = (t - times[i]) / (times[i + 1] - times[i]);
  return values[i] + (values[i + 1] - values[i]) * w;
}

bool TimeFunction::is_constant() const {
  switch (kind_) {
    case Kind::Constant: return true;
    case Kind::Expression: return impl_->expression.is_constant();
    case Kind::Table:
      return impl_->extrapolation == Extrapolation::Hold &&
             std::adjacent_find(impl_->values.begin(), impl_->values.end(), std::not_equal_to<>()) ==
                 impl_->values.end();
  }
  return false;
}

bool TimeFunction::same_values(const TimeFunction& other) const {
  if (is_constant() || other.is_constant())
    return is_constant() && other.is_constant() && (*this)(0.0) == other(0.0);
  if (kind_ != other.kind_ || scale_ != other.scale_) return false;
  const Impl &a = *impl_, &b = *other.impl_;
  if (kind_ == Kind::Expression) return collapse_spaces(a.expression.text()) == collapse_spaces(b.expression.text());
  return a.times == b.times && a.values == b.values && a.interpolation == b.interpolation &&
         a.extrapolation == b.extrapolation;
}

std::string TimeFunction::describe() const {
  switch (kind_) {
    case Kind::Constant: return number_text(value_);
    case Kind::Table: {
      const std::size_t n = impl_->times.size();
      std::string out = "table(" + std::to_string(n) + (n == 1 ? " row, " : " rows, ") +
                        to_string(impl_->interpolation);
      if (impl_->extrapolation == Extrapolation::Error) out += ", extrapolation error";
      return out + ")";
    }
    case Kind::Expression: {
      std::string text = collapse_spaces(impl_->expression.text());
      constexpr std::size_t kMax = 60;
      if (text.size() > kMax) text = text.substr(0, kMax - 3) + "...";
      return "expression: " + text;
    }
  }
  return "?";
}

YAML::Node TimeFunction::to_yaml() const {
  switch (kind_) {
    case Kind::Constant: return YAML::Node(number_text(value_));
    case Kind::Table: {
      YAML::Node rows(YAML::NodeType::Sequence);
      for (std::size_t i = 0; i < impl_->times.size(); ++i) {
        YAML::Node row(YAML::NodeType::Sequence);
        row.push_back(number_text(impl_->times[i]));
        row.push_back(number_text(impl_->values[i]));
        row.SetStyle(YAML::EmitterStyle::Flow);
        rows.push_back(row);
      }
      YAML::Node out(YAML::NodeType::Map);
      out["table"] = rows;
      out["interpolation"] = to_string(impl_->interpolation);
      out["extrapolation"] = to_string(impl_->extrapolation);
      return out;
    }
    case Kind::Expression: {
      YAML::Node out(YAML::NodeType::Map);
      out["expression"] = impl_->expression.text();
      return out;
    }
  }
  return YAML::Node();
}

}  // namespace frostmpm
