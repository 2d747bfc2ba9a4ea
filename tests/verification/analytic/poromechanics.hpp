// Closed-form reference solutions for poromechanics and small-strain elastodynamics.
//
// Header-only, standard library only, double precision. Used by the verification tests to compare
// simulated consolidation, thaw consolidation, wave and stress-rate results against exact solutions.
// The published numbers quoted below are recomputed independently (numpy/scipy: brute-force series,
// scipy root finding, quadrature, a finite-difference wave solver) by check_poromechanics.py.
//
// Contents
//   oedometric_modulus, axial_wave_modulus, consolidation_coefficient   moduli and c_v helpers
//   terzaghi_pressure, terzaghi_degree            Terzaghi (1943) 1-D consolidation
//   MandelSolution, mandel_*                      Mandel (1953) plane-strain squeeze
//                                                 (Cheng & Detournay 1988; Abousleiman et al. 1996)
//   ThawConsolidation, thaw_degree_*              Morgenstern & Nixon (1971) thaw consolidation
//   SealedMelting                                 undrained melting: suction = skeleton compression
//   ElasticColumn                                 confined column under suddenly applied gravity
//   VibratingBar                                  first-mode (or n-th mode) axial vibration, fixed-free
//   jaumann_*, rigid_rotation_exact               Jaumann-rate update of a rigidly rotated stress
//
// Conventions: lengths in m, times in s, stresses and moduli in Pa, compression and settlement
// positive where stated. Invalid arguments throw std::invalid_argument / std::domain_error.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace frostmpm::analytic {

namespace poro_detail {
inline void require(bool ok, const char* msg) {
  if (!ok) throw std::invalid_argument(msg);
}
inline void require_domain(bool ok, const char* msg) {
  if (!ok) throw std::domain_error(msg);
}
// exp(-y) is below 1e-18 of the leading term once y exceeds this; used to truncate series.
inline constexpr double kSeriesCut = 42.0;
}  // namespace poro_detail

// ---------------------------------------------------------------------------------------------
// Moduli
// ---------------------------------------------------------------------------------------------

/// Constrained (oedometric, P-wave) modulus E_oed = E (1 - nu) / ((1 + nu)(1 - 2 nu)) = 1/m_v.
inline double oedometric_modulus(double E, double nu) {
  poro_detail::require(E > 0.0 && nu > -1.0 && nu < 0.5, "oedometric_modulus: needs E > 0, -1 < nu < 1/2");
  return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
}

/// Lateral condition of a bar or column carrying a 1-D axial wave. The long-wavelength axial
/// modulus differs: a laterally free 3-D bar (or a 2-D plane-stress strip) uses E; a plane-strain
/// strip with traction-free long faces uses E/(1 - nu^2); a laterally confined column (rollers on
/// the sides, uniaxial strain) uses E_oed. A plane-strain model is only "E_oed" if its sides are
/// constrained. (Free-face values hold when the width is small against the wavelength.)
enum class LateralCondition { free, free_plane_strain, confined };

inline double axial_wave_modulus(double E, double nu, LateralCondition c) {
  poro_detail::require(E > 0.0 && nu > -1.0 && nu < 0.5, "axial_wave_modulus: needs E > 0, -1 < nu < 1/2");
  switch (c) {
    case LateralCondition::free: return E;
    case LateralCondition::free_plane_strain: return E / (1.0 - nu * nu);
    case LateralCondition::confined: return oedometric_modulus(E, nu);
  }
  throw std::invalid_argument("axial_wave_modulus: unknown lateral condition");
}

/// Coefficient of consolidation c = (k / gamma_w) * M [m^2/s]: k hydraulic conductivity [m/s],
/// gamma_w unit weight of water [N/m^3], M the constrained modulus E_oed [Pa] (incompressible
/// grains and water). For Mandel's problem with incompressible constituents this is also c.
inline double consolidation_coefficient(double k, double gamma_w, double M) {
  poro_detail::require(k > 0.0 && gamma_w > 0.0 && M > 0.0, "consolidation_coefficient: needs positive k, gamma_w, M");
  return k / gamma_w * M;
}

// ---------------------------------------------------------------------------------------------
// 1. Terzaghi (1943) 1-D consolidation of a layer of thickness H, drained at z = 0, impermeable
//    at z = H, uniform initial excess pressure u0 (instantaneous load), T_v = c_v t / H^2:
//      u/u0 = sum_m (2/M) sin(M z/H) exp(-M^2 T_v),   M = pi (2m + 1)/2
//      U    = 1 - sum_m (2/M^2) exp(-M^2 T_v)          (average degree = settlement / final)
//    The Fourier series needs ~1/sqrt(T_v) terms at small T_v, so below T_v = 0.1 the equivalent
//    image (erfc) series is summed instead; it converges in a handful of terms there:
//      u/u0 = 1 - sum_n (-1)^n [erfc((2n + z/H)/(2 sqrt T_v)) + erfc((2n + 2 - z/H)/(2 sqrt T_v))]
//      U    = 2 sqrt(T_v/pi) + 4 sqrt(T_v) sum_{n>=1} (-1)^n ierfc(n/sqrt T_v)
//    (the leading 2 sqrt(T_v/pi) alone is exact to round-off for T_v < 0.02). Both forms agree
//    to 3e-16 where they overlap (checked in check_poromechanics.py).
// ---------------------------------------------------------------------------------------------

