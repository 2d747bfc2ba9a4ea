// Rigid footings (boundary condition `footing`, probes footing_*) against closed forms: a smooth
// footing compressing a laterally confined elastic column (oedometer: q = E_oed ln(H/(H − s)) for
// a settlement s in the updated-Lagrangian limit), Prandtl's rough strip footing on weightless Tresca soil,
// q_u = (2 + π) c, with and without the volumetric-locking remedy, and Prandtl–Reissner's on c–φ soil
// with a surcharge, q_u = c N_c + q0 N_q, each at two resolutions.
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

/// A confined column H = 1 m, 0.1 m wide (rollers on both sides), E = 10 MPa, ν = 0.3
/// (E_oed = 13.4615 MPa), with a smooth footing on its top pushed at `speed` m/s (ramped over
/// 0.05 s) to `end` s; `physics`, `material` and `probes` add lines to those sections.
std::string oedometer_scene(const std::string& end, const std::string& speed, const std::string& physics,
                            const std::string& material, const std::string& probes) {
  return R"yaml(task: simulation
grid: {cells: [2, 21], cell_size: 0.05}
time: {end: )yaml" + end + R"yaml(}
physics:
  mechanical: {local_damping: 0.1}
)yaml" + physics + R"yaml(materials:
  soil:
    porosity: 0.4
    solid_density: 2650
    water_density: 1000
    mechanical_model: {model: linear_elastic, youngs_modulus: 1.0e7, poisson_ratio: 0.3}
)yaml" + material + R"yaml(regions:
  - shape: {box: {min: [0, 0], max: [0.1, 1.0]}}
    material: soil
boundary_conditions:
  - {type: fixed, nodes: {face: y_min}}
  - {type: roller, nodes: {face: x_min}}
  - {type: roller, nodes: {face: x_max}}
  - {type: footing, name: plate, nodes: {box: {min: [0, 1.0], max: [0.1, 1.05]}}, y: {expression: "-)yaml" + speed +
         R"yaml( * min(t / 0.05, 1)"}, contact: smooth}
output: {every: 0, metrics_every: 0.01}
probes:
  - {name: q, type: footing_pressure, boundary: plate}
  - {name: s, type: settlement}
)yaml" + probes;
}

}  // namespace

TEST_CASE("smooth footing on a confined elastic column: the oedometric pressure, force = pressure x width, "
          "displacement = the integral of its speed",
          "[verification][mechanics][footing]") {
  TempDir dir;
  const std::string scene = dir.file("oedometer.yaml");
  write_file(scene, oedometer_scene("0.5", "0.01", "", "",
                                    "  - {name: d, type: footing_displacement, boundary: plate}\n"
                                    "  - {name: F, type: footing_force, boundary: plate}\n"
                                    "  - {name: Ry, type: reaction, boundary: plate, component: y}\n"));
  const CsvTable t = run_scene(dir, scene, {}, "out");
  const double E_oed = 1e7 * 0.7 / (1.3 * 0.4);
  REQUIRE(E_oed == Approx(1.346154e7).epsilon(1e-6));
  const auto time = t.column("time_s"), d = t.column("d"), F = t.column("F"), q = t.column("q"), R = t.column("Ry"),
             s = t.column("s");
  int checked = 0;
  for (const auto& row : t.rows) {
    const double tt = row[time];
    // ∫ v dt of the ramp, then the constant speed; the footing moves as the material under it,
    // with v at each step's start (first order: ½ (dv/dt) Δt t_ramp = 1.5e-6 m short over the ramp).
    const double exact_d = tt <= 0.05 ? 0.01 * tt * tt / 0.1 : 0.01 * (tt - 0.025);
    CHECK(row[d] == Approx(exact_d).margin(2e-6));
    CHECK(row[F] == Approx(0.1 * row[q]).epsilon(1e-12));
    CHECK(row[F] == Approx(-row[R]).epsilon(1e-12));  // the force on the material is downward
    if (tt < 0.2) continue;  // past the ramp's transient
    INFO("t = " << tt << " s, d = " << row[d] << " m, settlement " << row[s] << " m");
    // The footing drives the node row at the column's top; the material's surface follows it
    // within a few micrometres (its nodes stay where the grid has them).
    CHECK(row[s] == Approx(row[d]).epsilon(0.01));
    CHECK(row[q] == Approx(E_oed * std::log(1.0 / (1.0 - row[s]))).epsilon(0.01));
    ++checked;
  }
  CHECK(checked >= 30);

  // A restart carries the footing's travel: stopped at 0.25 s and resumed, the last row is the
  // uninterrupted run's to the bit.
  run_scene(dir, scene, {"time.end=0.25"}, "first_half");
  const auto resumed = run_frostmpm("run --restart " + dir.file("first_half") + " --set time.end=0.5 --set output.progress=false");
  INFO(resumed.output);
  REQUIRE(resumed.exit_code == 0);
  const CsvTable r = read_csv(dir.file("first_half/metrics.csv"));
  REQUIRE(r.rows.back()[time] == t.rows.back()[time]);
  CHECK(r.rows.back() == t.rows.back());
}

