// Closed-form reference solutions for 1-D heat conduction with and without phase change.
//
// Header-only, standard library only, double precision. Used by the verification tests to
// compare simulated temperature profiles against exact solutions; every solution here is
// itself checked against published numbers in tests/verification/test_analytic_references.cpp
// (see tests/verification/analytic/README.md for sources and parameters).
//
// Contents
//   erfcx, erfc_ratio, scaled_erf_difference   numerically safe special-function helpers
//   brent_root, expand_bracket                 bracketed root finding
//   SemiInfiniteStep                           surface temperature step (erf solution)
//   SemiInfiniteConvective                     convective (Robin) surface, Carslaw & Jaeger §2.7
//   NeumannParams / NeumannSolution            two-phase Neumann (Stefan) problem, freezing or thawing
//   LunardiniParams / LunardiniSolution        three-zone freezing with a mushy zone (Lunardini;
//                                              McKenzie, Voss & Siegel 2007)
//   profile_error, observed_order(s)           error norms and observed convergence order
//
// Conventions: x >= 0 is depth below the surface x = 0 [m], t >= 0 time [s], temperatures in
// any consistent unit (°C in the tests), conductivities k [W/m/K], volumetric heat capacities C
// [J/m^3/K], diffusivities alpha = k/C [m^2/s]. Negative x or t throws std::domain_error.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace frostmpm::analytic {

// ---------------------------------------------------------------------------------------------
// Special functions
// ---------------------------------------------------------------------------------------------

/// Scaled complementary error function erfcx(x) = exp(x^2) erfc(x).
/// x < 4: direct product (std::erfc keeps full relative accuracy there, exp(16) is harmless);
/// x >= 4: Laplace continued fraction erfc(x) = exp(-x^2)/sqrt(pi) * 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + ...)))),
/// evaluated bottom-up with 40 terms (converged to machine precision for x >= 4, finite for any
/// x up to +inf where it returns 0). x < 0 uses erfcx(x) = 2 exp(x^2) - erfcx(-x), which
/// overflows to +inf below about -26.6 as the true value does.
inline double erfcx(double x) {
  if (std::isnan(x)) return x;
  if (x < 0.0) return 2.0 * std::exp(x * x) - erfcx(-x);
  if (x < 4.0) return std::exp(x * x) * std::erfc(x);
  if (std::isinf(x)) return 0.0;
  double t = x;
  for (int n = 40; n >= 1; --n) t = x + 0.5 * n / t;
  return 1.0 / (std::sqrt(std::numbers::pi) * t);
}

/// erfc(a) / erfc(b) without underflow for large non-negative arguments.
inline double erfc_ratio(double a, double b) {
  if (a >= 0.0 && b >= 0.0) return erfcx(a) / erfcx(b) * std::exp((b - a) * (b + a));
  return std::erfc(a) / std::erfc(b);
}

/// exp(a^2) * (erf(b) - erf(a)) for 0 <= a <= b, accurate for small and large arguments
/// (erf difference for b < 0.5, erfcx form otherwise, so neither cancels nor underflows).
inline double scaled_erf_difference(double a, double b) {
  if (b < 0.5) return std::exp(a * a) * (std::erf(b) - std::erf(a));
  return erfcx(a) - std::exp((a - b) * (a + b)) * erfcx(b);
}

// ---------------------------------------------------------------------------------------------
// Root finding
// ---------------------------------------------------------------------------------------------

