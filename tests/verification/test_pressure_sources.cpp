// The volume sources of the pressure equation (paper Eq. 48): the phase change ζ φ ∂S_l/∂T Ṫ
// (ζ = 1 − ρ_c/ρ_l: freezing water expands and drives water out) and the thermal expansion
// −β_m Ṫ, each against a closed form, with the explicit thermal scheme and flow together:
// - Neumann freezing (ζ = 0.083, φ = 0.5, S_l 1 → 0): water expelled = ζ φ X(t) per unit
//   width, X the two-phase Neumann front;
// - a heat flux q into a column above 0 °C: water expelled = β_m q t / C_m per unit width (the
//   heat that entered, over the capacity, times the expansion);
// - frozen ground warmed while sealed: the skeleton closes the meltwater's deficit, σ′_yy = p.
// The expelled water is what crossed the drained boundary, measured independently from the
// sources (hydraulic.boundary_inflow_volume against hydraulic.source_volume).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "verification/analytic/poromechanics.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

/// A thermal verification scene with the hydraulic physics added: drained at the far end
/// (y = 0), constant permeability, `extra` material lines.
std::string with_flow(const TempDir& dir, const std::string& scene, const std::string& extra) {
  std::string text = read_file(source_dir() + "/configs/verification/" + scene);
  auto insert_after = [&](const std::string& anchor, const std::string& lines) {
    const auto at = text.find(anchor);
    REQUIRE(at != std::string::npos);
    text.insert(at + anchor.size(), lines);
  };
  insert_after("\nphysics:\n", "  hydraulic: {}\n");
  insert_after("\n  soil:\n", "    absolute_permeability: {model: constant, k0: 1.0e-6}\n" + extra);
  insert_after("\nboundary_conditions:\n", "  - {type: pore_pressure, nodes: {face: y_min}, value: 0}\n");
  const std::string path = dir.file(scene);
  write_file(path, text);
  return path;
}

struct Volumes {
  double inflow = 0, source = 0;
};

Volumes run(const TempDir& dir, const std::string& scene, const std::string& sets) {
  const std::string out = dir.file("out_" + std::to_string(std::hash<std::string>{}(sets)));
  const auto r = run_frostmpm("run " + scene + " -o " + out + sets);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return {run_counter(out, "hydraulic.boundary_inflow_volume"), run_counter(out, "hydraulic.source_volume")};
}

}  // namespace

TEST_CASE("freezing expels ζ φ X(t) of water: the Neumann front times the ice's expansion, at two resolutions",
          "[verification][hydraulic][sources]") {
  TempDir dir;
  const std::string scene = with_flow(dir, "neumann_freezing.yaml", "");
  // X(1 d) = 2 λ √(α_frozen t), λ = 0.15904, α_frozen = 2.619 / 2.08121e6 (the scene's header)
  const double zeta = 1 - 917.0 / 1000.0, phi = 0.5, front = 2 * 0.15904 * std::sqrt(2.619 / 2.08121e6 * 86400);
  for (double h : {0.02, 0.01}) {
    const std::string cell = std::to_string(h);
    const auto v = run(dir, scene,
                       " --set 'grid.cells=[1," + std::to_string(std::lround(2 / h)) + "]' --set grid.cell_size=" + cell +
                           " --set 'regions.0.shape={box: {min: [0, 0], max: [" + cell + ", 2]}}'");
    const double expected = -zeta * phi * front * h;  // an inflow: negative
    const double error = std::abs(v.inflow / expected - 1);
    WARN("h = " << h << " m: water in " << v.inflow << " m³/m, sources " << v.source << ", closed form " << expected
                << " (error " << 100 * error << " %)");
    // What crossed the boundary is what the sources made, up to the water's storage.
    CHECK(v.inflow == Approx(v.source).epsilon(1e-3));
    // The ice content behind the front carries the thermal scheme's front error (≤ 0.4 %).
    CHECK(error < 0.01);  // measured 0.25 % (2 cm), 0.05 % (1 cm)
  }
}