/// Excess pore pressure u/u0 at z/H in [0, 1] (0 = drained face, 1 = impermeable base), T_v >= 0.
inline double terzaghi_pressure(double z_over_H, double Tv) {
  poro_detail::require_domain(z_over_H >= 0.0 && z_over_H <= 1.0 && Tv >= 0.0,
                              "terzaghi_pressure: needs 0 <= z/H <= 1 and T_v >= 0");
  if (z_over_H == 0.0) return 0.0;
  if (Tv == 0.0) return 1.0;
  if (Tv < 0.1) {
    const double s = 2.0 * std::sqrt(Tv);
    double sum = 0.0;
    for (int n = 0; n < 60; ++n) {
      const double a = (2.0 * n + z_over_H) / s;
      if (a > 27.0) break;  // erfc(27) < 1e-318
      const double term = std::erfc(a) + std::erfc((2.0 * n + 2.0 - z_over_H) / s);
      sum += (n % 2 == 0) ? term : -term;
    }
    return 1.0 - sum;
  }
  const double M0 = 0.5 * std::numbers::pi;
  double sum = 0.0;
  for (int m = 0;; ++m) {
    const double M = std::numbers::pi * (2.0 * m + 1.0) / 2.0;
    if ((M * M - M0 * M0) * Tv > poro_detail::kSeriesCut) break;
    sum += 2.0 / M * std::sin(M * z_over_H) * std::exp(-M * M * Tv);
  }
  return sum;
}

/// Average degree of consolidation U(T_v) = settlement / final settlement, T_v >= 0.
inline double terzaghi_degree(double Tv) {
  poro_detail::require_domain(Tv >= 0.0, "terzaghi_degree: needs T_v >= 0");
  if (Tv == 0.0) return 0.0;
  if (Tv < 0.1) {
    const double r = std::sqrt(Tv);
    double sum = 0.0;
    for (int n = 1; n < 60; ++n) {
      const double x = n / r;
      if (x > 27.0) break;
      const double ierfc = std::exp(-x * x) / std::sqrt(std::numbers::pi) - x * std::erfc(x);
      sum += (n % 2 == 0) ? ierfc : -ierfc;
    }
    return 2.0 * r / std::sqrt(std::numbers::pi) + 4.0 * r * sum;
  }
  const double M0 = 0.5 * std::numbers::pi;
  double sum = 0.0;
  for (int m = 0;; ++m) {
    const double M = std::numbers::pi * (2.0 * m + 1.0) / 2.0;
    if ((M * M - M0 * M0) * Tv > poro_detail::kSeriesCut) break;
    sum += 2.0 / (M * M) * std::exp(-M * M * Tv);
  }
  return 1.0 - sum;
}

// ---------------------------------------------------------------------------------------------
// 2. Mandel's problem (Mandel 1953; Cheng & Detournay 1988; Abousleiman et al. 1996, Comput.
//    Mech. 17:143). Plane strain, |x| <= a, loaded by rigid frictionless impermeable plates with a
//    total force 2F (per unit out-of-plane length); lateral faces x = +-a drained and traction free.
//    T = c t / a^2, xi = x/a. Roots alpha_n of tan(alpha) = K alpha, K = (1 - nu)/(nu_u - nu) > 1:
//    exactly one in each (n pi, n pi + pi/2), n = 0, 1, 2, ... (tan - K alpha is convex there and
//    changes sign; none in (n pi + pi/2, (n+1) pi) where tan < 0). alpha(0) is the "alpha_1" of
//    the literature (1.364368 for nu = 0.3, nu_u = 1/2). With
//      a_n = sin(alpha_n) / (alpha_n - sin(alpha_n) cos(alpha_n)):
//      p/p0        = 2 sum a_n (cos(alpha_n xi) - cos(alpha_n)) exp(-alpha_n^2 T)
//      p0          = B (1 + nu_u) F / (3a)          (undrained pressure at t = 0+; F/(2a) for B = 1, nu_u = 1/2)
//      eps_yy G a/F = -(1 - nu)/2 + (1 - nu_u) sum a_n cos(alpha_n) exp(-alpha_n^2 T)
//      u_x G/F     = [nu/2 - nu_u sum a_n cos(alpha_n) exp(-alpha_n^2 T)] xi
//                    + sum [cos(alpha_n)/(alpha_n - sin cos)] sin(alpha_n xi) exp(-alpha_n^2 T)
//      sigma_yy a/F = -1 - 2 (nu_u - nu)/(1 - nu) sum a_n cos(alpha_n xi) exp(-alpha_n^2 T)
//                    + 2 sum a_n cos(alpha_n) exp(-alpha_n^2 T)      (tension positive; sigma_xx = 0)
//    The vertical strain follows from sigma_xx = 0, the plate force balance and the mean pressure:
//    eps_yy = -F(1 - nu)/(2Ga) + alpha_B (1 - 2nu) pbar/(2G) (pbar the mean over the width), which
//    with alpha_B = 3(nu_u - nu)/(B(1 - 2nu)(1 + nu_u)) and sin(alpha) = K alpha cos(alpha) gives the
//    series above. Limits: sum a_n cos(alpha_n) -> (nu_u - nu)/(2(1 - nu_u)) as T -> 0, so the
//    undrained strain is -F(1 - nu_u)/(2Ga); the drained one is -F(1 - nu)/(2Ga).
//    c = 2 kappa B^2 G (1 - nu)(1 + nu_u)^2 / (9 (1 - nu_u)(nu_u - nu)), kappa = k/gamma_w; for
//    incompressible constituents (B = 1, nu_u = 1/2) this is kappa E_oed.
//    At T -> 0+ the centre pressure tends to 1 like 1 + 0.32 sqrt(T) (nu = 0.3): the T = 0 series
//    converges only conditionally (terms ~ 2(-1)^n/alpha_n) to 1, so T = 0 returns 1 exactly and
//    T > 0 sums ~ sqrt(42/T)/pi terms (T >= 1e-10 required). The centre pressure then rises above
//    p0 (Mandel-Cryer effect): peak 1.076380 at T = 0.063953 for nu = 0.3, nu_u = 1/2.
// ---------------------------------------------------------------------------------------------