/// Brent's method (inverse quadratic interpolation / secant / bisection) on a bracket [a, b]
/// with f(a) and f(b) of opposite sign (or one of them zero). Converges to |b - a| <= 2*tol
/// with tol = 2 eps |x| + xtol. Throws std::invalid_argument if the bracket is not valid and
/// std::runtime_error if it does not converge within max_iter.
inline double brent_root(const std::function<double(double)>& f, double a, double b,
                         double xtol = 0.0, int max_iter = 300) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  double fa = f(a), fb = f(b);
  if (std::isnan(fa) || std::isnan(fb))
    throw std::invalid_argument("brent_root: f is NaN at a bracket end");
  if (fa == 0.0) return a;
  if (fb == 0.0) return b;
  if ((fa > 0.0) == (fb > 0.0))
    throw std::invalid_argument("brent_root: f(a) and f(b) have the same sign");
  double c = a, fc = fa, d = b - a, e = d;
  for (int iter = 0; iter < max_iter; ++iter) {
    if ((fb > 0.0) == (fc > 0.0)) {  // keep the root between b and c
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::fabs(fc) < std::fabs(fb)) {  // b is the best estimate
      a = b; b = c; c = a;
      fa = fb; fb = fc; fc = fa;
    }
    const double tol = 2.0 * eps * std::fabs(b) + 0.5 * xtol;
    const double m = 0.5 * (c - b);
    if (std::fabs(m) <= tol || fb == 0.0) return b;
    if (std::fabs(e) >= tol && std::fabs(fa) > std::fabs(fb)) {
      double p, q, r;
      const double s = fb / fa;
      if (a == c) {  // secant
        p = 2.0 * m * s;
        q = 1.0 - s;
      } else {  // inverse quadratic interpolation
        q = fa / fc;
        r = fb / fc;
        p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0));
        q = (q - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0.0) q = -q; else p = -p;
      if (2.0 * p < std::min(3.0 * m * q - std::fabs(tol * q), std::fabs(e * q))) {
        e = d;
        d = p / q;
      } else {  // interpolation rejected: bisect
        d = m;
        e = m;
      }
    } else {
      d = m;
      e = m;
    }
    a = b;
    fa = fb;
    b += (std::fabs(d) > tol) ? d : (m > 0.0 ? tol : -tol);
    fb = f(b);
    if (std::isnan(fb)) throw std::runtime_error("brent_root: f returned NaN");
  }
  throw std::runtime_error("brent_root: no convergence");
}

/// For f positive at lo and eventually negative: grows hi geometrically (factor 2) from the
/// starting value until f(hi) < 0, then returns {lo, hi}. Throws if hi exceeds hi_max.
inline std::pair<double, double> expand_bracket_down_crossing(const std::function<double(double)>& f,
                                                              double lo, double hi, double hi_max) {
  if (!(f(lo) > 0.0)) throw std::invalid_argument("expand_bracket: f(lo) must be positive");
  while (!(f(hi) < 0.0)) {
    lo = hi;  // f(hi) >= 0 here, so the crossing lies above it
    hi *= 2.0;
    if (hi > hi_max) throw std::runtime_error("expand_bracket: no sign change found");
  }
  return {lo, hi};
}

namespace detail {
inline void require_xt(double x, double t, const char* who) {
  if (!(x >= 0.0) || !(t >= 0.0))
    throw std::domain_error(std::string(who) + ": requires x >= 0 and t >= 0");
}
inline void require(bool ok, const char* msg) {
  if (!ok) throw std::invalid_argument(msg);
}
}  // namespace detail

// ---------------------------------------------------------------------------------------------
// 1. Semi-infinite conduction, surface temperature step
//    T(x,t) = Ts + (Ti - Ts) erf(x / (2 sqrt(alpha t))),  T(x,0) = Ti, T(0,t>0) = Ts.
// ---------------------------------------------------------------------------------------------

inline double semi_infinite_step(double x, double t, double alpha, double Ts, double Ti) {
  detail::require_xt(x, t, "semi_infinite_step");
  if (x == 0.0) return Ts;
  if (t == 0.0) return Ti;
  return Ts + (Ti - Ts) * std::erf(x / (2.0 * std::sqrt(alpha * t)));
}

