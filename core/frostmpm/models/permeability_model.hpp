#pragma once
// Hydraulic conductivity k = k_a(φ) k_r(S_l, φ) (paper Eqs. 26–27, B2), split into two swappable
// model kinds, each evaluated in batches with analytic derivatives.
#include <span>

#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// Relative conductivity k_r in [floor, 1] from liquid saturation (and porosity where a model
/// uses it, e.g. the impedance form 10^(−Ω φ (1 − S_l))).
class RelativePermeabilityModel {
 public:
  static constexpr const char* kKind = "relative_permeability";
  virtual ~RelativePermeabilityModel();
  virtual void evaluate(std::span<const double> S_l, std::span<const double> porosity,
                        std::span<double> k_r, std::span<double> dk_r_dS_l) const = 0;
};

/// Absolute hydraulic conductivity k_a(φ) [m/s] of the (unfrozen) soil.
class AbsolutePermeabilityModel {
 public:
  static constexpr const char* kKind = "absolute_permeability";
  virtual ~AbsolutePermeabilityModel();
  virtual void evaluate(std::span<const double> porosity, std::span<double> k_a,
                        std::span<double> dk_a_dphi) const = 0;
};

}  // namespace frostmpm
