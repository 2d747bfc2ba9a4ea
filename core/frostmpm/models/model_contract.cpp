#include "frostmpm/models/model_contract.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <span>

#include "frostmpm/config/input_error.hpp"
#include "frostmpm/config/units.hpp"

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
  bool has(const std::string& rule) const {
    return std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.rule == rule; });
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

// ---- mechanical models -------------------------------------------------------------------------

namespace {

using Voigt = std::array<double, 6>;
using Matrix3 = std::array<std::array<double, 3>, 3>;

constexpr const char* kComponent[6] = {"xx", "yy", "zz", "yz", "xz", "xy"};
constexpr int kVoigt[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr std::uint64_t kSeed = 20240611;
constexpr double kMaxMeanStress = 1e6;       // Pa, compressive
constexpr double kDeviatorFraction = 0.2;    // of the mean stress, for the loading step
// Every other sample is loaded 15 times as far: beyond the friction of any soil, so that an
// elastoplastic model starts those samples on its yield surface and its plastic branch (the
// return and its tangent) is checked as often as its elastic one.
constexpr double kYieldingLoad = 15.0;
constexpr double kMaxStrainIncrement = 1e-3;
constexpr double kTemperatureRange[2] = {-20.0, 20.0};
constexpr double kMaxPorePressure = 1e6;     // Pa
constexpr double kStep = 1e-3;               // s, a typical explicit step
// Finite differences of the tangent (and half of it): 1e-7, or less for a model stiffer than
// 1e7 Pa, by the square root of the excess, between the curvature of a return map (its principal
// directions turn with the strain), which wants small steps, and the round-off of a return from
// a large trial stress, which wants large ones.
constexpr double kStrainStep = 1e-7;
constexpr double kReferenceModulus = 1e7;  // Pa

/// Q A Qᵀ of a symmetric tensor in Voigt order.
Voigt rotate(const Matrix3& Q, const double* a) {
  Voigt out{};
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      double sum = 0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) sum += Q[i][k] * Q[j][l] * a[kVoigt[k][l]];
      out[kVoigt[i][j]] = sum;
    }
  return out;
}

double max_abs(const double* a, std::size_t n) {
  double m = 0;
  for (std::size_t i = 0; i < n; ++i) m = std::max(m, std::abs(a[i]));
  return m;
}

std::string voigt_text(const double* a) {
  std::string s = "[";
  for (int i = 0; i < 6; ++i) s += (i ? ", " : "") + num(a[i]);
  return s + "]";
}

/// Uniform doubles from the raw 64-bit engine: the same samples on every standard library.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform(double a, double b) { return a + (b - a) * static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 engine_;
};

struct Rotation {
  Matrix3 Q;
  std::string text;
};