struct SemiInfiniteStep {
  double alpha;  ///< thermal diffusivity k/C [m^2/s]
  double Ts;     ///< surface temperature for t > 0
  double Ti;     ///< initial temperature
  double temperature(double x, double t) const { return semi_infinite_step(x, t, alpha, Ts, Ti); }
  double operator()(double x, double t) const { return temperature(x, t); }
};

// ---------------------------------------------------------------------------------------------
// 2. Semi-infinite conduction with a convective surface (Carslaw & Jaeger 1959, §2.7):
//    -k dT/dx(0,t) = h (Ta - T(0,t)), T(x,0) = Ti:
//    (T - Ti)/(Ta - Ti) = erfc(xi) - exp(h x/k + h^2 alpha t/k^2) erfc(xi + beta),
//    xi = x/(2 sqrt(alpha t)), beta = h sqrt(alpha t)/k.
//    Since h x/k = 2 xi beta, exp(2 xi beta + beta^2) erfc(xi + beta) = exp(-xi^2) erfcx(xi + beta),
//    which never overflows (h -> inf recovers the step solution with Ts = Ta).
// ---------------------------------------------------------------------------------------------

inline double semi_infinite_convective(double x, double t, double k, double alpha, double h,
                                       double Ta, double Ti) {
  detail::require_xt(x, t, "semi_infinite_convective");
  if (t == 0.0) return Ti;
  const double s = std::sqrt(alpha * t);
  const double xi = x / (2.0 * s);
  const double beta = h * s / k;
  const double theta = std::erfc(xi) - std::exp(-xi * xi) * erfcx(xi + beta);
  return Ti + (Ta - Ti) * theta;
}

struct SemiInfiniteConvective {
  double k;      ///< conductivity [W/m/K]
  double alpha;  ///< diffusivity [m^2/s]
  double h;      ///< surface heat-transfer coefficient [W/m^2/K]
  double Ta;     ///< ambient temperature
  double Ti;     ///< initial temperature
  double temperature(double x, double t) const {
    return semi_infinite_convective(x, t, k, alpha, h, Ta, Ti);
  }
  double operator()(double x, double t) const { return temperature(x, t); }
};

// ---------------------------------------------------------------------------------------------
// 3. Two-phase Neumann problem (Kurylyk et al. 2014 benchmark 1 / INTERFROST TH1 form).
//    Zone 1 (0 < x < X): the changed phase (frozen when freezing, thawed when thawing), k1, C1.
//    Zone 2 (x > X): the initial phase, k2, C2. Sharp front at Tf, X(t) = 2 lambda sqrt(alpha1 t).
//      T1 = Ts + (Tf - Ts) erf(x/(2 sqrt(alpha1 t))) / erf(lambda)
//      T2 = Ti + (Tf - Ti) erfc(x/(2 sqrt(alpha2 t))) / erfc(lambda sqrt(alpha1/alpha2))
//    Stefan condition s (k1 dT1/dx - k2 dT2/dx) = L_v dX/dt at x = X gives
//      k1 (Tf-Ts) e^{-l^2}/(sqrt(a1) erf l) - k2 (Ti-Tf) e^{-l^2 a1/a2}/(sqrt(a2) erfc(l sqrt(a1/a2)))
//        = s l L_v sqrt(pi a1),           s = +1 freezing, -1 thawing.
// ---------------------------------------------------------------------------------------------

struct NeumannParams {
  double k1;   ///< conductivity of the changed phase (zone 1, next to the surface)
  double k2;   ///< conductivity of the initial phase (zone 2)
  double C1;   ///< volumetric heat capacity, zone 1 [J/m^3/K]
  double C2;   ///< volumetric heat capacity, zone 2 [J/m^3/K]
  double L_v;  ///< volumetric latent heat released/absorbed at the front [J/m^3]
  double Ts;   ///< surface temperature for t > 0
  double Ti;   ///< initial temperature
  double Tf;   ///< phase-change temperature
  int s;       ///< +1 freezing (Ts < Tf <= Ti), -1 thawing (Ts > Tf >= Ti)
};

