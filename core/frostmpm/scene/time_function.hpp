#pragma once
// A scalar function of time t (seconds) for boundary conditions and sources. In a scene it is
// one of
//   5.0                                              a constant ("20 kPa": with a unit, units.hpp)
//   {table: [[t0, v0], [t1, v1], ...],               piecewise, times strictly increasing
//                                                    (each number may carry a unit: [30 d, 5 degC]);
//    interpolation: linear | step,                   (default linear; step holds v_i on [t_i, t_i+1))
//    extrapolation: hold | error}                    (default hold: end values outside the table)
//   {expression: "5 + 2*sin(2*pi*t/86400)"}          see expression.hpp; t in s, the value in the
//                                                    declared unit (an expression has no units)
// It is read and checked once; evaluation is cheap and allocation-free, and copies share one
// immutable implementation (safe to evaluate from several threads).
#include <memory>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/scene/expression.hpp"

namespace frostmpm {

class TimeFunction {
 public:
  enum class Kind { Constant, Table, Expression };
  enum class Interpolation { Linear, Step };
  enum class Extrapolation { Hold, Error };

  /// The constant 0.
  TimeFunction() = default;

  static TimeFunction constant(double v);
  /// A table from code; throws InputError for empty, mismatched or non-increasing times.
  static TimeFunction table(std::vector<double> times, std::vector<double> values,
                            Interpolation interpolation = Interpolation::Linear,
                            Extrapolation extrapolation = Extrapolation::Hold);
  /// An expression of t from code; throws ExpressionError when malformed.
  static TimeFunction expression(const std::string& text);

  /// Reads any of the three forms, values in `unit` (a UDUNITS-2 unit, units.hpp) and times in
  /// s; consumes the node's keys and calls finish(). Every problem is an InputError naming the
  /// YAML path and line.
  static TimeFunction read(const ConfigNode& node, const std::string& unit);
  /// read(), then evaluated at setup at t = 0, `end_time` and points between: a value that is
  /// not finite (1/t, log(0)) or whose magnitude exceeds `max_magnitude` (in the quantity's
  /// unit) is an InputError naming the node, instead of a blow-up during the run.
  static TimeFunction read(const ConfigNode& node, const std::string& unit, double max_magnitude, double end_time);

  /// Value at time t. With `extrapolation: error`, a t outside the table is an InputError
  /// pointing at the table in the scene.
  double operator()(double t) const { return kind_ == Kind::Constant ? value_ : scale_ * evaluate(t); }
  /// The same function times `factor` (e.g. a pressure turned into a traction along a normal).
  TimeFunction scaled(double factor) const;

  Kind kind() const { return kind_; }
  /// True when the value never depends on t (a constant, an expression without t, a table of
  /// equal values that holds outside its range).
  bool is_constant() const;
  /// True when both give the same value at every t: equal constants, or the same table or
  /// expression (spaces aside) with the same factor. Two conditions on one node may then agree.
  bool same_values(const TimeFunction& other) const;
  /// One-line summary: "5", "table(4 rows, linear)", "expression: 5+2*sin(2*pi*t/86400)".
  std::string describe() const;
  /// The resolved form, as it would be written in a scene.
  YAML::Node to_yaml() const;

  /// The accepted YAML forms, for error messages and documentation.
  static std::string forms_help();

 private:
  struct Impl;
  Kind kind_ = Kind::Constant;
  double value_ = 0;                  ///< the constant, for Kind::Constant
  double scale_ = 1;                  ///< factor on a table or expression (scaled())
  std::shared_ptr<const Impl> impl_;  ///< table or expression, shared between copies

  double evaluate(double t) const;
};

}  // namespace frostmpm