TEST_CASE("heating expels β_m q t / C_m of water: the thermal-expansion term against the heat that entered",
          "[verification][hydraulic][sources]") {
  TempDir dir;
  const std::string scene = with_flow(dir, "heat_flux.yaml",
                                      "    solid_thermal_expansion: 3.0e-5\n    water_thermal_expansion: 2.1e-4\n");
  const double beta = 0.5 * 3.0e-5 + 0.5 * 2.1e-4, capacity = 3.20225e6, q = 50.0, t = 86400;
  for (double h : {0.02, 0.01}) {
    const std::string cell = std::to_string(h);
    const auto v = run(dir, scene,
                       " --set 'grid.cells=[1," + std::to_string(std::lround(2 / h)) + "]' --set grid.cell_size=" + cell +
                           " --set 'regions.0.shape={box: {min: [0, 0], max: [" + cell + ", 2]}}'");
    const double expected = -beta * q * h * t / capacity;
    WARN("h = " << h << " m: water in " << v.inflow << " m³/m, closed form " << expected);
    CHECK(v.inflow == Approx(v.source).epsilon(1e-3));
    // The source lags one step (the temperature changes at the end of a step): Δt/t ≈ 1e-3.
    CHECK(v.inflow == Approx(expected).epsilon(3e-3));
  }
}