class NeumannSolution {
 public:
  explicit NeumannSolution(const NeumannParams& p) : p_(p) {
    detail::require(p.k1 > 0 && p.k2 > 0 && p.C1 > 0 && p.C2 > 0, "Neumann: k and C must be > 0");
    detail::require(p.s == 1 || p.s == -1, "Neumann: s must be +1 (freezing) or -1 (thawing)");
    detail::require(p.s * (p.Tf - p.Ts) > 0.0, "Neumann: surface temperature must be on the changed side of Tf");
    detail::require(p.s * (p.Ti - p.Tf) >= 0.0, "Neumann: initial temperature must be on the unchanged side of Tf");
    detail::require(p.L_v >= 0.0 && (p.L_v > 0.0 || p.Ti != p.Tf), "Neumann: degenerate problem");
    a1_ = p.k1 / p.C1;
    a2_ = p.k2 / p.C2;
    r_ = std::sqrt(a1_ / a2_);
    // g(l) = s * residual(l) is +inf at 0+, strictly decreasing, and -> -inf: unique root.
    const auto g = [this](double l) { return p_.s * residual(l); };
    auto [lo, hi] = expand_bracket_down_crossing(g, 1e-12, 1.0, 1e6);
    lambda_ = brent_root(g, lo, hi);
  }

  /// Residual LHS - RHS of the transcendental equation (W/m^2 * sqrt(s)); zero at lambda().
  double residual(double l) const {
    const double t1 = p_.k1 * (p_.Tf - p_.Ts) * std::exp(-l * l) / (std::sqrt(a1_) * std::erf(l));
    const double t2 = p_.k2 * (p_.Ti - p_.Tf) / (std::sqrt(a2_) * erfcx(l * r_));
    return t1 - t2 - p_.s * l * p_.L_v * std::sqrt(std::numbers::pi * a1_);
  }

  double lambda() const { return lambda_; }
  double alpha1() const { return a1_; }
  double alpha2() const { return a2_; }
  const NeumannParams& params() const { return p_; }

  /// Front position X(t) = 2 lambda sqrt(alpha1 t) [m].
  double front(double t) const {
    detail::require_xt(0.0, t, "Neumann::front");
    return 2.0 * lambda_ * std::sqrt(a1_ * t);
  }
  /// Front speed dX/dt [m/s] (t > 0).
  double front_speed(double t) const { return lambda_ * std::sqrt(a1_ / t); }

  /// Analytic expression of zone 1 or 2 evaluated at any x >= 0 (smooth extension past the
  /// front; used for one-sided derivatives in tests). t > 0.
  double zone_temperature(int zone, double x, double t) const {
    if (zone == 1)
      return p_.Ts + (p_.Tf - p_.Ts) * std::erf(x / (2.0 * std::sqrt(a1_ * t))) / std::erf(lambda_);
    return p_.Ti + (p_.Tf - p_.Ti) * erfc_ratio(x / (2.0 * std::sqrt(a2_ * t)), lambda_ * r_);
  }

  double temperature(double x, double t) const {
    detail::require_xt(x, t, "Neumann::temperature");
    if (x == 0.0) return p_.Ts;
    if (t == 0.0) return p_.Ti;
    return zone_temperature(x < front(t) ? 1 : 2, x, t);
  }
  double operator()(double x, double t) const { return temperature(x, t); }

 private:
  NeumannParams p_;
  double a1_ = 0, a2_ = 0, r_ = 0, lambda_ = 0;
};

