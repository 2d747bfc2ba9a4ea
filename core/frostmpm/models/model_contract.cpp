#include "frostmpm/models/model_contract.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <span>

namespace frostmpm {

namespace {

std::string num(double v) { return number_text(v, 6); }

std::vector<double> linspace(double a, double b, std::size_t n) {
  std::vector<double> out(std::max<std::size_t>(n, 2));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = a + (b - a) * static_cast<double>(i) / (out.size() - 1);
  return out;
}

/// One line per broken rule: its first offending sample, and how many samples broke it.
class Violations {
 public:
  void add(const std::string& rule, const std::string& first) {
    for (auto& e : entries_)
      if (e.rule == rule) {
        ++e.count;
        return;
      }
    entries_.push_back({rule, first, 1});
  }
  std::vector<std::string> lines() const {
    std::vector<std::string> out;
    for (const auto& e : entries_)
      out.push_back(e.first + (e.count > 1 ? " (and " + std::to_string(e.count - 1) + " more samples)" : ""));
    return out;
  }

 private:
  struct Entry {
    std::string rule, first;
    std::size_t count;
  };
  std::vector<Entry> entries_;
};

/// y(x) and dy/dx of a model along one variable, at every x of a batch.
using Curve = std::function<void(std::span<const double> x, std::span<double> y, std::span<double> dy)>;

/// Values and slopes of `curve` at `xs`; outputs start as NaN so an unwritten entry shows.
struct Samples {
  std::vector<double> x, y, dy;
  Samples(const Curve& curve, std::vector<double> xs)
      : x(std::move(xs)),
        y(x.size(), std::numeric_limits<double>::quiet_NaN()),
        dy(x.size(), std::numeric_limits<double>::quiet_NaN()) {
    curve(x, y, dy);
  }
};

/// Names used in messages: "S_l", "dS_l/dT", "T".
struct Names {
  std::string y, dy, x, where;  ///< `where`: extra context such as " at porosity 0.3"
  std::string at(double x_value) const { return "(" + x + " = " + num(x_value) + where + ")"; }
};

void check_finite(const Samples& s, std::span<const double> values, const std::string& name, const Names& n,
                  Violations& v) {
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (!std::isfinite(values[i]))
      v.add(name + " finite", name + n.at(s.x[i]) + " = " + num(values[i]) + " is not finite (not written?)");
}

void check_finite(const Samples& s, const Names& n, Violations& v) {
  check_finite(s, s.y, n.y, n, v);
  check_finite(s, s.dy, n.dy, n, v);
}

void check_bounds(const Samples& s, const Names& n, double lo, double hi, Violations& v) {
  constexpr double kRoundOff = 1e-12;
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (s.y[i] < lo - kRoundOff || s.y[i] > hi + kRoundOff)
      v.add(n.y + " bounds", n.y + n.at(s.x[i]) + " = " + num(s.y[i]) + " is outside [" + num(lo) + ", " + num(hi) + "]");
}

void check_non_decreasing(const Samples& s, const Names& n, Violations& v) {
  for (std::size_t i = 0; i + 1 < s.x.size(); ++i)
    if (s.y[i + 1] < s.y[i] - 1e-12)
      v.add(n.y + " monotone", n.y + " decreases as " + n.x + " rises: " + n.y + n.at(s.x[i]) + " = " + num(s.y[i]) +
                                   " > " + n.y + n.at(s.x[i + 1]) + " = " + num(s.y[i + 1]));
}

/// Each analytic slope must match the central difference of the values at x ∓ h, or (at a
/// kink) a one-sided one.
void compare_slopes(const Samples& s, std::span<const double> y_lo, std::span<const double> y_hi, double h,
                    const Names& n, double abs_tol, Violations& v) {
  const auto close = [&](double a, double b) {
    return std::abs(a - b) <= 1e-3 * std::max(std::abs(a), std::abs(b)) + abs_tol;
  };
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!std::isfinite(s.dy[i])) continue;  // reported by check_finite
    const double central = (y_hi[i] - y_lo[i]) / (2 * h);
    const double left = (s.y[i] - y_lo[i]) / h, right = (y_hi[i] - s.y[i]) / h;
    if (!close(s.dy[i], central) && !close(s.dy[i], left) && !close(s.dy[i], right))
      v.add(n.dy + " slope", n.dy + n.at(s.x[i]) + " = " + num(s.dy[i]) + " but finite differences give " +
                                 num(central) + " (central), " + num(left) + " (left), " + num(right) + " (right)");
  }
}

/// The slope along the curve's own variable.
void check_slope(const Curve& curve, const Samples& s, const Names& n, double h, double abs_tol, Violations& v) {
  std::vector<double> below(s.x), above(s.x);
  for (auto& x : below) x -= h;
  for (auto& x : above) x += h;
  compare_slopes(s, Samples(curve, below).y, Samples(curve, above).y, h, n, abs_tol, v);
}

}  // namespace

