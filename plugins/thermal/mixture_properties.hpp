#pragma once
// Thermal properties of the solid–liquid–ice mixture (paper Sec. 2.4) and the energy the
// mixture stores, evaluated per material over contiguous particle ranges.
#include <cmath>
#include <memory>
#include <span>

#include "frostmpm/config/param_schema.hpp"
#include "frostmpm/models/sfcc_model.hpp"

namespace frostmpm::thermal {

enum class ConductivityAverage { Arithmetic, Geometric };

/// Phase constants of one material (per unit volume where noted).
struct PhaseConstants {
  double solid_capacity = 0;  ///< ρ_s c_s [J/m³/K]
  double water_capacity = 0;  ///< ρ_l c_l
  double ice_capacity = 0;    ///< ρ_c c_c
  double solid_conductivity = 0, water_conductivity = 0, ice_conductivity = 0;
  double latent_density = 0;  ///< ρ L_f [J/m³] of the pore space (× φ × ΔS_l gives the heat)
  ConductivityAverage average = ConductivityAverage::Arithmetic;

  /// C_m = n_s ρ_s c_s + n_l ρ_l c_l + n_c ρ_c c_c with n_l = φS, n_c = φ(1 − S).
  double capacity(double phi, double S) const {
    return (1 - phi) * solid_capacity + phi * (S * water_capacity + (1 - S) * ice_capacity);
  }
  /// κ_m, arithmetic (the paper's) or geometric mean of the phases.
  double conductivity(double phi, double S) const {
    if (average == ConductivityAverage::Arithmetic)
      return (1 - phi) * solid_conductivity + phi * (S * water_conductivity + (1 - S) * ice_conductivity);
    return std::pow(solid_conductivity, 1 - phi) * std::pow(water_conductivity, phi * S) *
           std::pow(ice_conductivity, phi * (1 - S));
  }
};

/// Material parameters the thermal physics reads (with the paper's Table 1 defaults).
ParamSchema material_schema();
/// Builds the phase constants of a material from its parameters.
PhaseConstants phase_constants(const ParamSet& material, ConductivityAverage average, bool latent_with_water);

}  // namespace frostmpm::thermal