// ---------------------------------------------------------------------------------------------
// 4. Lunardini three-zone freezing (McKenzie, Voss & Siegel 2007, Adv. Water Resour. 30:966;
//    INTERFROST T1). Surface stepped from T0 to Ts; ice content linear in T between Tm and Tf
//    (unfrozen water mass ratio xi0 at/above Tf falling linearly to xiF at Tm, constant below).
//    All latent heat is released inside the mushy zone, so there is no latent jump at either
//    front, only temperature and flux continuity.
//      zone 1 frozen  0 < x < X1:  alpha1 = k1/C1
//      zone 2 mushy   X1 < x < X2: alpha2 = k2/(C2 + rho_d L (xi0 - xiF)/(Tf - Tm))   (apparent C)
//      zone 3 thawed  x > X2:      alpha3 = k3/C3
//    X1 = 2 psi sqrt(alpha1 t),  X2 = 2 gamma sqrt(alpha2 t)
//      T1 = Ts + (Tm - Ts) erf(x/(2 sqrt(a1 t))) / erf(psi)
//      T2 = Tm + (Tf - Tm) [erf(x/(2 sqrt(a2 t))) - erf(psi sqrt(a1/a2))] / [erf(gamma) - erf(psi sqrt(a1/a2))]
//      T3 = T0 + (Tf - T0) erfc(x/(2 sqrt(a3 t))) / erfc(gamma sqrt(a2/a3))
//    Root equations (flux continuity, common factors removed), D = erf(gamma) - erf(psi sqrt(a1/a2)):
//      at X1:  k1 (Tm-Ts) e^{-psi^2} / (sqrt(a1) erf psi) - k2 (Tf-Tm) e^{-psi^2 a1/a2} / (sqrt(a2) D) = 0
//      at X2:  k2 (Tf-Tm) e^{-gamma^2} / (sqrt(a2) D) - k3 (T0-Tf) e^{-gamma^2 a2/a3} / (sqrt(a3) erfc(gamma sqrt(a2/a3))) = 0
//    (the "-" before the mushy-side term in the X1 equation is the sign that reproduces the published values).
//    Solved as nested 1-D problems: for fixed gamma the X1 equation is strictly decreasing in
//    psi on (0, gamma sqrt(a2/a1)) (+inf -> -inf), and the resulting X2 residual goes from +inf
//    (gamma -> 0) to -inf (gamma -> inf); both are solved with brent_root.
// ---------------------------------------------------------------------------------------------

struct LunardiniParams {
  double k1, k2, k3;  ///< conductivity frozen / mushy / thawed [W/m/K]
  double C1, C2, C3;  ///< volumetric heat capacity frozen / mushy (sensible only) / thawed [J/m^3/K]
  double rho_d;       ///< dry density [kg/m^3]
  double xiF;         ///< unfrozen water mass ratio (water/solids) in the frozen zone (at and below Tm)
  double xi0;         ///< total water mass ratio (unfrozen at and above Tf)
  double L;           ///< latent heat [J/kg]
  double Ts;          ///< surface temperature for t > 0 (Ts < Tm)
  double T0;          ///< initial temperature (T0 > Tf)
  double Tf;          ///< freezing (liquidus) temperature
  double Tm;          ///< temperature at which the mushy zone ends (Tm < Tf)
};

class LunardiniSolution {
 public:
  explicit LunardiniSolution(const LunardiniParams& p) : p_(p) {
    detail::require(p.k1 > 0 && p.k2 > 0 && p.k3 > 0 && p.C1 > 0 && p.C2 > 0 && p.C3 > 0,
                    "Lunardini: k and C must be > 0");
    detail::require(p.Ts < p.Tm && p.Tm < p.Tf && p.Tf < p.T0,
                    "Lunardini: requires Ts < Tm < Tf < T0 (freezing)");
    detail::require(p.rho_d >= 0 && p.L >= 0 && p.xi0 >= p.xiF, "Lunardini: invalid latent data");
    a1_ = p.k1 / p.C1;
    a2_ = p.k2 / mushy_heat_capacity();
    a3_ = p.k3 / p.C3;
    const auto g = [this](double gam) { return x2_residual(gam, psi_for_gamma(gam)); };
    auto [lo, hi] = expand_bracket_down_crossing(g, 1e-9, 1.0, 1e7);
    gamma_ = brent_root(g, lo, hi);
    psi_ = psi_for_gamma(gamma_);
  }

