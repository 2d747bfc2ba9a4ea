// Scenes that combine conditions and values in ways the bad-input corpus cannot show, since they
// are accepted: velocity conditions that agree where they meet, a side load reaching the fixed
// base's corner (its force still balanced by the reactions), initial vectors given as lists, and
// keys without effect in a scene, which are warned about rather than refused.
#include <catch2/catch.hpp>

#include <cmath>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

std::string scene(const std::string& path) { return source_dir() + "/configs/" + path + ".yaml"; }

/// `frostmpm ARGS`, required to succeed; its output.
std::string succeeds(const std::string& args) {
  const auto r = run_frostmpm(args);
  INFO("frostmpm " << args << "\n" << r.output);
  REQUIRE(r.exit_code == 0);
  return r.output;
}

}  // namespace

TEST_CASE("velocity conditions that prescribe the same value where they meet are accepted",
          "[mechanical][boundary]") {
  const std::string column = "check " + scene("verification/self_weight_column");
  // The side rollers and the fixed base share the bottom corners, all holding 0 there.
  succeeds(column);
  // A zero side velocity agrees with the base at the corner, as a number or a constant table.
  succeeds(column + " --set 'boundary_conditions.2={type: velocity, nodes: {face: x_max}, x: 0}'");
  succeeds(column +
           " --set 'boundary_conditions.2={type: velocity, nodes: {face: x_max}, x: {table: [[0, 0], [1, 0]]}}'");
}

TEST_CASE("a traction on a whole side reaching held corners is accepted, and the reactions balance it",
          "[mechanical][boundary]") {
  // Mandel's top face loaded by a traction with shear, the left rollers holding its corner's x.
  succeeds("check " + scene("verification/mandel") +
           " --set 'boundary_conditions.2={type: traction, nodes: {face: y_max}, normal: -1000, shear: 100}'"
           " --set 'probes.2={name: s, type: settlement}'");

  // The self-weight column pushed sideways over its whole right face (1 m × 1 kPa): the fixed
  // base holds the bottom corner, so it takes that node's share, and with the left rollers it
  // balances the whole load once the damped column is at rest.
  TempDir dir;
  succeeds("run -q " + scene("verification/self_weight_column") + " -o " + dir.file("out") +
           " --set 'boundary_conditions.1={type: roller, nodes: {face: x_min}, name: wall}'"
           " --set 'boundary_conditions.2={type: traction, nodes: {face: x_max}, normal: -1000, name: side}'"
           " --set 'probes=[{name: wall, type: reaction, boundary: wall, component: x},"
           " {name: base, type: reaction, boundary: base, component: x},"
           " {name: side, type: reaction, boundary: side, component: x}]'");
  const auto metrics = read_csv(dir.file("out/metrics.csv"));
  const auto& last = metrics.rows.back();
  const double wall = last[metrics.column("wall")], base = last[metrics.column("base")],
               side = last[metrics.column("side")];
  CHECK(side == Approx(-1000).epsilon(1e-12));
  CHECK(base != 0);  // the corner's share of the load
  CHECK(std::abs(wall + base + side) < 1e-3 * 1000);
}

TEST_CASE("an initial vector may be a list of its components", "[mechanical][cli]") {
  TempDir dir;
  succeeds("run -q " + scene("verification/vibrating_bar") + " -o " + dir.file("out") +
           " --set time.end=0.01 --set 'regions.0.initial={solid_velocity: [0.1, {expression: \"0.002*x\"}]}'"
           " --set 'probes=[{name: vx_min, type: min, field: solid_velocity.x},"
           " {name: vx_max, type: max, field: solid_velocity.x}, {name: vy_max, type: max, field: solid_velocity.y}]'");
  const auto metrics = read_csv(dir.file("out/metrics.csv"));
  const auto& start = metrics.rows.front();  // t = 0, before the first step
  CHECK(start[metrics.column("vx_min")] == 0.1);
  CHECK(start[metrics.column("vx_max")] == 0.1);
  CHECK(start[metrics.column("vy_max")] == Approx(0.002 * 24.75));  // the last particle centre, x = 24.75 m
}

TEST_CASE("gravity and mass scaling in a scene without a momentum balance are warned about", "[cli]") {
  const std::string output = succeeds("check " + scene("tutorials/frozen_inclusion") +
                                      " --set 'gravity=[0, -9.81]' --set time.mass_scaling=100");
  CHECK(output.find("warning: --set gravity=[0, -9.81]: at 'gravity': has no effect") != std::string::npos);
  CHECK(output.find("warning: --set time.mass_scaling=100: at 'time.mass_scaling': has no effect") != std::string::npos);
  // Where a physics solves for momentum they act: no warning.
  CHECK(succeeds("check " + scene("verification/self_weight_column") + " --set time.mass_scaling=100")
            .find("warning") == std::string::npos);
}

TEST_CASE("time.transport_scaling f is the same run as conductivities and permeabilities multiplied by f",
          "[cli][scaling]") {
  TempDir dir;
  // Each scene against itself with the constants divided by f and f given back as the scaling.
  const auto same_metrics = [&](const std::string& name, const std::string& sets, const std::string& scaled_sets) {
    succeeds("run " + scene("verification/" + name) + " -o " + dir.file(name) + " --set output.progress=false" + sets);
    succeeds("run " + scene("verification/" + name) + " -o " + dir.file(name + "_scaled") +
             " --set output.progress=false" + scaled_sets);
    const auto a = read_csv(dir.file(name + "/metrics.csv")), b = read_csv(dir.file(name + "_scaled/metrics.csv"));
    REQUIRE(a.rows.size() == b.rows.size());
    REQUIRE(a.rows.size() > 5);
    for (std::size_t r = 0; r < a.rows.size(); ++r)
      for (std::size_t c = 0; c < a.header.size(); ++c) {
        INFO(name << " row " << r << " column " << a.header[c]);
        CHECK(b.rows[r][c] == Approx(a.rows[r][c]).epsilon(1e-9).margin(1e-9));
      }
  };
  // Conduction: the explicit step follows the (scaled) diffusivity, so the steps agree too.
  same_metrics("conduction_erf", "",
               " --set time.transport_scaling=1000 --set materials.soil.solid_conductivity=3.078e-3"
               " --set materials.soil.water_conductivity=6e-4 --set materials.soil.ice_conductivity=2.14e-3");
  // Seepage: Terzaghi's pressure diffusion with k0 = 1e-6 m/s, or 1e-8 m/s scaled by 100.
  same_metrics("terzaghi_column", "",
               " --set time.transport_scaling=100"
               " --set 'materials.soil.absolute_permeability={model: constant, k0: 1.0e-8}'");
}