class MandelSolution {
 public:
  /// Drained and undrained Poisson ratios, -1 < nu < nu_u <= 1/2.
  explicit MandelSolution(double nu, double nu_u = 0.5) : nu_(nu), nu_u_(nu_u) {
    poro_detail::require(nu > -1.0 && nu < nu_u && nu_u <= 0.5, "Mandel: needs -1 < nu < nu_u <= 1/2");
    K_ = (1.0 - nu) / (nu_u - nu);
  }

  double nu() const { return nu_; }
  double nu_u() const { return nu_u_; }
  double K() const { return K_; }  ///< (1 - nu)/(nu_u - nu)

  /// n-th positive root (n = 0, 1, ...) of tan(alpha) = K alpha, in (n pi, n pi + pi/2).
  double root(std::size_t n) const {
    ensure_roots(n + 1);
    return roots_[n];
  }

  /// p(x, t)/p0 at xi = x/a in [-1, 1]; 0 on the drained faces |xi| = 1, 1 inside at T = 0.
  double pressure(double xi, double T) const {
    poro_detail::require_domain(std::fabs(xi) <= 1.0, "Mandel::pressure: needs |x/a| <= 1");
    if (check_time(T)) return std::fabs(xi) == 1.0 ? 0.0 : 1.0;
    return 2.0 * sum(T, 0.0, [xi](double al, double s, double c) {
             return s / (al - s * c) * (std::cos(al * xi) - c);
           });
  }

  /// Centre pressure p(0, t)/p0.
  double centre_pressure(double T) const { return pressure(0.0, T); }

  /// Vertical strain eps_yy * G a / F (negative: compression). Plate settlement of a specimen of
  /// height h (bottom plate fixed) is -eps_yy h = -vertical_strain(T) * F h/(G a).
  double vertical_strain(double T) const {
    poro_detail::require_domain(T >= 0.0, "Mandel: needs T >= 0");
    return -0.5 * (1.0 - nu_) + (1.0 - nu_u_) * cos_sum(T);
  }

  /// Horizontal displacement u_x * G / F at xi = x/a (outward positive for xi > 0). At T = 0 the
  /// undrained response is uniform, eps_xx = nu_u F/(2Ga), so u_x G/F = nu_u xi/2 (the sine series
  /// converges only slowly to that there).
  double horizontal_displacement(double xi, double T) const {
    poro_detail::require_domain(std::fabs(xi) <= 1.0, "Mandel: needs |x/a| <= 1");
    if (check_time(T)) return 0.5 * nu_u_ * xi;
    const double lateral = sum(T, 0.0, [xi](double al, double s, double c) {
      return c / (al - s * c) * std::sin(al * xi);
    });
    return (0.5 * nu_ - nu_u_ * cos_sum(T)) * xi + lateral;
  }

  /// Total vertical stress sigma_yy * a / F at xi (tension positive; integrates to -2 over xi).
  double vertical_stress(double xi, double T) const {
    poro_detail::require_domain(std::fabs(xi) <= 1.0, "Mandel: needs |x/a| <= 1");
    if (check_time(T)) return -1.0;  // undrained: uniform -F/a
    const double Sx = sum(T, 0.0, [xi](double al, double s, double c) {
      return s / (al - s * c) * std::cos(al * xi);
    });
    return -1.0 - 2.0 * (nu_u_ - nu_) / (1.0 - nu_) * Sx + 2.0 * cos_sum(T);
  }

  /// d/dT of the centre pressure p(0,t)/p0 (T > 0).
  double centre_pressure_rate(double T) const {
    poro_detail::require_domain(T >= 1e-10, "Mandel: rate needs T >= 1e-10");
    return -2.0 * sum(T, 8.0, [](double al, double s, double c) {
             return s / (al - s * c) * (1.0 - c) * al * al;
           });
  }

  struct Peak {
    double T;      ///< dimensionless time of the maximum centre pressure
    double value;  ///< p(0, T)/p0 there
  };

  /// Maximum of the centre pressure (Mandel-Cryer peak): bracket the sign change of dp/dT, then
  /// bisect to round-off (p(0,T) rises from 1 like sqrt(T), peaks once, then decays).
  Peak centre_pressure_peak() const {
    double lo = 0.05, hi = 0.05;
    while (centre_pressure_rate(lo) <= 0.0) {
      lo *= 0.5;
      if (lo < 1e-9) throw std::runtime_error("Mandel: no rising branch found");
    }
    while (centre_pressure_rate(hi) >= 0.0) {
      hi *= 2.0;
      if (hi > 1e3) throw std::runtime_error("Mandel: no falling branch found");
    }
    for (int i = 0; i < 200 && hi - lo > 4.0 * std::numeric_limits<double>::epsilon() * hi; ++i) {
      const double mid = 0.5 * (lo + hi);
      (centre_pressure_rate(mid) > 0.0 ? lo : hi) = mid;
    }
    const double T = 0.5 * (lo + hi);
    return {T, centre_pressure(T)};
  }

  /// Undrained initial pressure p0 = B (1 + nu_u) F/(3a); F is half the total plate force.
  static double initial_pressure(double F, double a, double B = 1.0, double nu_u = 0.5) {
    return B * (1.0 + nu_u) * F / (3.0 * a);
  }

