#pragma once
// The material keys of the pore space and the grains that several physics read: one
// spec, so the merged material schema validates them the same way whichever physics comes first.
#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// porosity φ, water density ρ_l and ice density ρ_c.
inline void declare_pore_space_keys(ParamSchema& s) {
  s.real("porosity", "-", "porosity φ (pore space filled by water and ice)").above(0).below(1);
  // Upper bounds: no pore fluid or ice is denser than the densest solids (≈ 2.3e4 kg/m³).
  s.real("water_density", "kg/m^3", "intrinsic density of liquid water ρ_l").defaults_to(1000.0).above(0).at_most(3e4);
  s.real("ice_density", "kg/m^3", "intrinsic density of ice ρ_c").defaults_to(917.0).above(0).at_most(3e4);
}

/// The solid grains' intrinsic density ρ_s (thermal: heat capacity; mechanical: weight, inertia).
inline void declare_solid_density(ParamSchema& s) {
  s.real("solid_density", "kg/m^3", "intrinsic density of the solid grains ρ_s").above(0).at_most(3e4);
}

/// The solid grains' volumetric thermal expansion β_s (hydraulic: the volume source of the mass
/// balance; mechanical: the thermal strain β_s ΔT / 3 of each normal component).
inline void declare_solid_thermal_expansion(ParamSchema& s) {
  s.real("solid_thermal_expansion", "1/K", "volumetric thermal expansion of the soil grains β_s")
      .defaults_to(0.0)
      .at_least(-1e-3)
      .at_most(1e-3);
}

}  // namespace frostmpm