/// A uniformly distributed rotation, from a random unit quaternion.
Rotation random_rotation(Random& random) {
  const double u = random.uniform(0, 1), a = 2 * std::numbers::pi * random.uniform(0, 1),
               b = 2 * std::numbers::pi * random.uniform(0, 1);
  const double w = std::sqrt(1 - u) * std::sin(a), x = std::sqrt(1 - u) * std::cos(a), y = std::sqrt(u) * std::sin(b),
               z = std::sqrt(u) * std::cos(b);
  Rotation r;
  r.Q = {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
  const double half = std::acos(std::clamp(std::abs(w), 0.0, 1.0)), sine = std::sin(half);
  const double axis = (w < 0 ? -1.0 : 1.0) / std::max(sine, 1e-300);
  r.text = "rotation by " + num(2 * half * 180 / std::numbers::pi) + " degrees about (" +
           (sine > 1e-12 ? num(x * axis) + ", " + num(y * axis) + ", " + num(z * axis) : "0, 0, 1") + ")";
  return r;
}

/// 90 degrees about z: x goes to y, so σ_xx and σ_yy swap (the plane-strain rotation).
const Rotation kQuarterTurn{{{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}}, "rotation by 90 degrees about z"};

/// One sampled state of a material point.
struct StressPoint {
  Voigt strain{}, stress{};
  std::vector<double> state;
  double T = 0, S_c = 0, p_l = 0;
};

/// A random direction of strain scaled to norm `length` (of the 3×3 tensor: shear components
/// count twice).
Voigt random_strain(Random& random, double length) {
  Voigt e;
  for (auto& c : e) c = random.uniform(-1, 1);
  double norm = 0;
  for (int k = 0; k < 6; ++k) norm += (k < 3 ? 1 : 2) * e[k] * e[k];
  for (auto& c : e) c *= length / std::sqrt(norm);
  return e;
}

/// A sample before its loading step: hydrostatic compression (zero for the first), its own
/// increment and inputs; `loading` receives the strain of the loading step.
StressPoint random_point(Random& random, std::size_t i, const std::vector<double>& state0, double loading_scale,
                         Voigt& loading) {
  StressPoint p;
  const double mean = i == 0 ? 0.0 : random.uniform(0, kMaxMeanStress);
  if (mean > 0)  // the first start stress is +0, not -0
    for (int k = 0; k < 3; ++k) p.stress[k] = -mean;
  const double load = (i % 2 == 1 ? kYieldingLoad : 1.0) * kDeviatorFraction * mean * loading_scale;
  loading = random_strain(random, random.uniform(0, 1) * load);
  p.strain = random_strain(random, random.uniform(0.01, 1.0) * kMaxStrainIncrement);
  p.state = state0;
  p.T = random.uniform(kTemperatureRange[0], kTemperatureRange[1]);
  p.S_c = i % 10 == 1 ? 0.0 : i % 10 == 2 ? 1.0 : random.uniform(0, 1);
  p.p_l = random.uniform(0, kMaxPorePressure);
  return p;
}

/// What a model returned for a batch; every output starts as NaN so an entry it does not
/// write shows.
struct StressResults {
  std::vector<double> stress, state, tangent, p_wave, shear;
  std::vector<std::uint8_t> failed;
};

StressResults integrate(const MechanicalModel& model, const std::vector<StressPoint>& points, std::size_t nv,
                        bool optional_inputs, bool tangent) {
  const std::size_t n = points.size();
  std::vector<double> strain(6 * n), stress(6 * n), state(nv * n), T(n), S_c(n), p_l(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(points[i].strain.begin(), points[i].strain.end(), strain.begin() + 6 * i);
    std::copy(points[i].stress.begin(), points[i].stress.end(), stress.begin() + 6 * i);
    std::copy(points[i].state.begin(), points[i].state.end(), state.begin() + nv * i);
    T[i] = points[i].T;
    S_c[i] = points[i].S_c;
    p_l[i] = points[i].p_l;
  }
  StressResults r;
  r.stress.assign(6 * n, kNaN);
  r.state.assign(nv * n, kNaN);
  r.tangent.assign(tangent ? 36 * n : 0, kNaN);
  r.p_wave.assign(n, kNaN);
  r.shear.assign(n, kNaN);
  r.failed.assign(n, 0);
  StressUpdateInput in;
  in.strain_increment = strain;
  in.stress_start = stress;
  in.state_start = state;
  if (optional_inputs) {
    in.temperature = T;
    in.ice_saturation = S_c;
    in.pore_pressure = p_l;
  }
  in.dt = kStep;
  StressUpdateOutput out;
  out.stress = r.stress;
  out.state = r.state;
  out.failed = r.failed;
  out.tangent = r.tangent;
  out.p_wave_modulus = r.p_wave;
  out.shear_modulus = r.shear;
  model.integrate(in, out);
  return r;
}

class MechanicalCheck {
 public:
  MechanicalCheck(const MechanicalModelCase& c, std::size_t samples, Violations& v)
      : model_(*c.model),
        with_(c.parameters.empty() ? "" : ", with " + c.parameters),
        samples_(std::max<std::size_t>(samples, 1)),
        v_(v) {}

  void run() {
    check_initial_state();
    sample_start_states();
    const StressResults base = integrate(model_, points_, names_.size(), true, true);
    check_outputs(base, true);
    check_outputs(integrate(model_, points_, names_.size(), false, false), false);
    check_yield_surface(base);
    check_zero_increment();
    check_tangent(base);
    check_rotation(base, false);
    check_rotation(base, true);
  }

 private:
  std::string at(const StressPoint& p, bool optional_inputs = true) const {
    return " (strain increment " + voigt_text(p.strain.data()) + ", start stress " + voigt_text(p.stress.data()) +
           " Pa, " +
           (optional_inputs ? "T = " + num(p.T) + " degC, S_c = " + num(p.S_c) + ", p_l = " + num(p.p_l) + " Pa"
                            : "no T, S_c or p_l given") +
           with_ + ")";
  }

  void check_initial_state() {
    names_.clear();
    for (const auto& variable : model_.internal_variables()) {
      names_.push_back(variable.name);
      if (!units::is_output_unit(variable.unit))
        v_.add("internal variable unit", "internal variable '" + variable.name + "' has the unit '" + variable.unit +
                                             "'; give a UDUNITS-2 unit (\"1\" when dimensionless)");
    }
    state0_ = model_.initial_state();
    if (state0_.size() != names_.size())
      v_.add("initial_state size", "initial_state() has " + std::to_string(state0_.size()) +
                                       " entries but internal_variables() names " + std::to_string(names_.size()) +
                                       (names_.empty() ? "" : " (" + join(names_) + ")") + with_);
    for (std::size_t k = 0; k < std::min(state0_.size(), names_.size()); ++k)
      if (!std::isfinite(state0_[k]))
        v_.add("initial_state finite",
               "initial_state() of '" + names_[k] + "' = " + num(state0_[k]) + " is not finite" + with_);
    state0_.resize(names_.size(), 0.0);  // what the mechanics would pass
    const double M = model_.max_p_wave_modulus();
    if (!(M > 0) || !std::isfinite(M))
      v_.add("max_p_wave_modulus", "max_p_wave_modulus() = " + num(M) + " must be positive and finite" + with_);
  }

  /// Start states the model reaches itself — one loading step from a hydrostatic compression p,
  /// of a strain worth up to 0.2 p (every other sample 3 p) at the largest P-wave modulus — so an elastoplastic model
  /// starts on or inside its yield surface. A point whose loading fails starts hydrostatic.
  void sample_start_states() {
    const double M = model_.max_p_wave_modulus();
    const double scale = M > 0 && std::isfinite(M) ? 1.0 / M : 0.0;
    Random random(kSeed);
    std::vector<StressPoint> loading;
    for (std::size_t i = 0; i < samples_; ++i) {
      Voigt strain;
      points_.push_back(random_point(random, i, state0_, scale, strain));
      rotations_.push_back(random_rotation(random));
      loading.push_back(points_.back());
      loading.back().strain = strain;
    }
    const StressResults r = integrate(model_, loading, names_.size(), true, false);
    const std::size_t nv = names_.size();
    for (std::size_t i = 0; i < samples_; ++i) {
      const bool usable = !r.failed[i] && std::isfinite(max_abs(&r.stress[6 * i], 6)) &&
                          std::all_of(r.state.begin() + nv * i, r.state.begin() + nv * (i + 1),
                                      [](double x) { return std::isfinite(x); });
      if (!usable || i == 0) continue;  // the first start stress stays exactly zero
      std::copy(&r.stress[6 * i], &r.stress[6 * i] + 6, points_[i].stress.begin());
      std::copy(r.state.begin() + nv * i, r.state.begin() + nv * (i + 1), points_[i].state.begin());
    }
  }

  /// Finite outputs, no failure, 0 < p_wave_modulus <= max_p_wave_modulus(), G >= 0. Without
  /// the optional inputs only what did not already break with them is reported.
  void check_outputs(const StressResults& r, bool optional_inputs) {
    const auto add = [&](const std::string& rule, const std::string& line) {
      if (optional_inputs) v_.add(rule, line);
      else if (!v_.has(rule)) v_.add(rule + " without inputs", line);
    };
    const std::size_t nv = names_.size();
    const double bound = model_.max_p_wave_modulus();
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const std::string where = at(points_[i], optional_inputs);
      if (r.failed[i]) add("failed", "the integration fails" + where);
      for (int k = 0; k < 6; ++k)
        if (!std::isfinite(r.stress[6 * i + k])) {
          add("stress finite", "stress_" + std::string(kComponent[k]) + " = " + num(r.stress[6 * i + k]) +
                                   " is not finite (not written?)" + where);
          break;
        }
      for (std::size_t k = 0; k < nv; ++k)
        if (!std::isfinite(r.state[nv * i + k])) {
          add("state finite", "state '" + names_[k] + "' = " + num(r.state[nv * i + k]) +
                                  " is not finite (not written?)" + where);
          break;
        }
      const double M = r.p_wave[i], G = r.shear[i];
      if (!std::isfinite(M))
        add("p_wave_modulus finite", "p_wave_modulus = " + num(M) + " is not finite (not written?)" + where);
      else if (!(M > 0) || M > bound * (1 + 1e-12))
        add("p_wave_modulus bounds",
            "p_wave_modulus = " + num(M) + " is outside (0, max_p_wave_modulus() = " + num(bound) + "]" + where);
      if (!std::isfinite(G))
        add("shear_modulus finite", "shear_modulus = " + num(G) + " is not finite (not written?)" + where);
      else if (G < 0)
        add("shear_modulus sign", "shear_modulus = " + num(G) + " is negative" + where);
    }
  }

  /// A plasticity model: every returned stress lies on or inside the surface its own returned
  /// internal variables describe (F ≤ 1e-8 of the stress's size).
  void check_yield_surface(const StressResults& r) {
    std::vector<double> F(points_.size(), kNaN);
    if (!model_.yield_function(r.stress, r.state, F)) return;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const double size = std::max(max_abs(&r.stress[6 * i], 6), 1.0);
      if (r.failed[i] || !std::isfinite(size)) continue;  // reported by check_outputs
      if (!(F[i] <= 1e-8 * size))
        v_.add("yield surface", "the returned stress " + voigt_text(&r.stress[6 * i]) +
                                    " Pa lies outside the yield surface: F = " + num(F[i]) + " Pa" + at(points_[i]));
    }
  }

  void check_zero_increment() {
    std::vector<StressPoint> still = points_;
    for (auto& p : still) p.strain.fill(0.0);
    const StressResults r = integrate(model_, still, names_.size(), true, false);
    for (std::size_t i = 0; i < still.size(); ++i) {
      const double* s = &r.stress[6 * i];
      if (!std::isfinite(max_abs(s, 6))) continue;  // reported as not finite
      const double tolerance = 1e-12 * max_abs(still[i].stress.data(), 6);
      for (int k = 0; k < 6; ++k)
        if (std::abs(s[k] - still[i].stress[k]) > tolerance) {
          v_.add("zero increment", "a zero strain increment changes the stress: stress " + voigt_text(s) +
                                       " Pa" + at(still[i]));
          break;
        }
    }
  }

  /// Each tangent column against differences of the stress along that strain component.
  void check_tangent(const StressResults& base) {
    if (std::none_of(base.tangent.begin(), base.tangent.end(), [](double d) { return std::isfinite(d); }))
      return;  // the model does not fill the tangent: nothing to check
    // Each component at -h, -h/2, +h/2, +h: Richardson-extrapolated central differences
    // (error O(h⁴)), or at a kink second-order one-sided ones.
    constexpr double kOffsets[4] = {-1.0, -0.5, 0.5, 1.0};
    const std::size_t n = points_.size();
    const double h = kStrainStep * std::sqrt(std::min(1.0, kReferenceModulus / model_.max_p_wave_modulus()));
    std::vector<StressPoint> shifted;
    shifted.reserve(24 * n);
    for (const auto& p : points_)
      for (int j = 0; j < 6; ++j)
        for (const double offset : kOffsets) {
          shifted.push_back(p);
          shifted.back().strain[j] += offset * h;
        }
    const StressResults r = integrate(model_, shifted, names_.size(), true, false);
    for (std::size_t i = 0; i < n; ++i) {
      const double* D = &base.tangent[36 * i];
      const double* s = &base.stress[6 * i];
      const std::string where = at(points_[i]);
      if (!std::isfinite(max_abs(D, 36))) {
        for (int k = 0; k < 36; ++k)
          if (!std::isfinite(D[k])) {
            v_.add("tangent finite", "tangent dstress_" + std::string(kComponent[k / 6]) + "/dstrain_" +
                                         kComponent[k % 6] + " = " + num(D[k]) + " is not finite (not written?)" +
                                         where);
            break;
          }
        continue;
      }
      double stress_size = max_abs(s, 6);
      for (std::size_t k = 0; k < 24; ++k) stress_size = std::max(stress_size, max_abs(&r.stress[6 * (24 * i + k)], 6));
      // A return map subtracts from its elastic trial stress, which may be far larger.
      stress_size = std::max(stress_size, max_abs(points_[i].stress.data(), 6) +
                                              model_.max_p_wave_modulus() * max_abs(points_[i].strain.data(), 6));
      // The differences lose ≈ 100 ε |σ| / h to cancellation (a return through an eigen-
      // decomposition loses a few digits): an entry of that size is zero, and so
      // is one below 1e-9 of the stiffest modulus the model can reach (at a plastic apex the
      // whole tangent is zero and the differences are round-off of stresses near zero).
      const double floor = 1e-6 * max_abs(D, 36) + 1e-9 * model_.max_p_wave_modulus() +
                           100 * std::numeric_limits<double>::epsilon() * stress_size / h;
      const auto close = [&](double a, double b) {
        return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)) + floor;
      };
      bool mismatch = false;
      for (int j = 0; j < 6 && !mismatch; ++j) {
        const double* f = &r.stress[6 * (24 * i + 4 * j)];  // f[6 k + a]: σ_a at kOffsets[k]
        for (int a = 0; a < 6 && !mismatch; ++a) {
          const double m1 = f[a], m2 = f[6 + a], p2 = f[12 + a], p1 = f[18 + a];
          const double central = (4 * (p2 - m2) / h - (p1 - m1) / (2 * h)) / 3;
          const double left = (3 * s[a] - 4 * m2 + m1) / h, right = (-3 * s[a] + 4 * p2 - p1) / h;
          const double d = D[6 * a + j];
          if (close(d, central) || close(d, left) || close(d, right)) continue;
          mismatch = true;
          v_.add("tangent", "tangent dstress_" + std::string(kComponent[a]) + "/dstrain_" + kComponent[j] + " = " +
                                num(d) + " but finite differences give " + num(central) + " (central), " + num(left) +
                                " (left), " + num(right) + " (right)" + where);
        }
      }
    }
  }

  /// Integrating the rotated increment and start stress must give the rotated end stress and
  /// the same internal variables.
  void check_rotation(const StressResults& base, bool quarter_turn) {
    std::vector<StressPoint> turned = points_;
    for (std::size_t i = 0; i < turned.size(); ++i) {
      const Matrix3& Q = quarter_turn ? kQuarterTurn.Q : rotations_[i].Q;
      turned[i].strain = rotate(Q, points_[i].strain.data());
      turned[i].stress = rotate(Q, points_[i].stress.data());
    }
    const StressResults r = integrate(model_, turned, names_.size(), true, false);
    const std::size_t nv = names_.size();
    std::vector<double> state_size(nv, 0.0);
    for (std::size_t i = 0; i < points_.size(); ++i)
      for (std::size_t k = 0; k < nv; ++k)
        if (const double x = base.state[nv * i + k]; std::isfinite(x))
          state_size[k] = std::max(state_size[k], std::abs(x));
    const std::string rule = quarter_turn ? "quarter turn" : "objective";
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Rotation& rotation = quarter_turn ? kQuarterTurn : rotations_[i];
      const double* s = &base.stress[6 * i];
      if (base.failed[i] || !std::isfinite(max_abs(s, 6))) continue;  // reported by check_outputs
      const std::string where = " under a " + rotation.text + at(points_[i]);
      if (r.failed[i]) {
        v_.add(rule, "the integration fails only after a " + rotation.text + at(points_[i]));
        continue;
      }
      const Voigt expected = rotate(rotation.Q, s);
      const double* got = &r.stress[6 * i];
      const double tolerance = 1e-9 * std::max({max_abs(s, 6), max_abs(points_[i].stress.data(), 6)});
      bool bad = !std::isfinite(max_abs(got, 6));
      for (int k = 0; k < 6 && !bad; ++k) bad = std::abs(got[k] - expected[k]) > tolerance;
      if (bad) {
        v_.add(rule, (quarter_turn ? "stress_xx and stress_yy do not swap: the rotated input gives stress "
                                   : "not objective: the rotated input gives stress ") +
                         voigt_text(got) + " Pa, the rotated stress is " + voigt_text(expected.data()) + " Pa" + where);
        continue;
      }
      for (std::size_t k = 0; k < nv; ++k) {
        const double a = base.state[nv * i + k], b = r.state[nv * i + k];
        const double tolerance = 1e-9 * std::max({std::abs(a), std::abs(b), 1e-3 * state_size[k]});
        if (std::isfinite(a) && !(std::abs(a - b) <= tolerance)) {
          v_.add(rule, "state '" + names_[k] + "' changes with the frame: " + num(a) + ", and " + num(b) + where);
          break;
        }
      }
    }
  }

  const MechanicalModel& model_;
  std::string with_;
  std::size_t samples_;
  Violations& v_;
  std::vector<StressPoint> points_;
  std::vector<Rotation> rotations_;
  std::vector<std::string> names_;
  std::vector<double> state0_;
};

}  // namespace

std::vector<std::string> check_mechanical_model_contract(const MechanicalModel& model, std::size_t samples) {
  return check_mechanical_model_contract(std::vector<MechanicalModelCase>{{&model, ""}}, samples);
}

std::vector<std::string> check_mechanical_model_contract(const std::vector<MechanicalModelCase>& cases,
                                                         std::size_t samples) {
  Violations v;
  for (const auto& c : cases) {
    try {
      MechanicalCheck(c, samples, v).run();
    } catch (const std::exception& e) {
      // A failed point must be flagged, not thrown: the mechanics names it and stops cleanly.
      v.add("throws", std::string("integrate() throws instead of setting the failure flag: ") + e.what() +
                          (c.parameters.empty() ? "" : " (with " + c.parameters + ")"));
    }
  }
  return v.lines();
}

}  // namespace frostmpm