  /// c = 2 kappa B^2 G (1 - nu)(1 + nu_u)^2 / (9 (1 - nu_u)(nu_u - nu)), kappa = k/gamma_w [m^2/(Pa s)].
  static double consolidation_coefficient(double kappa, double G, double nu, double nu_u, double B) {
    poro_detail::require(nu < nu_u && nu_u <= 0.5 && kappa > 0.0 && G > 0.0 && B > 0.0 && B <= 1.0,
                         "Mandel: needs nu < nu_u <= 1/2, kappa, G > 0, 0 < B <= 1");
    return 2.0 * kappa * B * B * G * (1.0 - nu) * (1.0 + nu_u) * (1.0 + nu_u) /
           (9.0 * (1.0 - nu_u) * (nu_u - nu));
  }

 private:
  // True (and T == 0) for the undrained instant; throws for T < 0 or 0 < T < 1e-10.
  static bool check_time(double T) {
    poro_detail::require_domain(T >= 0.0, "Mandel: needs T >= 0");
    if (T == 0.0) return true;
    poro_detail::require_domain(T >= 1e-10, "Mandel: 0 < T < 1e-10 needs too many terms");
    return false;
  }

  // sum_n term(alpha_n, sin, cos) exp(-alpha_n^2 T), truncated when the exponential has fallen
  // below exp(-(kSeriesCut + extra)) of the first term's.
  template <class Term>
  double sum(double T, double extra, Term&& term) const {
    const double a0 = root(0);
    double s = 0.0;
    for (std::size_t n = 0;; ++n) {
      const double al = root(n);
      if (n > 0 && (al * al - a0 * a0) * T > poro_detail::kSeriesCut + extra) break;
      s += term(al, std::sin(al), std::cos(al)) * std::exp(-al * al * T);
    }
    return s;
  }

  // sum a_n cos(alpha_n) exp(-alpha_n^2 T); at T = 0 its terms fall like 1/(K alpha^2), and the
  // closed form (nu_u - nu)/(2(1 - nu_u)) is used instead.
  double cos_sum(double T) const {
    if (T == 0.0) return (nu_u_ - nu_) / (2.0 * (1.0 - nu_u_));
    poro_detail::require_domain(T >= 1e-10, "Mandel: 0 < T < 1e-10 needs too many terms");
    return sum(T, 0.0, [](double al, double s, double c) { return s * c / (al - s * c); });
  }

  void ensure_roots(std::size_t count) const {
    constexpr double pi = std::numbers::pi;
    while (roots_.size() < count) {
      const double n = static_cast<double>(roots_.size());
      // g(alpha) = sin(alpha) - K alpha cos(alpha): sign change across the bracket, smooth inside.
      double lo = n * pi + (n == 0.0 ? 1e-8 : 0.0), hi = n * pi + 0.5 * pi;
      const auto g = [this](double al) { return std::sin(al) - K_ * al * std::cos(al); };
      const double glo = g(lo);
      // Newton from the large-n asymptote, safeguarded by bisection on [lo, hi].
      double x = n == 0.0 ? 0.5 * (lo + hi) : hi - 1.0 / (K_ * hi);
      if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
      for (int it = 0; it < 200; ++it) {
        const double gx = g(x);
        if (gx == 0.0) break;
        ((gx > 0.0) == (glo > 0.0) ? lo : hi) = x;
        const double dg = (1.0 - K_) * std::cos(x) + K_ * x * std::sin(x);
        double xn = x - gx / dg;
        if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
        if (std::fabs(xn - x) <= 2.0 * std::numeric_limits<double>::epsilon() * x) {
          x = xn;
          break;
        }
        x = xn;
      }
      roots_.push_back(x);
    }
  }

  double nu_, nu_u_, K_;
  mutable std::vector<double> roots_;  // cache; one object is not safe for concurrent use
};

/// p(0, t)/p0 for Mandel's problem at T = c t/a^2 (nu_u = 1/2: incompressible constituents).
inline double mandel_centre_pressure(double T, double nu, double nu_u = 0.5) {
  return MandelSolution(nu, nu_u).centre_pressure(T);
}

/// Mandel-Cryer peak of the centre pressure: {T_peak, p(0, T_peak)/p0}.
inline MandelSolution::Peak mandel_centre_pressure_peak(double nu, double nu_u = 0.5) {
  return MandelSolution(nu, nu_u).centre_pressure_peak();
}

/// Top-plate settlement [m] of a Mandel specimen of height h on a fixed bottom plate:
/// -eps_yy h with eps_yy from MandelSolution::vertical_strain (F half the total force, G shear modulus).
inline double mandel_plate_settlement(double T, double nu, double nu_u, double F, double G, double a,
                                      double h) {
  return -MandelSolution(nu, nu_u).vertical_strain(T) * F * h / (G * a);
}

// ---------------------------------------------------------------------------------------------
// 3. Thaw consolidation (Morgenstern & Nixon 1971, Can. Geotech. J. 8:558). The thaw front moves
//    down as X = alpha_t sqrt(t); the thawed layer 0 <= x <= X (x depth below the drained thawed
//    surface) consolidates with c_v = k M/gamma_w under its buoyant self-weight gamma' and a
//    surcharge P0 applied at t = 0. Newly thawed soil carries zero effective stress, so the water
//    it expels at the front must flow up: sigma'(X) = (c_v / dX/dt) du/dx at x = X.
//    Thaw-consolidation ratio R = alpha_t / (2 sqrt(c_v)). With eta = x/(2 sqrt(c_v t)):
//      u(x, t) = gamma' x / (1 + 1/(2R^2)) + P0 erf(eta) / (erf R + exp(-R^2)/(sqrt(pi) R))
//    (satisfies u_t = c_v u_xx, u(0) = 0 and the front condition; the linear part balances the
//    sqrt(t) terms, the erf part the constant ones).
//    "Degree of consolidation" is the consolidation settlement of the current thawed layer divided
//    by the settlement the same layer would have if fully drained under the same loads, i.e.
//    1 - (integral of u over 0..X)/(integral of the total-stress increment over 0..X), separately
//    for each load. Because the problem is self-similar it does not change in time:
//      U_sw = 1 - (1/(1 + 1/(2R^2)))                          = 1/(1 + 2R^2)
//      U_P0 = 1 - [erf R + (exp(-R^2) - 1)/(sqrt(pi) R)] / [erf R + exp(-R^2)/(sqrt(pi) R)]
//           = 1/(sqrt(pi) R erf R + exp(-R^2))
//    using int_0^R erf(s) ds = R erf R + (exp(-R^2) - 1)/sqrt(pi). Settlement (thaw strain of the
//    phase change itself not included; m_v = 1/M constant, small strain):
//      s(t) = int_0^X (P0 + gamma' x - u)/M dx = (P0 X/M) U_P0 + (gamma' X^2/(2M)) U_sw.
// ---------------------------------------------------------------------------------------------