TEST_CASE("smooth footing on an undrained confined column: the footing carries the mixture's stress, "
          "q = (E_oed + K_w/n) e and p = (K_w/n) e",
          "[verification][mechanics][footing][hydraulic]") {
  TempDir dir;
  // The oedometer above, saturated and sealed (k = 1e-12 m/s, no drained boundary), pushed 1 mm/s.
  // Grains incompressible: the water takes (K_w/n) ε and the skeleton E_oed ε, so a footing
  // reporting only the skeleton's share (σ′ − (1 − n) p) would read 31 % low. K_w = 2e7 Pa
  // (a soft water, so that both shares are of the same order); the strain is uniform, so the
  // answer is the same at any resolution up to the strain's size (2.5e-4), the top particles'
  // distance from the held row and the ramp's dynamics.
  const std::string scene = dir.file("undrained_oedometer.yaml");
  write_file(scene, oedometer_scene("0.3", "0.001", "  hydraulic: {}\n",
                                    "    water_compressibility: 5.0e-8\n"
                                    "    absolute_permeability: {model: constant, k0: 1.0e-12}\n",
                                    "  - {name: p_mid, type: value_at, field: pore_pressure, point: [0.05, 0.5]}\n"
                                    "  - {name: syy_mid, type: value_at, field: stress.yy, point: [0.05, 0.5]}\n"));
  const double E_oed = 1e7 * 0.7 / (1.3 * 0.4), water = 2e7 / 0.4;
  for (const double h : {0.05, 0.025}) {
    const int nx = int(std::lround(0.1 / h)), ny = int(std::lround(1.05 / h));
    const CsvTable t = run_scene(dir, scene,
                                 {"grid.cells=[" + std::to_string(nx) + ", " + std::to_string(ny) + "]",
                                  "grid.cell_size=" + exact_number(h),
                                  "boundary_conditions.3.nodes.box.max=[0.1, " + exact_number(1.0 + h) + "]"},
                                 "cells" + std::to_string(ny));
    const auto time = t.column("time_s"), q = t.column("q"), s = t.column("s"), p = t.column("p_mid"),
               syy = t.column("syy_mid");
    int checked = 0;
    double worst = 0;
    for (const auto& row : t.rows) {
      if (row[time] < 0.1) continue;  // past the ramp's transient
      const double strain = std::log(1.0 / (1.0 - row[s]));
      INFO("h = " << h << " m, t = " << row[time] << " s, settlement " << row[s] << " m");
      CHECK(row[q] == Approx((E_oed + water) * strain).epsilon(0.005));
      CHECK(row[p] == Approx(water * strain).epsilon(0.01));
      CHECK(row[q] == Approx(row[p] - row[syy]).epsilon(0.01));  // total = p − σ′_yy (tension positive)
      worst = std::max(worst, std::abs(row[q] / ((E_oed + water) * strain) - 1.0));
      ++checked;
    }
    // Measured: 0.29 % (h = 0.05 m), 0.15 % (0.025 m); 0.13 % at 0.0125 m, where the footing's
    // dynamics, not the grid, set it.
    WARN("undrained oedometer, h = " << h << " m: largest error of q " << worst);
    CHECK(checked >= 15);
  }
}

