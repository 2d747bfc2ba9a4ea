#pragma once
// Soil freezing characteristic curve: liquid saturation S_l(T, p_l) with its analytic
// derivatives. Evaluated in batches so a virtual call costs once per batch, not per particle.
#include <span>

#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// Output arrays of one SFCC batch; every span has the batch's length.
struct SfccResult {
  std::span<double> S_l;       ///< liquid saturation [-], in [S_res, 1]
  std::span<double> dS_l_dT;   ///< ∂S_l/∂T [1/°C]
  std::span<double> dS_l_dp;   ///< ∂S_l/∂p_l [1/Pa]
};

class SfccModel {
 public:
  static constexpr const char* kKind = "sfcc";
  virtual ~SfccModel();

  /// T in °C, p_l (liquid pressure) in Pa; pore_pressure may be empty (taken as 0).
  virtual void evaluate(std::span<const double> T, std::span<const double> p_l,
                        const SfccResult& out) const = 0;

  /// Temperature at and above which the soil is fully thawed at p_l = 0 [°C].
  virtual double freezing_point() const = 0;
};

}  // namespace frostmpm