/// Degree of consolidation of the thawed layer under its own (buoyant) weight, 1/(1 + 2R^2).
inline double thaw_degree_self_weight(double R) {
  poro_detail::require(R >= 0.0, "thaw_degree_self_weight: needs R >= 0");
  return 1.0 / (1.0 + 2.0 * R * R);
}

/// Degree of consolidation of the thawed layer under a surcharge P0, 1/(sqrt(pi) R erf R + e^{-R^2}).
inline double thaw_degree_surcharge(double R) {
  poro_detail::require(R >= 0.0, "thaw_degree_surcharge: needs R >= 0");
  return 1.0 / (std::sqrt(std::numbers::pi) * R * std::erf(R) + std::exp(-R * R));
}

struct ThawConsolidationParams {
  double alpha_t;      ///< thaw-front constant, X = alpha_t sqrt(t) [m/s^0.5]
  double c_v;          ///< coefficient of consolidation k M / gamma_w [m^2/s]
  double gamma_prime;  ///< buoyant unit weight of the thawed soil [N/m^3]
  double P0;           ///< surcharge applied at t = 0 [Pa]
  double M;            ///< constrained modulus 1/m_v [Pa] (only needed for settlements)
};

class ThawConsolidation {
 public:
  explicit ThawConsolidation(const ThawConsolidationParams& p) : p_(p) {
    poro_detail::require(p.alpha_t >= 0.0 && p.c_v > 0.0 && p.M > 0.0,
                         "ThawConsolidation: needs alpha_t >= 0, c_v > 0, M > 0");
    R_ = p.alpha_t / (2.0 * std::sqrt(p.c_v));
    const double sp = std::sqrt(std::numbers::pi);
    A_ = p.gamma_prime * 2.0 * R_ * R_ / (2.0 * R_ * R_ + 1.0);
    B_ = p.P0 * sp * R_ / (sp * R_ * std::erf(R_) + std::exp(-R_ * R_));  // finite at R = 0
  }

  double R() const { return R_; }
  double front(double t) const {
    poro_detail::require_domain(t >= 0.0, "ThawConsolidation: needs t >= 0");
    return p_.alpha_t * std::sqrt(t);
  }
  double degree_self_weight() const { return thaw_degree_self_weight(R_); }
  double degree_surcharge() const { return thaw_degree_surcharge(R_); }

  /// Excess pore pressure u(x, t) [Pa] in the thawed layer 0 <= x <= X(t); throws below the front.
  double excess_pore_pressure(double x, double t) const {
    check_x(x, t);
    if (t == 0.0 || x == 0.0) return 0.0;
    return A_ * x + B_ * std::erf(x / (2.0 * std::sqrt(p_.c_v * t)));
  }

  /// Effective stress sigma' = P0 + gamma' x - u [Pa] (compression positive).
  double effective_stress(double x, double t) const {
    return p_.P0 + p_.gamma_prime * x - excess_pore_pressure(x, t);
  }

  /// Consolidation settlement of the surface [m] at time t.
  double settlement(double t) const {
    const double X = front(t);
    return p_.P0 * X / p_.M * degree_surcharge() + p_.gamma_prime * X * X / (2.0 * p_.M) * degree_self_weight();
  }

  /// Settlement if the thawed layer were fully drained: (P0 X + gamma' X^2/2)/M [m].
  double drained_settlement(double t) const {
    const double X = front(t);
    return (p_.P0 * X + 0.5 * p_.gamma_prime * X * X) / p_.M;
  }

  const ThawConsolidationParams& params() const { return p_; }

 private:
  void check_x(double x, double t) const {
    poro_detail::require_domain(t >= 0.0 && x >= 0.0, "ThawConsolidation: needs x >= 0, t >= 0");
    poro_detail::require_domain(x <= front(t) * (1.0 + 1e-12),
                                "ThawConsolidation: x lies below the thaw front (frozen soil)");
  }
  ThawConsolidationParams p_;
  double R_ = 0, A_ = 0, B_ = 0;
};