TEST_CASE("Prandtl's strip footing: the plateau pressure within 5 % of (2 + pi) c with the cell-averaged "
          "volumetric strain at two resolutions, converging, and locked without it",
          "[verification][mechanics][footing][mohr_coulomb]") {
  TempDir dir;
  const std::string scene = verification_scene("prandtl_footing.yaml");
  const double c = 1e4, q_u = (2 + M_PI) * c;
  REQUIRE(q_u == Approx(51415.93).epsilon(1e-6));
  // The plateau: the mean pressure while the footing's face travels from h/4 to 5h/8 of the first
  // cell (plastic from d ≈ 0.002 m; at d = h the face reaches the next node row, see the scene).
  auto plateau_error = [&](double h, const std::string& volumetric) {
    const int nx = int(std::lround(2.5 / h)), ny = int(std::lround(1.5 / h)) + 2;
    const double end = 0.05 + 0.65 * h / 0.1;  // the ramp's 0.005 m, then 5h/8 + a margin at 0.1 m/s
    const CsvTable t = run_scene(dir, scene,
                                 {"grid.cells=[" + std::to_string(nx) + ", " + std::to_string(ny) + "]",
                                  "grid.cell_size=" + exact_number(h), "time.end=" + exact_number(end),
                                  "physics.mechanical.volumetric_strain=" + volumetric},
                                 volumetric + std::to_string(nx));
    const auto d = t.column("footing_displacement"), q = t.column("footing_pressure");
    double sum = 0;
    int n = 0;
    for (const auto& row : t.rows)
      if (row[d] >= h / 4 && row[d] <= 5 * h / 8) sum += row[q], ++n;
    REQUIRE(n > 50);
    return sum / n / q_u - 1.0;
  };
  const double coarse = plateau_error(1.0 / 16, "cell_average"), fine = plateau_error(1.0 / 32, "cell_average");
  const double locked_coarse = plateau_error(1.0 / 16, "particle"), locked_fine = plateau_error(1.0 / 32, "particle");
  WARN("Prandtl plateau error, cell_average: " << coarse << " (B/16), " << fine << " (B/32); particle (locked): "
                                                << locked_coarse << ", " << locked_fine);
  // Measured: +2.5 %, +1.4 % with the remedy (F-bar volumes; +2.2 %, +1.3 % before them); +21 %, +10 % without. MPM with a rough footing lands
  // above the rigid-plastic value, approaching it as h shrinks.
  CHECK(std::abs(coarse) < 0.05);
  CHECK(std::abs(fine) < 0.05);
  CHECK(fine > 0);
  CHECK(std::log2(coarse / fine) > 0.5);  // converging, about first order
  CHECK(locked_coarse > 0.15);            // locking: far above, and the remedy removes most of it
  CHECK(locked_fine > 2 * fine);
}

TEST_CASE("Prandtl-Reissner strip footing on weightless c-phi soil with a surcharge: c Nc + q0 Nq within 7 % at "
          "h = B/32, converging from B/16",
          "[verification][mechanics][footing][mohr_coulomb]") {
  TempDir dir;
  const std::string scene = verification_scene("reissner_footing.yaml");
  // Associated flow, φ = 20°: N_q = e^{π tanφ} tan²(45° + φ/2), N_c = (N_q − 1) cot φ.
  const double phi = 20 * M_PI / 180, c = 1e4, q0 = 1e4;
  const double Nq = std::exp(M_PI * std::tan(phi)) * std::pow(std::tan(M_PI / 4 + phi / 2), 2), Nc = (Nq - 1) / std::tan(phi);
  REQUIRE(Nq == Approx(6.3994).epsilon(1e-4));
  REQUIRE(Nc == Approx(14.8347).epsilon(1e-4));
  const double q_u = c * Nc + q0 * Nq;
  // The plateau: the mean pressure over d = 8 to 28 mm. The pressure peaks at d ≈ 6.5 mm at
  // both resolutions, then swings by about ±15 % with a period of about 10 mm of travel (the
  // same at both) as the dilating material flows round the footing's edge; the window spans two
  // whole swings and stays short of d = h at B/32, where the face reaches the next node row.
  auto plateau_error = [&](double h) {
    const int nx = int(std::lround(4.0 / h)), ny = int(std::lround(2.0 / h)) + 2;
    const CsvTable t = run_scene(dir, scene,
                                 {"grid.cells=[" + std::to_string(nx) + ", " + std::to_string(ny) + "]",
                                  "grid.cell_size=" + exact_number(h), "time.end=0.4",
                                  // the surcharge on the top row of particles, the footing's box one cell tall
                                  "boundary_conditions.3.particles.box.min=[0.5, " + exact_number(2 - h / 2) + "]",
                                  "boundary_conditions.4.nodes.box.max=[0.5, " + exact_number(2 + h) + "]"},
                                 "reissner" + std::to_string(nx));
    const auto d = t.column("footing_displacement"), q = t.column("footing_pressure");
    double sum = 0;
    int n = 0;
    for (const auto& row : t.rows)
      if (row[d] >= 0.008 && row[d] <= 0.028) sum += row[q], ++n;
    REQUIRE(n > 500);
    return sum / n / q_u - 1.0;
  };
  const double coarse = plateau_error(1.0 / 16), fine = plateau_error(1.0 / 32);
  WARN("Prandtl-Reissner plateau error: " << coarse << " (B/16), " << fine << " (B/32)");
  // Measured: +8.2 % (B/16), +1.5 % (B/32).
  CHECK(std::abs(coarse) < 0.12);
  CHECK(std::abs(fine) < 0.07);
  CHECK(std::log2(std::abs(coarse) / std::abs(fine)) > 0.5);
}

