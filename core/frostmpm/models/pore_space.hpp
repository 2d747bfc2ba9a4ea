#pragma once
// The material keys of the pore space that several physics read (thermal, hydraulic): one
// spec, so the merged material schema validates them the same way whichever physics comes first.
#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// porosity φ, water density ρ_l and ice density ρ_c.
inline void declare_pore_space_keys(ParamSchema& s) {
  s.real("porosity", "-", "porosity φ (pore space filled by water and ice)").above(0).below(1);
  s.real("water_density", "kg/m^3", "intrinsic density of liquid water ρ_l").defaults_to(1000.0).above(0);
  s.real("ice_density", "kg/m^3", "intrinsic density of ice ρ_c").defaults_to(917.0).above(0);
}

}  // namespace frostmpm
