#include "mixture_properties.hpp"

#include <algorithm>
#include <vector>

#include "frostmpm/models/pore_space.hpp"

namespace frostmpm::thermal {

ParamSchema material_schema() {
  ParamSchema s;
  declare_pore_space_keys(s);
  declare_solid_density(s);
  // Upper bounds well past any material (heat capacities ≤ 1.5e4 J/kg/K, diamond conducts
  // ≈ 2e3 W/m/K): a value beyond them is a typo or a unit slip, not a soil.
  s.real("solid_heat_capacity", "J/kg/K", "specific heat capacity of the solid c_s").above(0).at_most(1e5);
  s.real("solid_conductivity", "W/m/K", "thermal conductivity of the solid κ_s").above(0).at_most(1e4);
  s.real("water_heat_capacity", "J/kg/K", "specific heat capacity of water c_l").defaults_to(4182.0).above(0).at_most(1e5);
  s.real("water_conductivity", "W/m/K", "thermal conductivity of water κ_l").defaults_to(0.6).above(0).at_most(1e4);
  s.real("ice_heat_capacity", "J/kg/K", "specific heat capacity of ice c_c").defaults_to(2060.0).above(0).at_most(1e5);
  s.real("ice_conductivity", "W/m/K", "thermal conductivity of ice κ_c").defaults_to(2.14).above(0).at_most(1e4);
  s.real("latent_heat", "J/kg", "latent heat of fusion L_f").defaults_to(3.34e5).at_least(0).at_most(1e8);
  return s;
}

PhaseConstants phase_constants(const ParamSet& m, ConductivityAverage average, bool latent_with_water) {
  PhaseConstants pc;
  pc.solid_capacity = m.real("solid_density") * m.real("solid_heat_capacity");
  pc.water_capacity = m.real("water_density") * m.real("water_heat_capacity");
  pc.ice_capacity = m.real("ice_density") * m.real("ice_heat_capacity");
  pc.solid_conductivity = m.real("solid_conductivity");
  pc.water_conductivity = m.real("water_conductivity");
  pc.ice_conductivity = m.real("ice_conductivity");
  pc.latent_density = (latent_with_water ? m.real("water_density") : m.real("ice_density")) * m.real("latent_heat");
  pc.average = average;
  return pc;
}

}  // namespace frostmpm::thermal