TEST_CASE("the cell-averaged volumetric strain and stress give the same footing bit for bit on 1 and 2 threads",
          "[verification][mechanics][footing][threads]") {
  // Past the peak (d ≈ 5 mm at t = 0.2 s): most of the soil under the footing yields and dilates.
  TempDir dir;
  std::string metrics[2];
  for (int threads : {1, 2}) {
    const std::string name = "threads" + std::to_string(threads);
    run_scene(dir, verification_scene("reissner_footing.yaml"), {"time.end=0.2", "output.metrics_every=0.01"}, name,
              threads);
    metrics[threads - 1] = read_file(dir.file(name + "/metrics.csv"));
  }
  CHECK(metrics[0].find("footing_pressure") != std::string::npos);
  CHECK(metrics[0] == metrics[1]);
}

TEST_CASE("cell_average: the particles of a cell change their volume by the cell's mean ratio (F-bar)",
          "[verification][mechanics][footing]") {
  // Prandtl's footing past the start of yield (d ≈ 2 mm): no particle has left its cell yet, so
  // with F-bar every particle of a cell has the same V / V0 = det F, the product of the cell's
  // mean volume ratios; each particle's own ratio (volumetric_strain: particle) spreads them.
  auto spread = [](const std::string& volumetric) {
    frostmpm::ConfigNode file = frostmpm::ConfigNode::load_file(verification_scene("prandtl_footing.yaml"));
    YAML::Node tree = file.raw();
    for (const std::string& o : std::vector<std::string>{"time.end=0.03", "output.every=0", "output.progress=false",
                                                         "physics.mechanical.volumetric_strain=" + volumetric})
      frostmpm::apply_override(tree, o);
    frostmpm::ConfigNode root(tree, "prandtl_footing.yaml");
    root.child("task");
    frostmpm::Simulation sim(builtin_registry(), root);
    TempDir dir;
    frostmpm::OutputDir out(dir.path());
    sim.run(out, frostmpm::RunOptions{});
    const auto x = sim.particles().field("position");
    const auto V = sim.particles().field("volume"), V0 = sim.particles().field("volume_initial");
    std::vector<double> low(sim.grid().cell_count(), 1e300), high(sim.grid().cell_count(), -1e300);
    double compressed = 0;
    for (std::size_t p = 0; p < sim.particles().size(); ++p) {
      const std::size_t c = sim.grid().cell_of(x.data() + 2 * p);
      const double J = V[p] / V0[p];
      low[c] = std::min(low[c], J);
      high[c] = std::max(high[c], J);
      compressed = std::max(compressed, std::abs(J - 1));
    }
    double widest = 0;
    for (std::size_t c = 0; c < low.size(); ++c)
      if (high[c] >= low[c]) widest = std::max(widest, high[c] - low[c]);
    REQUIRE(compressed > 1e-5);  // the soil under the footing has changed its volume
    return widest;
  };
  const double averaged = spread("cell_average"), own = spread("particle");
  INFO("widest spread of V/V0 within a cell: cell_average " << averaged << ", particle " << own);
  CHECK(averaged < 1e-12);
  CHECK(own > 1e-6);
}