TEST_CASE("a sealed column that thaws through cavitates: held at the cavitation pressure, the vapour fills ζ φ ΔS_l",
          "[verification][hydraulic][sources][cavitation]") {
  // Frozen at −5 °C (S_l = S_res = 0.05), sealed on every face, warmed to +5 °C on both ends until
  // it has thawed through (S_l = 1). The meltwater lacks ζ φ (1 − S_res) of the column's volume;
  // without a limit the pore water stretches to fill it (hundreds of MPa of suction), with a
  // cavitation pressure p_c the water stays at p_c and the vapour takes the deficit, less what the
  // frozen ground's water gave by expanding to p_c before any vapour formed (φ S_res c_w |p_c|,
  // 3e-5 of it; meltwater forms at p_c and does not expand). Then cooled back to −5 °C: the ice's
  // expansion fills the vapour again — with held nodes let go as their vapour runs out, none
  // overdrawn — and a full cycle leaves next to none (round-off of the solves, first order in h).
  TempDir dir;
  const double zeta = 1 - 917.0 / 1000.0, phi = 0.37, residual = 0.05, p_c = -1.0e5;
  auto scene = [&](double h, bool refreeze) {
    const long cells = std::lround(0.2 / h);
    const std::string warm = refreeze ? "{expression: \"t < 4.0e5 ? 5.0 : -5.0\"}" : "5.0";
    std::string text = "task: simulation\n"
                       "grid: {cells: [1, " + std::to_string(cells) + "], cell_size: " + std::to_string(h) + "}\n"
                       "time: {end: " + std::string(refreeze ? "8.0e5" : "4.0e5") + ", dt: 600}\n"
                       "physics:\n  thermal: {scheme: implicit}\n  hydraulic: {}\n"
                       "materials:\n  sand:\n    porosity: 0.37\n    solid_density: 2650\n"
                       "    solid_heat_capacity: 835\n    solid_conductivity: 9.0\n"
                       "    sfcc: {model: exponential, width: 0.5, residual_saturation: 0.05}\n"
                       "    absolute_permeability: {model: constant, k0: 1.0e-5}\n"
                       "    relative_permeability: {model: impedance, omega: 50}\n"
                       "regions:\n  - shape: {box: {min: [0, 0], max: [" + std::to_string(h) + ", 0.2]}}\n"
                       "    material: sand\n    initial: {temperature: -5.0}\n"
                       "boundary_conditions:\n  - {type: temperature, nodes: {face: y_min}, value: " + warm + "}\n"
                       "  - {type: temperature, nodes: {face: y_max}, value: " + warm + "}\n"
                       "output: {every: 0}\n"
                       "probes:\n  - {name: p_min, type: min, field: pore_pressure}\n"
                       "  - {name: S_min, type: min, field: liquid_saturation}\n"
                       "  - {name: S_max, type: max, field: liquid_saturation}\n";
    const std::string path = dir.file("sealed_" + std::to_string(cells) + (refreeze ? "_cycle" : "") + ".yaml");
    write_file(path, text);
    return path;
  };
  const std::string limit = " --set physics.hydraulic.cavitation_pressure=" + std::to_string(p_c);
  for (double h : {0.02, 0.01}) {
    const std::string out = dir.file("out_" + std::to_string(std::lround(0.2 / h)));
    const auto unlimited = run_frostmpm("run " + scene(h, false) + " -o " + out + "_free");
    const auto r = run_frostmpm("run " + scene(h, false) + " -o " + out + limit);
    const auto cycle = run_frostmpm("run " + scene(h, true) + " -o " + out + "_cycle" + limit);
    INFO(r.output << unlimited.output << cycle.output);
    REQUIRE(r.exit_code == 0);
    REQUIRE(unlimited.exit_code == 0);
    REQUIRE(cycle.exit_code == 0);
    const auto limited = read_csv(out + "/metrics.csv"), free = read_csv(out + "_free/metrics.csv");
    REQUIRE(limited.rows.back()[limited.column("S_min")] > 0.999);  // thawed through
    const double p_min = limited.rows.back()[limited.column("p_min")];
    const double p_free = free.rows.back()[free.column("p_min")];
    const double deficit = zeta * phi * (1 - residual) * h * 0.2;  // m³ per m
    const double expected = deficit - phi * residual * 4.6e-10 * -p_c * h * 0.2;
    const double vapour = run_counter(out, "hydraulic.cavitated_volume");
    const auto refrozen = read_csv(out + "_cycle/metrics.csv");
    REQUIRE(refrozen.rows.back()[refrozen.column("S_max")] < 0.0501);  // frozen again
    const double left = run_counter(out + "_cycle", "hydraulic.cavitated_volume");
    WARN("h = " << h << " m: p_min " << p_min << " Pa (without the limit " << p_free << " Pa), vapour " << vapour
                << " m³/m against " << expected << " (error " << 100 * std::abs(vapour / expected - 1)
                << " %); after refreezing " << left << " m³/m (" << 100 * left / expected << " %)");
    CHECK(p_free < 100 * p_c);                       // the limit is what holds it
    CHECK(p_min == Approx(p_c).epsilon(1e-6));       // held at p_c, not below
    CHECK(vapour == Approx(expected).epsilon(5e-4));  // measured 9e-5 at both h
    CHECK(run_counter(out, "hydraulic.source_volume") == Approx(deficit).epsilon(1e-3));
    CHECK(left < 0.005 * expected);  // the ice's expansion filled the vapour again (0.16 %, 0.07 %)
    CHECK(run_counter(out + "_cycle", "hydraulic.cavitation_unresolved_volume") < 1e-6 * expected);
    CHECK(refrozen.rows.back()[refrozen.column("p_min")] >= p_c * (1 + 1e-9));
  }
  // The vapour is particle state: a restart in the middle of refreezing continues bit for bit, and
  // the thread count changes nothing.
  const std::string cycle = scene(0.02, true), sets = limit + " --set time.dt=500";
  const std::string straight = dir.file("straight"), resumed = dir.file("resumed"), one = dir.file("one_thread");
  REQUIRE(run_frostmpm("run " + cycle + " -o " + straight + sets + " --threads 2").exit_code == 0);
  REQUIRE(run_frostmpm("run " + cycle + " -o " + one + sets + " --threads 1").exit_code == 0);
  REQUIRE(run_frostmpm("run " + cycle + " -o " + resumed + sets + " --set time.end=4.2e5").exit_code == 0);
  REQUIRE(run_frostmpm("run --restart " + resumed + " --set time.end=8.0e5").exit_code == 0);
  CHECK(read_file(straight + "/metrics.csv") == read_file(resumed + "/metrics.csv"));
  CHECK(read_file(straight + "/metrics.csv") == read_file(one + "/metrics.csv"));
  CHECK(run_counter(straight, "hydraulic.cavitated_volume") == run_counter(resumed, "hydraulic.cavitated_volume"));
}