// ---------------------------------------------------------------------------------------------
// 3b. Frozen ground that warms while sealed (no flow), laterally confined, top traction-free,
//     elastic skeleton with constrained modulus M, weightless, quasi-static, no thermal
//     expansion. Pore ice melts from liquid saturation S0 to S1; the meltwater takes ζ φ dS_l less
//     volume than the ice it came from (ζ = 1 − ρ_c/ρ_l). With no water able to flow in, the mass
//     balance (the paper's Eq. 6) leaves the skeleton to close that volume and the water to expand:
//       (1 − ζ n_c) d(ln J) − ζ dn_c + n_l c_l dp = 0,   n_c = φ S_c, S_c = 1 − S_l, n_l = φ S_l,
//     with J = V/V0 and φ = 1 − (1 − φ0)/J (the grains keep their volume: dφ = (1 − φ) d(ln J)),
//     so −ζ dn_c = ζ φ dS_l − ζ S_c (1 − φ) d(ln J): the pores' compression melts the ice that a
//     fixed S_c no longer has room for, and the balance is
//       (1 − ζ S_c) d(ln J) + ζ φ dS_l + n_l c_l dp = 0.
//     (The printed Eq. 7 has (1 − ζ n_c) here: it drops ζ S_c Dφ/Dt.) The column's total stress
//     is zero (free top), so σ′_yy = p (σ = σ′ − p I), and σ′_yy = M ln J (rate form). Hence
//     dp = M d(ln J) and
//       d(ln J)/dS_l = −ζ φ / (1 − ζ (1 − S_l) + φ S_l M c_l),
//     integrated here by classical Runge–Kutta in S_l (the right side depends on J through φ).
//     To first order: p ≈ −M ζ φ0 ΔS_l / (1 − ζ (1 − S̄) + φ0 S̄ M c_l), S̄ the mean of S0 and
//     S1: melting under undrained conditions puts the water under suction and the skeleton
//     under the same compression. S_l is a function of T alone (Eq. 25's pressure term left out,
//     as this code and the paper's compute it).
// ---------------------------------------------------------------------------------------------

/// Eq. 25 at p_l = 0: S_l = [1 + s^(1/(1−λ))]^(−λ), s = −(ρ_c L_f/p0) ln((T + 273.15)/273.15).
inline double van_genuchten_cc_saturation(double T, double lambda, double p0, double rho_c = 917.0,
                                          double L_f = 3.34e5) {
  const double s = -(rho_c * L_f / p0) * std::log((T + 273.15) / 273.15);
  return s <= 0.0 ? 1.0 : std::pow(1.0 + std::pow(s, 1.0 / (1.0 - lambda)), -lambda);
}

struct SealedMelting {
  double phi0;  ///< porosity at the start
  double zeta;  ///< 1 − ρ_c/ρ_l
  double M;     ///< constrained modulus of the skeleton [Pa]
  double c_l;   ///< compressibility of the water 1/K_l [1/Pa]

  /// ln(V/V0) after the pore ice has melted from S0 to S1 (steps of RK4 in S_l).
  double log_volume_ratio(double S0, double S1, int steps = 4000) const {
    poro_detail::require(phi0 > 0.0 && phi0 < 1.0 && zeta >= 0.0 && zeta < 1.0 && M > 0.0 && c_l >= 0.0,
                         "SealedMelting: needs 0 < phi0 < 1, 0 <= zeta < 1, M > 0, c_l >= 0");
    poro_detail::require_domain(S0 >= 0.0 && S0 <= 1.0 && S1 >= 0.0 && S1 <= 1.0 && steps > 0,
                                "SealedMelting: needs 0 <= S0, S1 <= 1 and steps > 0");
    auto rate = [&](double S, double lnJ) {
      const double phi = 1.0 - (1.0 - phi0) * std::exp(-lnJ);
      return -zeta * phi / (1.0 - zeta * (1.0 - S) + phi * S * M * c_l);
    };
    const double dS = (S1 - S0) / steps;
    double lnJ = 0.0;
    for (int i = 0; i < steps; ++i) {
      const double S = S0 + i * dS;
      const double k1 = rate(S, lnJ), k2 = rate(S + dS / 2, lnJ + dS * k1 / 2);
      const double k3 = rate(S + dS / 2, lnJ + dS * k2 / 2), k4 = rate(S + dS, lnJ + dS * k3);
      lnJ += dS * (k1 + 2 * k2 + 2 * k3 + k4) / 6;
    }
    return lnJ;
  }

  /// The pore pressure, equal to the skeleton's vertical effective stress σ′_yy [Pa] (negative:
  /// suction and compression).
  double pore_pressure(double S0, double S1) const { return M * log_volume_ratio(S0, S1); }

  /// Settlement of a column of height H [m].
  double settlement(double H, double S0, double S1) const { return H * (1.0 - std::exp(log_volume_ratio(S0, S1))); }
};

// ---------------------------------------------------------------------------------------------
// 4. Confined elastic column under self-weight (1-D, uniaxial strain, modulus M = E_oed).
//    Height H, base x = 0 fixed, top x = H free, density rho, gravity g switched on at t = 0 with
//    the column at rest and unstressed; w(x, t) is the downward displacement (settlement):
//      rho w_tt = M w_xx + rho g,   w(0,t) = 0,  w_x(H,t) = 0,  w = w_t = 0 at t = 0.
//    Static: w_s = (rho g/M)(H x - x^2/2), s = w_s(H) = rho g H^2/(2M), base stress rho g H.
//    Dynamic (d'Alembert): w = w_s(x) - [W(x - ct) + W(x + ct)]/2, W the extension of w_s that is
//    odd about 0, even about H and 4H-periodic, c = sqrt(M/rho). Equivalent modal series:
//      w = (rho g/M) sum_n (2/(H k_n^3)) sin(k_n x)(1 - cos(c k_n t)),  k_n = (2n - 1) pi/(2H)
//      w(H, t)/s = 1 - (32/pi^3) sum_n (-1)^(n+1) cos((2n - 1) pi c t/(2H)) / (2n - 1)^3
//    which sums to the piecewise parabola (tau = ct/H folded into [0, 2]):
//      w(H, t)/s = tau^2 (tau <= 1: free fall, g t^2/2, until the base signal arrives), 2 - (2 - tau)^2
//    The surface swings between 0 and 2s with period 4H/c; the base stress is a triangle wave
//    between 0 and 2 rho g H.
// ---------------------------------------------------------------------------------------------

