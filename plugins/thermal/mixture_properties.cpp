#include "mixture_properties.hpp"

#include <algorithm>
#include <vector>

namespace frostmpm::thermal {

ParamSchema material_schema() {
  ParamSchema s;
  s.real("porosity", "-", "porosity φ (pore space filled by water and ice)").above(0).below(1);
  s.real("solid_density", "kg/m^3", "intrinsic density of the solid grains ρ_s").above(0);
  s.real("solid_heat_capacity", "J/kg/K", "specific heat capacity of the solid c_s").above(0);
  s.real("solid_conductivity", "W/m/K", "thermal conductivity of the solid κ_s").above(0);
  s.real("water_density", "kg/m^3", "intrinsic density of liquid water ρ_l").defaults_to(1000.0).above(0);
  s.real("water_heat_capacity", "J/kg/K", "specific heat capacity of water c_l").defaults_to(4182.0).above(0);
  s.real("water_conductivity", "W/m/K", "thermal conductivity of water κ_l").defaults_to(0.6).above(0);
  s.real("ice_density", "kg/m^3", "intrinsic density of ice ρ_c").defaults_to(917.0).above(0);
  s.real("ice_heat_capacity", "J/kg/K", "specific heat capacity of ice c_c").defaults_to(2060.0).above(0);
  s.real("ice_conductivity", "W/m/K", "thermal conductivity of ice κ_c").defaults_to(2.14).above(0);
  s.real("latent_heat", "J/kg", "latent heat of fusion L_f").defaults_to(3.34e5).at_least(0);
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

int invert_heat(const SfccModel& sfcc, const PhaseConstants& pc, std::span<const double> porosity,
                std::span<const double> energy, std::span<double> T, std::span<double> S) {
  const std::size_t n = T.size();
  std::vector<double> T0(T.begin(), T.end()), S0(n), trial(n), St(n), dS(n), dSdp(n), lo(n), hi(n), x(n);
  std::vector<char> done(n, 0);
  sfcc.evaluate(T0, {}, SfccResult{S0, dS, dSdp});
  // Initial guess from the sensible+apparent capacity at the start; bracket from the
  // sensible heat alone (latent heat only adds capacity, so |ΔT| ≤ |E|/C_min).
  for (std::size_t i = 0; i < n; ++i) {
    const double c_min = std::min(pc.capacity(porosity[i], 0.0), pc.capacity(porosity[i], 1.0));
    const double bound = std::abs(energy[i]) / c_min * 1.000001 + 1e-12;
    lo[i] = energy[i] >= 0 ? 0.0 : -bound;
    hi[i] = energy[i] >= 0 ? bound : 0.0;
    const double apparent = pc.capacity(porosity[i], S0[i]) + pc.latent_density * porosity[i] * dS[i];
    x[i] = std::clamp(energy[i] / apparent, lo[i], hi[i]);
    if (energy[i] == 0.0) done[i] = 1, x[i] = 0.0;
  }
  int iterations = 0;
  for (; iterations < 100; ++iterations) {
    for (std::size_t i = 0; i < n; ++i) trial[i] = T0[i] + x[i];
    sfcc.evaluate(trial, {}, SfccResult{St, dS, dSdp});
    bool all_done = true;
    for (std::size_t i = 0; i < n; ++i) {
      if (done[i]) continue;
      const double phi = porosity[i];
      const double residual = pc.heat(phi, T0[i], S0[i], trial[i], St[i]) - energy[i];
      // Converged when the remaining energy error is worth less than 1e-10 °C of sensible heat.
      const double capacity = std::min(pc.capacity(phi, 0.0), pc.capacity(phi, 1.0));
      if (std::abs(residual) <= 1e-10 * capacity || hi[i] - lo[i] <= 1e-12 * (1 + std::abs(T0[i]))) {
        done[i] = 1;
        continue;
      }
      all_done = false;
      if (residual > 0) hi[i] = x[i];
      else lo[i] = x[i];
      // d heat/dΔT at the trial point (trapezoid term + latent term)
      const double cap1 = pc.capacity(phi, St[i]);
      const double dcap = phi * (pc.water_capacity - pc.ice_capacity) * dS[i];
      const double slope = 0.5 * (pc.capacity(phi, S0[i]) + cap1) + 0.5 * dcap * x[i] +
                           pc.latent_density * phi * dS[i];
      double next = slope > 0 ? x[i] - residual / slope : 0.5 * (lo[i] + hi[i]);
      if (!(next > lo[i] && next < hi[i])) next = 0.5 * (lo[i] + hi[i]);  // Newton left the bracket
      x[i] = next;
    }
    if (all_done) break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    T[i] = T0[i] + x[i];
    S[i] = St[i];
  }
  // S must match the final T exactly (x may have moved after the last evaluation).
  sfcc.evaluate(T, {}, SfccResult{S, dS, dSdp});
  return iterations;
}

}  // namespace frostmpm::thermal