TEST_CASE("frozen ground warmed while sealed: the meltwater's deficit compresses the skeleton, σ′_yy = p = M ln J",
          "[verification][hydraulic][mechanical][sources]") {
  // configs/verification/undrained_warming.yaml: warmed from −5 °C to −1 °C with no water able to
  // enter; the closed form integrates the mass balance (the paper's Eq. 6) for a sealed,
  // laterally confined column with a free top (analytic::SealedMelting). The same volume balance
  // raises the effective stress of the frozen ground under the paper's strip footing where it
  // warms (docs/verification.md).
  namespace an = frostmpm::analytic;
  TempDir dir;
  const an::SealedMelting closed{0.4, 1 - 917.0 / 1000.0, an::oedometric_modulus(1.0e8, 0.3), 1.0e-9};
  const auto eq25 = [](double T) { return an::van_genuchten_cc_saturation(T, 0.4, 1.0e5); };
  const double S0 = eq25(-5.0), S1 = eq25(-1.0);
  const double p_end = closed.pore_pressure(S0, S1), s_end = closed.settlement(1.0, S0, S1);
  REQUIRE(p_end == Approx(-619895.47).epsilon(1e-7));  // scipy's solve_ivp (analytic/check_poromechanics.py)
  // During the warming, at t = 0.85 s (T = −1.22 °C on the scene's ramp, 81 % of the melting).
  const double T_ramp = -5 + 2 * (1 - std::cos(std::numbers::pi * 0.85));
  const double p_ramp = closed.pore_pressure(S0, eq25(T_ramp));
  std::vector<double> h = {0.05, 0.025}, ramp_error;
  for (double cell : h) {
    const auto t = run_scene(dir, verification_scene("undrained_warming.yaml"),
                             {"grid.cells=[" + std::to_string(std::lround(0.05 / cell)) + "," +
                                  std::to_string(std::lround(1 / cell)) + "]",
                              "grid.cell_size=" + exact_number(cell)},
                             "warm_" + std::to_string(std::lround(1 / cell)));
    const auto& last = t.rows.back();
    const double p = last[t.column("p_mid")], sigma = last[t.column("stress_yy_mid")];
    const double S = last[t.column("S_l_mid")], s = last[t.column("settlement")];
    const double p_min = last[t.column("p_min")], p_max = last[t.column("p_max")];
    double p_at_ramp = NAN;
    for (const auto& row : t.rows)
      if (std::abs(row[t.column("time_s")] - 0.85) < 1e-9) p_at_ramp = row[t.column("p_mid")];
    REQUIRE(std::isfinite(p_at_ramp));  // a metrics row at 0.85 s (metrics_every 0.05)
    ramp_error.push_back(std::abs(p_at_ramp / p_ramp - 1));
    WARN("h = " << cell << " m: p " << p << " Pa (" << p_min << " to " << p_max << "), σ′_yy " << sigma
                << " Pa (closed form " << p_end << "), settlement " << s << " m (" << s_end << "), p at 0.85 s "
                << p_at_ramp << " Pa (" << p_ramp << ")");
    CHECK(S == Approx(S1).epsilon(1e-6));
    CHECK(p == Approx(p_end).epsilon(2e-5));   // measured 2.7e-6 (0.05 m), 1.1e-6 (0.025 m)
    CHECK(sigma == Approx(p).epsilon(1e-6));   // the free top: zero total stress
    CHECK(s == Approx(s_end).epsilon(2e-5));   // measured 2e-6, 1e-7
    // The same everywhere, the free top included: there the projection moves the skeleton
    // most, and without the volume it leaves out carried to the next step (melt_carried_ in
    // the hydraulic physics) the top two cells stood 3.3 % off (settlement −1.8e-3, −9.1e-4).
    CHECK(p_min == Approx(p_end).epsilon(2e-5));
    CHECK(p_max == Approx(p_end).epsilon(2e-5));
    CHECK(ramp_error.back() < 1e-3);           // the source lags a step: 4.9e-4, 2.6e-4
  }
  // The ramp's error is the lagged source, first order in Δt (Δt ∝ h here: the skeleton's wave
  // speed sets the step).
  CHECK(std::log(ramp_error[0] / ramp_error[1]) / std::log(2.0) > 0.6);  // measured 0.9
}