struct ElasticColumn {
  double H;    ///< height [m]
  double rho;  ///< density [kg/m^3]
  double g;    ///< gravity [m/s^2]
  double M;    ///< axial modulus: E_oed for a confined column (see axial_wave_modulus)

  double static_settlement() const { return rho * g * H * H / (2.0 * M); }
  double static_base_stress() const { return rho * g * H; }
  double wave_speed() const { return std::sqrt(M / rho); }
  double period() const { return 4.0 * H / wave_speed(); }

  /// Static settlement profile w_s(x), 0 <= x <= H (x above the base).
  double static_displacement(double x) const { return rho * g / M * (H * x - 0.5 * x * x); }

  /// Downward displacement w(x, t) after gravity is switched on at t = 0 (undamped).
  double displacement(double x, double t) const {
    check(x, t);
    const double ct = wave_speed() * t;
    return static_displacement(x) - 0.5 * (extension(x - ct) + extension(x + ct));
  }

  /// Downward velocity w_t(x, t).
  double velocity(double x, double t) const {
    check(x, t);
    const double c = wave_speed(), ct = c * t;
    return 0.5 * c * (extension_slope(x - ct) - extension_slope(x + ct));
  }

  /// Compressive axial stress M w_x(x, t) [Pa].
  double stress(double x, double t) const {
    check(x, t);
    const double ct = wave_speed() * t;
    return M * (rho * g / M * (H - x) - 0.5 * (extension_slope(x - ct) + extension_slope(x + ct)));
  }

  /// Surface settlement w(H, t), closed form.
  double surface_displacement(double t) const {
    poro_detail::require_domain(t >= 0.0, "ElasticColumn: needs t >= 0");
    double tau = std::fmod(wave_speed() * t / H, 4.0);
    if (tau > 2.0) tau = 4.0 - tau;
    const double f = tau <= 1.0 ? tau * tau : 2.0 - (2.0 - tau) * (2.0 - tau);
    return static_settlement() * f;
  }

  /// Surface settlement from the first nterms modes (for convergence studies / cross-checks).
  double surface_displacement_series(double t, int nterms) const {
    constexpr double pi = std::numbers::pi;
    double s = 0.0;
    for (int n = nterms; n >= 1; --n) {  // smallest first
      const double m = 2.0 * n - 1.0;
      s += ((n % 2 == 1) ? 1.0 : -1.0) * std::cos(m * pi * wave_speed() * t / (2.0 * H)) / (m * m * m);
    }
    return static_settlement() * (1.0 - 32.0 / (pi * pi * pi) * s);
  }

  /// Compressive base stress M w_x(0, t): triangle wave rho g H * (tau folded into [0, 2]).
  double base_stress(double t) const {
    poro_detail::require_domain(t >= 0.0, "ElasticColumn: needs t >= 0");
    double tau = std::fmod(wave_speed() * t / H, 4.0);
    if (tau > 2.0) tau = 4.0 - tau;
    return static_base_stress() * tau;
  }

 private:
  void check(double x, double t) const {
    poro_detail::require_domain(x >= 0.0 && x <= H && t >= 0.0, "ElasticColumn: needs 0 <= x <= H, t >= 0");
  }
  // Fold y into [0, H] with the sign of the odd/even/periodic extension.
  std::pair<double, double> fold(double y) const {  // {y in [0, H], sign}
    double r = std::fmod(y, 4.0 * H);
    if (r < 0.0) r += 4.0 * H;
    double sign = 1.0;
    if (r > 2.0 * H) {  // odd about 0 with period 4H: W(r) = -W(4H - r)
      r = 4.0 * H - r;
      sign = -1.0;
    }
    if (r > H) r = 2.0 * H - r;  // even about H
    return {r, sign};
  }
  double extension(double y) const {
    const auto [r, sign] = fold(y);
    return sign * static_displacement(r);
  }
  // dW/dy: W' is even about 0, odd about H, 4H-periodic.
  double extension_slope(double y) const {
    double r = std::fmod(y, 4.0 * H);
    if (r < 0.0) r += 4.0 * H;
    if (r > 2.0 * H) r = 4.0 * H - r;  // W'(r) = W'(4H - r)
    return rho * g / M * (H - r);     // on [0, 2H] the slope H - r is already odd about H
  }
};

// ---------------------------------------------------------------------------------------------
// 5. Axially vibrating bar, fixed at x = 0, free at x = L, mode n (1 = fundamental), released from
//    the unstrained position with velocity v0 sin(k x) (small strain, no damping):
//      v = v0 cos(omega t) sin(k x),  u = (v0/omega) sin(omega t) sin(k x),
//      k = (2n - 1) pi/(2L),  omega = k sqrt(M/rho).
//    M is the axial modulus: E for a bar with free lateral faces, E_oed for a laterally confined
//    (roller-sided) plane-strain column, E/(1 - nu^2) for a plane-strain strip with free faces;
//    see axial_wave_modulus. Example: L = 25, M = 100, rho = 1, v0 = 0.1: period 10 s, free-end
//    amplitude v0/omega = 0.159155 m.
// ---------------------------------------------------------------------------------------------

struct VibratingBar {
  double L;      ///< length [m]
  double M;      ///< axial modulus [Pa]
  double rho;    ///< density [kg/m^3]
  double v0;     ///< velocity amplitude at the free end [m/s]
  int mode = 1;  ///< mode number n >= 1