  /// Apparent volumetric heat capacity of the mushy zone, C2 + rho_d L (xi0 - xiF)/(Tf - Tm).
  double mushy_heat_capacity() const {
    return p_.C2 + p_.rho_d * p_.L * (p_.xi0 - p_.xiF) / (p_.Tf - p_.Tm);
  }

  /// Residual of the X1 (frozen/mushy) flux balance for given psi, gamma (0 < z1 < gamma).
  double x1_residual(double psi, double gam) const {
    const double z1 = psi * std::sqrt(a1_ / a2_);
    const double Dx = scaled_erf_difference(z1, gam);  // e^{z1^2} D
    return p_.k1 * (p_.Tm - p_.Ts) * std::exp(-psi * psi) / (std::sqrt(a1_) * std::erf(psi)) -
           p_.k2 * (p_.Tf - p_.Tm) / (std::sqrt(a2_) * Dx);
  }
  /// Residual of the X2 (mushy/thawed) flux balance for given psi, gamma.
  double x2_residual(double gam, double psi) const {
    const double z1 = psi * std::sqrt(a1_ / a2_);
    const double Dx = scaled_erf_difference(z1, gam);
    const double w = gam * std::sqrt(a2_ / a3_);
    return p_.k2 * (p_.Tf - p_.Tm) * std::exp((z1 - gam) * (z1 + gam)) / (std::sqrt(a2_) * Dx) -
           p_.k3 * (p_.T0 - p_.Tf) / (std::sqrt(a3_) * erfcx(w));
  }

  double psi() const { return psi_; }
  double gamma() const { return gamma_; }
  double alpha1() const { return a1_; }
  double alpha2() const { return a2_; }  ///< mushy-zone apparent diffusivity (includes latent heat)
  double alpha3() const { return a3_; }
  const LunardiniParams& params() const { return p_; }

  /// Frozen/mushy boundary (T = Tm): X1 = 2 psi sqrt(alpha1 t).
  double front_frozen(double t) const {
    detail::require_xt(0.0, t, "Lunardini::front_frozen");
    return 2.0 * psi_ * std::sqrt(a1_ * t);
  }
  /// Mushy/thawed boundary (T = Tf): X2 = 2 gamma sqrt(alpha2 t).
  double front_thawed(double t) const {
    detail::require_xt(0.0, t, "Lunardini::front_thawed");
    return 2.0 * gamma_ * std::sqrt(a2_ * t);
  }

  /// Analytic expression of zone 1, 2 or 3 at any x >= 0 (smooth extension; t > 0).
  double zone_temperature(int zone, double x, double t) const {
    if (zone == 1)
      return p_.Ts + (p_.Tm - p_.Ts) * std::erf(x / (2.0 * std::sqrt(a1_ * t))) / std::erf(psi_);
    if (zone == 2) {
      const double z1 = psi_ * std::sqrt(a1_ / a2_);
      const double eta = x / (2.0 * std::sqrt(a2_ * t));
      double num;
      if (eta >= z1) {
        num = scaled_erf_difference(z1, eta);
      } else {  // extension below X1
        num = -scaled_erf_difference(eta, z1) * std::exp((z1 - eta) * (z1 + eta));
      }
      return p_.Tm + (p_.Tf - p_.Tm) * num / scaled_erf_difference(z1, gamma_);
    }
    const double w = gamma_ * std::sqrt(a2_ / a3_);
    return p_.T0 + (p_.Tf - p_.T0) * erfc_ratio(x / (2.0 * std::sqrt(a3_ * t)), w);
  }

  /// Zone index (1 frozen, 2 mushy, 3 thawed) of depth x at time t > 0.
  int zone(double x, double t) const {
    if (x < front_frozen(t)) return 1;
    if (x < front_thawed(t)) return 2;
    return 3;
  }

