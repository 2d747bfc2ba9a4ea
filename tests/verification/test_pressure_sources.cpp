// The volume sources of the pressure equation (paper Eq. 48): the phase change ζ φ ∂S_l/∂T Ṫ
// (ζ = 1 − ρ_c/ρ_l: freezing water expands and drives water out) and the thermal expansion
// −β_m Ṫ, each against a closed form, with the explicit thermal scheme and flow together:
// - Neumann freezing (ζ = 0.083, φ = 0.5, S_l 1 → 0): water expelled = ζ φ X(t) per unit
//   width, X the two-phase Neumann front;
// - a heat flux q into a column above 0 °C: water expelled = β_m q t / C_m per unit width (the
//   heat that entered, over the capacity, times the expansion).
// The expelled water is what crossed the drained boundary, measured independently from the
// sources (hydraulic.boundary_inflow_volume against hydraulic.source_volume).
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

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