  double wavenumber() const {
    poro_detail::require(mode >= 1 && L > 0.0, "VibratingBar: needs mode >= 1, L > 0");
    return (2.0 * mode - 1.0) * std::numbers::pi / (2.0 * L);
  }
  double omega() const { return wavenumber() * std::sqrt(M / rho); }
  double period() const { return 2.0 * std::numbers::pi / omega(); }
  double amplitude() const { return v0 / omega(); }  ///< displacement amplitude at x = L (|sin kL| = 1)
  double velocity(double x, double t) const { return v0 * std::cos(omega() * t) * std::sin(wavenumber() * x); }
  double displacement(double x, double t) const {
    return amplitude() * std::sin(omega() * t) * std::sin(wavenumber() * x);
  }
  /// Axial stress M u_x (tension positive).
  double stress(double x, double t) const {
    return M * amplitude() * wavenumber() * std::sin(omega() * t) * std::cos(wavenumber() * x);
  }
  /// Total (kinetic + strain) energy per unit cross-section, rho v0^2 L/4 (constant).
  double energy() const { return 0.25 * rho * v0 * v0 * L; }
};

// ---------------------------------------------------------------------------------------------
// 6. Jaumann stress rate under rigid rotation. Velocity gradient (grad v)_ij = d v_i / d x_j,
//    spin W = (grad v - grad v^T)/2. For v = omega e_z x x = omega (-y, x) (counter-clockwise for
//    omega > 0), W = [[0, -omega], [omega, 0]] and R(t) = exp(W t) is the counter-clockwise
//    rotation; sigma = R sigma0 R^T solves d sigma/dt = W sigma - sigma W. So the update is
//    sigma <- sigma + dt (W sigma - sigma W); the opposite order rotates clockwise (checked: it
//    gives sigma_xy = -0.50621 instead of +0.50621 below). If a code stores grad v transposed
//    (d v_j / d x_i), its W has the opposite sign and its update must be sigma + dt (sigma W - W sigma).
//    Forward Euler multiplies the deviatoric part (sigma_xx - sigma_yy)/2 + i sigma_xy by
//    (1 + 2 i omega dt) per step: the trace is kept exactly, the deviator turns by
//    atan(2 omega dt) and grows by sqrt(1 + 4 omega^2 dt^2) each step. sigma0 = diag(1, 0) turned
//    by 45 deg: exact [[1/2, 1/2], [1/2, 1/2]]; Euler gives sigma_xy = 0.506206 / 0.500617 /
//    0.500062 in 100 / 1000 / 10000 steps.
// ---------------------------------------------------------------------------------------------

template <std::size_t N>
using Matrix = std::array<std::array<double, N>, N>;
using Mat2 = Matrix<2>;

/// Spin W = (L - L^T)/2 of a velocity gradient L_ij = d v_i / d x_j.
template <std::size_t N>
Matrix<N> spin_tensor(const Matrix<N>& L) {
  Matrix<N> W{};
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) W[i][j] = 0.5 * (L[i][j] - L[j][i]);
  return W;
}

/// One forward-Euler Jaumann step of the rotational part: sigma + dt (W sigma - sigma W).
template <std::size_t N>
Matrix<N> jaumann_euler_step(const Matrix<N>& sigma, const Matrix<N>& L, double dt) {
  const Matrix<N> W = spin_tensor(L);
  Matrix<N> out = sigma;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) {
      double r = 0.0;
      for (std::size_t k = 0; k < N; ++k) r += W[i][k] * sigma[k][j] - sigma[i][k] * W[k][j];
      out[i][j] += dt * r;
    }
  return out;
}

/// Velocity gradient of the 2-D rigid rotation v = omega (-y, x).
inline Mat2 rigid_rotation_velocity_gradient(double omega) { return {{{0.0, -omega}, {omega, 0.0}}}; }

/// sigma0 rotated counter-clockwise by `angle` [rad]: R sigma0 R^T.
inline Mat2 rigid_rotation_exact(const Mat2& s0, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Mat2 R{{{c, -s}, {s, c}}};
  Mat2 out{};
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j)
      for (std::size_t k = 0; k < 2; ++k)
        for (std::size_t l = 0; l < 2; ++l) out[i][j] += R[i][k] * s0[k][l] * R[j][l];
  return out;
}

/// The forward-Euler sequence a code's Jaumann update should reproduce: nsteps steps of
/// jaumann_euler_step for the rigid rotation through `angle` (omega dt = angle/nsteps).
inline Mat2 jaumann_rigid_rotation_euler(const Mat2& sigma0, double angle, int nsteps) {
  poro_detail::require(nsteps >= 1, "jaumann_rigid_rotation_euler: needs nsteps >= 1");
  const double dt = 1.0 / nsteps;  // unit total time, omega = angle
  const Mat2 L = rigid_rotation_velocity_gradient(angle);
  Mat2 s = sigma0;
  for (int n = 0; n < nsteps; ++n) s = jaumann_euler_step<2>(s, L, dt);
  return s;
}

/// Closed form of the same Euler sequence: deviator times (1 + 2 i angle/nsteps)^nsteps.
inline Mat2 jaumann_rigid_rotation_euler_closed_form(const Mat2& sigma0, double angle, int nsteps) {
  poro_detail::require(nsteps >= 1, "jaumann_rigid_rotation_euler_closed_form: needs nsteps >= 1");
  const double mean = 0.5 * (sigma0[0][0] + sigma0[1][1]);
  const double shear = 0.5 * (sigma0[0][1] + sigma0[1][0]);
  const std::complex<double> d0(0.5 * (sigma0[0][0] - sigma0[1][1]), shear);
  const std::complex<double> d = d0 * std::pow(std::complex<double>(1.0, 2.0 * angle / nsteps), nsteps);
  // an antisymmetric part of sigma0 (not a stress) would also rotate; it is not carried here
  return {{{mean + d.real(), d.imag()}, {d.imag(), mean - d.real()}}};
}

}  // namespace frostmpm::analytic
