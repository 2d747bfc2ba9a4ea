#pragma once
// The heat content of one material as a closed-form, exactly invertible state function.
//
// The SFCC S_l(T) is tabulated once, at setup, as a piecewise-linear curve on adaptive knots
// (bisection until the interpolation error is below `tolerance`, the freezing point always a
// knot). On that curve the heat content per unit pore volume
//     G(T) = C_c T + (C_l − C_c) ∫ S_l dT + L_v S_l(T)        [J/m³ of pore space]
// is piecewise quadratic and exact, so a particle's heat content
//     H(T) = (1 − φ) C_s T + φ G(T)                            [J/m³]
// is a true state function: energy is conserved to round-off whatever path a particle takes,
// H⁻¹ is one square root once the interval is known, and the apparent capacity H'(T) is
// exact. Each lookup takes a hint (the interval found last time), so a particle or node whose
// temperature moved little finds its interval in O(1). Outside the table S_l is held at its
// end value (the table spans T_f ± 100 °C, or more when the scene's temperatures need it).
#include <cstdint>
#include <limits>
#include <vector>

#include "frostmpm/models/sfcc_model.hpp"
#include "mixture_properties.hpp"

namespace frostmpm::thermal {

class EnthalpyTable {
 public:
  struct Options {
    double lo = -100, hi = 100;  ///< tabulated range [°C] (the freezing point is added)
    double tolerance = 1e-7;    ///< max |S_l − table| at interval quarter points
    double min_spacing = 1e-9;  ///< knots never closer than this [°C]
  };

  EnthalpyTable(const SfccModel& sfcc, const PhaseConstants& pc, const Options& options);

  /// Interval containing T, searched from `hint` (any valid interval index).
  int locate(double T, int hint) const {
    int i = hint;
    while (i > 0 && T < lower_[i]) --i;
    while (i + 1 < intervals() && T >= lower_[i + 1]) ++i;
    return i;
  }
  int intervals() const { return static_cast<int>(lower_.size()); }
  /// An interval index to start searches from (the freezing point's).
  int freezing_interval() const { return freezing_interval_; }

  double saturation(double T, int i) const { return S_[i] + slope_[i] * (T - base_[i]); }
  double saturation_slope(int i) const { return slope_[i]; }
  /// G(T) [J/m³ of pore space] and its derivative G'(T).
  double pore_heat(double T, int i) const {
    const double x = T - base_[i];
    return G_[i] + x * (g1_[i] + x * g2_[i]);
  }
  double pore_capacity(double T, int i) const { return g1_[i] + 2 * g2_[i] * (T - base_[i]); }

  /// H(T) = a T + b G(T) for a bulk sensible coefficient a = (1 − φ) C_s (or any a ≥ 0) and
  /// pore fraction b = φ (or any b ≥ 0): the form shared by particles and single-material nodes.
  double heat(double a, double b, double T, int& hint) const {
    hint = locate(T, hint);
    return a * T + b * pore_heat(T, hint);
  }
  /// The T with a T + b G(T) = H (a + b > 0), in closed form; `hint` in/out.
  double invert(double a, double b, double H, int& hint) const;

  double freezing_point() const { return freezing_point_; }
  const PhaseConstants& constants() const { return pc_; }
  /// Sensible capacities of the pore filling fully thawed and fully frozen.
  double min_pore_capacity() const { return std::min(pc_.water_capacity, pc_.ice_capacity); }

 private:
  PhaseConstants pc_;
  double freezing_point_ = 0;
  int freezing_interval_ = 0;
  // Interval i covers [lower_[i], lower_[i+1]); interval 0 starts at −∞ and the last one
  // runs to +∞ (S_l held constant there). On interval i, with x = T − base_[i]:
  //   S = S_[i] + slope_[i] x,  G = G_[i] + g1_[i] x + g2_[i] x².
  std::vector<double> lower_, base_, S_, slope_, G_, g1_, g2_;
};

}  // namespace frostmpm::thermal