std::vector<std::string> check_sfcc_contract(const SfccModel& model, double T_min, double T_max, std::size_t samples) {
  Violations v;
  const double T_f = model.freezing_point();
  const auto at_pressure = [&model](double p) -> Curve {
    return [&model, p](std::span<const double> T, std::span<double> S, std::span<double> dS_dT) {
      std::vector<double> pressure(T.size(), p), dS_dp(T.size());
      model.evaluate(T, pressure, {S, dS_dT, dS_dp});
    };
  };
  const Curve curve = at_pressure(0.0);
  const Names n{"S_l", "dS_l/dT", "T", ""};
  std::vector<double> temperatures = linspace(T_min, T_max, samples);
  if (T_f > T_min && T_f < T_max) temperatures.insert(std::upper_bound(temperatures.begin(), temperatures.end(), T_f), T_f);
  const Samples s(curve, temperatures);
  check_finite(s, n, v);
  check_bounds(s, n, 0.0, 1.0, v);
  check_non_decreasing(s, n, v);
  check_slope(curve, s, n, 1e-6 * std::max(1.0, T_max - T_min), 1e-7, v);
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (s.x[i] >= T_f && s.y[i] != 1.0)
      v.add("thawed", "S_l" + n.at(s.x[i]) + " = " + num(s.y[i]) + " at or above freezing_point() = " + num(T_f) +
                          "; must be 1");

  // Continuity at T_f: a step there survives any refinement, a steep curve does not.
  const double step = 1e-9 * std::max(1.0, std::abs(T_f));
  const Samples edge(curve, {T_f - step, T_f});
  if (std::abs(edge.y[1] - edge.y[0]) > 1e-5)
    v.add("continuous", "S_l jumps at the freezing point T_f = " + num(T_f) + ": S_l(T_f - " + num(step) +
                            ") = " + num(edge.y[0]) + ", S_l(T_f) = " + num(edge.y[1]));

  // ∂S_l/∂p_l at p_l = 0 (T fixed), and an empty p_l must mean p_l = 0.
  const std::size_t count = s.x.size();
  const std::vector<double> zero(count, 0.0);
  std::vector<double> S_empty(count), dT_empty(count), dp_empty(count);
  model.evaluate(s.x, {}, {S_empty, dT_empty, dp_empty});
  for (std::size_t i = 0; i < count; ++i)
    if (S_empty[i] != s.y[i])
      v.add("empty pressure", "S_l" + n.at(s.x[i]) + " = " + num(S_empty[i]) + " with an empty p_l but " + num(s.y[i]) +
                                  " with p_l = 0; an empty p_l means 0");
  Samples along_p(curve, s.x);  // x stays T; y is S_l, dy becomes ∂S_l/∂p_l
  std::fill(along_p.dy.begin(), along_p.dy.end(), std::numeric_limits<double>::quiet_NaN());
  model.evaluate(along_p.x, zero, {along_p.y, dT_empty, along_p.dy});
  constexpr double kPressureStep = 1.0;  // Pa
  const Samples p_lo(at_pressure(-kPressureStep), s.x), p_hi(at_pressure(kPressureStep), s.x);
  const Names pressure_names{"S_l", "dS_l/dp_l", "T", ", p_l = 0"};
  check_finite(along_p, along_p.dy, pressure_names.dy, pressure_names, v);
  compare_slopes(along_p, p_lo.y, p_hi.y, kPressureStep, pressure_names, 1e-12, v);
  return v.lines();
}

std::vector<std::string> check_relative_permeability_contract(const RelativePermeabilityModel& model,
                                                              std::size_t samples) {
  Violations v;
  for (const double porosity : {0.1, 0.3, 0.5}) {
    const Curve curve = [&model, porosity](std::span<const double> S, std::span<double> k, std::span<double> dk) {
      const std::vector<double> phi(S.size(), porosity);
      model.evaluate(S, phi, k, dk);
    };
    const Names n{"k_r", "dk_r/dS_l", "S_l", ", porosity " + num(porosity)};
    // S_l = 1 itself is checked for k_r = 1 only: slopes may be unbounded there (van Genuchten).
    std::vector<double> saturations = linspace(0.0, 1.0, samples + 1);
    saturations.pop_back();
    const Samples s(curve, saturations);
    check_finite(s, n, v);
    check_bounds(s, n, 0.0, 1.0, v);
    check_non_decreasing(s, n, v);
    check_slope(curve, s, n, 1e-7, 1e-7, v);
    const Samples full(curve, {1.0});
    if (full.y[0] != 1.0) v.add("saturated", "k_r" + n.at(1.0) + " = " + num(full.y[0]) + "; must be 1 when fully saturated");
  }
  return v.lines();
}

std::vector<std::string> check_absolute_permeability_contract(const AbsolutePermeabilityModel& model,
                                                              std::size_t samples) {
  Violations v;
  const Curve curve = [&model](std::span<const double> phi, std::span<double> k, std::span<double> dk) {
    model.evaluate(phi, k, dk);
  };
  const Names n{"k_a", "dk_a/dphi", "porosity", ""};
  const Samples s(curve, linspace(0.01, 0.99, samples));
  check_finite(s, n, v);
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (!(s.y[i] > 0.0)) v.add("positive", "k_a" + n.at(s.x[i]) + " = " + num(s.y[i]) + " must be positive");
  double scale = 0;
  for (double k : s.y) scale = std::max(scale, std::abs(k));
  check_slope(curve, s, n, 1e-7, 1e-9 * scale, v);
  return v.lines();
}

}  // namespace frostmpm