  double temperature(double x, double t) const {
    detail::require_xt(x, t, "Lunardini::temperature");
    if (x == 0.0) return p_.Ts;
    if (t == 0.0) return p_.T0;
    return zone_temperature(zone(x, t), x, t);
  }
  double operator()(double x, double t) const { return temperature(x, t); }

  /// Unfrozen water mass ratio (water/solids) at (x, t): xi0 above Tf, xiF below Tm, linear between.
  double unfrozen_water_ratio(double x, double t) const {
    const double T = temperature(x, t);
    if (T >= p_.Tf) return p_.xi0;
    if (T <= p_.Tm) return p_.xiF;
    return p_.xiF + (p_.xi0 - p_.xiF) * (T - p_.Tm) / (p_.Tf - p_.Tm);
  }

 private:
  double psi_for_gamma(double gam) const {
    const double psi_max = gam * std::sqrt(a2_ / a1_);  // X1 = X2
    const auto f = [&](double psi) { return x1_residual(psi, gam); };
    double lo = psi_max * 1e-12, hi = psi_max * (1.0 - 1e-12);
    return brent_root(f, lo, hi);
  }

  LunardiniParams p_;
  double a1_ = 0, a2_ = 0, a3_ = 0, psi_ = 0, gamma_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Error norms and observed convergence order
// ---------------------------------------------------------------------------------------------

struct ProfileError {
  double rmse = 0.0;      ///< sqrt(mean((T_i - T_exact(x_i))^2))
  double max_abs = 0.0;   ///< max |T_i - T_exact(x_i)|
  double x_at_max = 0.0;  ///< position of the maximum error
  std::size_t n = 0;      ///< number of points compared
};

/// Errors of a simulated profile (x_i, T_i) against exact(x).
template <class F>
ProfileError profile_error(const std::vector<double>& x, const std::vector<double>& T, F&& exact) {
  if (x.size() != T.size()) throw std::invalid_argument("profile_error: x and T differ in size");
  if (x.empty()) throw std::invalid_argument("profile_error: empty profile");
  ProfileError e;
  double sum2 = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = T[i] - static_cast<double>(exact(x[i]));
    if (std::isnan(d)) throw std::domain_error("profile_error: NaN in profile or reference");
    sum2 += d * d;
    if (std::fabs(d) > e.max_abs) {
      e.max_abs = std::fabs(d);
      e.x_at_max = x[i];
    }
  }
  e.n = x.size();
  e.rmse = std::sqrt(sum2 / static_cast<double>(e.n));
  return e;
}

/// Errors of a simulated profile at time t against exact(x, t) (any solution above, or a lambda).
template <class F>
ProfileError profile_error(const std::vector<double>& x, const std::vector<double>& T, double t,
                           F&& exact) {
  return profile_error(x, T, [&](double xi) { return exact(xi, t); });
}

/// Observed order from errors e1, e2 at resolutions h1, h2: log(e1/e2)/log(h1/h2).
inline double observed_order(double e1, double e2, double h1, double h2) {
  if (!(e1 > 0 && e2 > 0 && h1 > 0 && h2 > 0) || h1 == h2)
    throw std::invalid_argument("observed_order: needs positive errors and distinct positive h");
  return std::log(e1 / e2) / std::log(h1 / h2);
}

/// Observed orders between successive resolutions (result has size h.size() - 1).
inline std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& e) {
  if (h.size() != e.size() || h.size() < 2)
    throw std::invalid_argument("observed_orders: need >= 2 (h, e) pairs of equal length");
  std::vector<double> p;
  for (std::size_t i = 0; i + 1 < h.size(); ++i) p.push_back(observed_order(e[i], e[i + 1], h[i], h[i + 1]));
  return p;
}

}  // namespace frostmpm::analytic
