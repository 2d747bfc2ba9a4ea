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
  std::vector<double> T0(T.begin(), T.end()), S0(n), dS0(n), unused(n), lo(n), hi(n), x(n);
  sfcc.evaluate(T0, {}, SfccResult{S0, dS0, unused});
  // Start from the apparent capacity at T0, bracketed by the sensible heat alone (latent heat
  // only adds capacity, so |ΔT| ≤ |E|/C_min).
  std::vector<std::size_t> active;
  for (std::size_t i = 0; i < n; ++i) {
    const double phi = porosity[i];
    const double c_min = std::min(pc.capacity(phi, 0.0), pc.capacity(phi, 1.0));
    const double bound = std::abs(energy[i]) / c_min * 1.000001 + 1e-12;
    lo[i] = energy[i] >= 0 ? 0.0 : -bound;
    hi[i] = energy[i] >= 0 ? bound : 0.0;
    const double apparent = pc.capacity(phi, S0[i]) + pc.latent_density * phi * dS0[i];
    x[i] = std::clamp(energy[i] / apparent, lo[i], hi[i]);
    S[i] = S0[i];
    // Below 1e-10 °C of sensible heat there is nothing to resolve.
    if (std::abs(energy[i]) > 1e-10 * c_min) active.push_back(i);
    else T[i] = T0[i] + x[i];
  }
  // Newton on the still-unconverged particles only, one SFCC batch call per iteration.
  std::vector<double> trial, St, dS, dSdp;
  int iterations = 0;
  while (!active.empty() && iterations < 100) {
    ++iterations;
    const std::size_t m = active.size();
    trial.resize(m);
    St.resize(m);
    dS.resize(m);
    dSdp.resize(m);
    for (std::size_t a = 0; a < m; ++a) trial[a] = T0[active[a]] + x[active[a]];
    sfcc.evaluate(trial, {}, SfccResult{St, dS, dSdp});
    std::size_t kept = 0;
    for (std::size_t a = 0; a < m; ++a) {
      const std::size_t i = active[a];
      const double phi = porosity[i];
      const double residual = pc.heat(phi, T0[i], S0[i], trial[a], St[a]) - energy[i];
      const double capacity = std::min(pc.capacity(phi, 0.0), pc.capacity(phi, 1.0));
      T[i] = trial[a];
      S[i] = St[a];
      // Converged when the energy error is worth less than 1e-10 °C of sensible heat.
      if (std::abs(residual) <= 1e-10 * capacity || hi[i] - lo[i] <= 1e-12 * (1 + std::abs(T0[i]))) continue;
      if (residual > 0) hi[i] = x[i];
      else lo[i] = x[i];
      const double dcap = phi * (pc.water_capacity - pc.ice_capacity) * dS[a];
      const double slope = 0.5 * (pc.capacity(phi, S0[i]) + pc.capacity(phi, St[a])) + 0.5 * dcap * x[i] +
                           pc.latent_density * phi * dS[a];
      double next = slope > 0 ? x[i] - residual / slope : 0.5 * (lo[i] + hi[i]);
      if (!(next > lo[i] && next < hi[i])) next = 0.5 * (lo[i] + hi[i]);  // Newton left the bracket
      x[i] = next;
      active[kept++] = i;
    }
    active.resize(kept);
  }
  return iterations;
}

}  // namespace frostmpm::thermal
