// The skeleton and its coupling with the pore water against closed forms (configs/verification/):
// an elastic column under its own weight (static and suddenly loaded), a vibrating bar, Terzaghi
// consolidation with a moving skeleton, the undrained limit, and Mandel's problem with its
// Mandel–Cryer overshoot. Each at two or three resolutions, asserting the error and the observed
// order; the closed forms are in analytic/poromechanics.hpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "scene_runs.hpp"
#include "test_support.hpp"
#include "verification/analytic/poromechanics.hpp"

using namespace frostmpm::test;
namespace an = frostmpm::analytic;

namespace {

/// A column of `cells` cells of height 1 m and one cell width.
std::vector<std::string> column(int cells, std::vector<std::string> more = {}) {
  const double h = 1.0 / cells;
  std::vector<std::string> sets = {"grid.cells=[1, " + std::to_string(cells) + "]", "grid.cell_size=" + exact_number(h),
                                   "regions.0.shape={box: {min: [0, 0], max: [" + exact_number(h) + ", 1.0]}}"};
  sets.insert(sets.end(), more.begin(), more.end());
  return sets;
}

double order(double coarse, double fine) { return std::log2(std::abs(coarse) / std::abs(fine)); }

/// The largest |value| of a metrics.csv column over the run.
double largest_magnitude(const CsvTable& t, const std::string& probe) {
  const auto c = t.column(probe);
  double largest = 0;
  for (const auto& row : t.rows) largest = std::max(largest, std::abs(row[c]));
  return largest;
}

/// Time of the first crossing of v from positive to negative after t_min, interpolated.
double down_crossing(const CsvTable& t, const std::string& probe, double t_min) {
  const auto c = t.column(probe), time = t.column("time_s");
  for (std::size_t i = 1; i < t.rows.size(); ++i) {
    const double a = t.rows[i - 1][c], b = t.rows[i][c];
    if (t.rows[i][time] > t_min && a > 0 && b <= 0)
      return t.rows[i - 1][time] + (t.rows[i][time] - t.rows[i - 1][time]) * a / (a - b);
  }
  return NAN;
}

// The column of self_weight_column.yaml: E = 1 MPa, ν = 0.3, ρ = 2000, H = 1 m.
const an::ElasticColumn kColumn{1.0, 2000.0, 9.81, an::oedometric_modulus(1e6, 0.3)};
/// The large-strain settlement an updated-Lagrangian code converges to (see the scene).
double large_strain_settlement() {
  const double a = kColumn.rho * kColumn.g * kColumn.H / kColumn.M;
  return kColumn.H * (1.0 - (1.0 - std::exp(-a)) / a);
}

}  // namespace

TEST_CASE("self-weight column: settlement converges to the closed form, the base carries the weight",
          "[verification][mechanics]") {
  TempDir dir;
  REQUIRE(kColumn.static_settlement() == Approx(7.2874e-3).epsilon(1e-4));
  REQUIRE(kColumn.static_base_stress() == Approx(19620.0).epsilon(1e-12));
  const double s_large = large_strain_settlement();
  std::vector<double> settlement_error, stress_error;
  for (int cells : {10, 20, 40}) {
    const auto t = run_scene(dir, verification_scene("self_weight_column.yaml"), column(cells, {"time.end=3"}), "sw" + std::to_string(cells));
    const auto& last = t.rows.back();
    const double s = last[t.column("settlement")];
    settlement_error.push_back((s - s_large) / s_large);
    // The reaction of the base is the weight, exactly (mass is conserved).
    CHECK(last[t.column("base_reaction")] * cells == Approx(kColumn.static_base_stress()).epsilon(1e-6));
    // The stress at the base through the grid (a nodal average of particles above it): first order.
    stress_error.push_back((-last[t.column("base_stress")] - kColumn.static_base_stress()) / kColumn.static_base_stress());
    // Within half a per cent of the small-strain closed form (the large-strain answer is 0.49 % below it).
    CHECK(std::abs(s / kColumn.static_settlement() - 1) < 5e-3);
    std::printf("self weight %2d cells: s = %.6e (large strain %.6e, rel %+.2e; small strain %.6e), σ_base %+.2e\n", cells,
                s, s_large, settlement_error.back(), kColumn.static_settlement(), stress_error.back());
  }
  for (double e : settlement_error) CHECK(std::abs(e) < 1e-3);
  CHECK(order(settlement_error[0], settlement_error[1]) > 0.8);
  CHECK(order(settlement_error[1], settlement_error[2]) > 0.8);
  CHECK(std::abs(stress_error[2]) < 0.015);
  CHECK(order(stress_error[0], stress_error[2]) / 2 > 0.9);
}

TEST_CASE("self-weight column loaded suddenly, undamped: the surface swings to 2s after half a period 2H/c_p",
          "[verification][mechanics]") {
  TempDir dir;
  REQUIRE(kColumn.period() == Approx(0.15418).epsilon(1e-4));
  std::vector<double> time_error;
  for (int cells : {10, 20, 40}) {
    const auto t = run_scene(dir, verification_scene("self_weight_column.yaml"),
                             column(cells, {"time.end=0.12", "physics.mechanical.local_damping=0", "output.metrics_every=0"}),
                             "swd" + std::to_string(cells));
    double peak = 0, at = 0;
    for (const auto& row : t.rows)
      if (row[t.column("settlement")] > peak) peak = row[t.column("settlement")], at = row[t.column("time_s")];
    time_error.push_back(at / (0.5 * kColumn.period()) - 1);
    std::printf("sudden gravity %2d cells: peak %.6e = %.5f × 2s (2 × large strain %.5f) at t = %.5f s (T/2 = %.5f)\n", cells,
                peak, peak / (2 * kColumn.static_settlement()), peak / (2 * large_strain_settlement()), at,
                0.5 * kColumn.period());
    // Twice the static settlement: within 1 % of the small-strain form, 0.5 % of the large-strain one.
    CHECK(peak / (2 * kColumn.static_settlement()) == Approx(1.0).margin(0.01));
    CHECK(peak / (2 * large_strain_settlement()) == Approx(1.0).margin(0.005));
  }
  CHECK(std::abs(time_error[2]) < 0.005);
  CHECK(std::abs(time_error[2]) < std::abs(time_error[0]));
}

TEST_CASE("a free elastic block flying at constant velocity stays a rigid translation: equal steps between "
          "metrics rows",
          "[verification][mechanics]") {
  // Exact: every particle at 0.25 m/s, no stress (the scene's header). Landed on each metrics row
  // in full steps and a short one, the velocity noise grew to 1.9e-3 m/s by 1.6 s; in equal steps
  // it stays at round-off (measured 1.5e-13 m/s).
  TempDir dir;
  const auto t = run_scene(dir, verification_scene("flying_block.yaml"), {}, "block");
  double noise = 0;
  for (const auto& row : t.rows)
    noise = std::max({noise, row[t.column("vx_max")] - 0.25, 0.25 - row[t.column("vx_min")],
                      std::abs(row[t.column("vy_max")]), std::abs(row[t.column("vy_min")])});
  std::printf("flying block: largest velocity deviation over 1.6 s %.3e m/s\n", noise);
  CHECK(t.rows.back()[t.column("time_s")] == Approx(1.6).epsilon(1e-12));
  CHECK(noise < 1e-10);
  // Equal steps: the run's smallest and largest Δt agree (no short step to any row).
  CHECK(std::stod(run_json(dir.file("block"), "['run']['dt']['min']")) ==
        Approx(std::stod(run_json(dir.file("block"), "['run']['dt']['max']"))).epsilon(1e-9));
}

TEST_CASE("vibrating bar: period and free-end amplitude of the first mode", "[verification][mechanics]") {
  TempDir dir;
  const an::VibratingBar bar{25.0, 100.0, 1.0, 0.1};
  REQUIRE(bar.period() == Approx(10.0).epsilon(1e-12));
  REQUIRE(bar.amplitude() == Approx(0.159155).epsilon(1e-5));
  auto sets = [](double h, double v0) {
    const int cells = static_cast<int>(std::lround(30.0 / h));
    return std::vector<std::string>{
        "grid.cells=[" + std::to_string(cells) + ", 1]", "grid.cell_size=" + exact_number(h),
        "regions.0.shape={box: {min: [0, 0], max: [25, " + exact_number(h) + "]}}",
        "regions.0.initial={solid_velocity.x: {expression: \"" + exact_number(v0) + "*sin(pi*x/50)\"}}",
        "probes.0.point=[25, " + exact_number(h / 2) + "]", "output.metrics_every=0.01", "time.end=11"};
  };
  // v0 = 0.1 m/s (1 % strain): period and amplitude within a per cent.
  for (double h : {2.5, 1.25, 0.625}) {
    const auto t = run_scene(dir, verification_scene("vibrating_bar.yaml"), sets(h, 0.1), "bar" + exact_number(h));
    const double amplitude = largest_magnitude(t, "u_end");
    // The probe follows the particle nearest the end, a quarter cell inside the bar.
    const double expected = bar.amplitude() * std::sin(bar.wavenumber() * (25.0 - h / 4));
    const double half = down_crossing(t, "u_end", 1.0);
    std::printf("vibrating bar h = %.4g m: amplitude %.6f (exact %.6f, %+.3f %%), half period %.5f s (%+.3f %%)\n", h,
                amplitude, expected, 100 * (amplitude / expected - 1), half, 100 * (half / 5 - 1));
    CHECK(amplitude / expected == Approx(1.0).margin(0.005));
    CHECK(half / 5.0 == Approx(1.0).margin(0.01));
  }
  // Small amplitude (linear): the displacement history converges at second order.
  std::vector<double> errors;
  for (double h : {2.5, 1.25, 0.625}) {
    const double v0 = 1e-3;
    const auto t = run_scene(dir, verification_scene("vibrating_bar.yaml"), sets(h, v0), "barl" + exact_number(h));
    const double x = 25.0 - h / 4;
    double e2 = 0, u2 = 0;
    for (const auto& row : t.rows) {
      const double exact = v0 / bar.omega() * std::sin(bar.omega() * row[t.column("time_s")]) * std::sin(bar.wavenumber() * x);
      e2 += std::pow(row[t.column("u_end")] - exact, 2);
      u2 += exact * exact;
    }
    errors.push_back(std::sqrt(e2 / u2));
    std::printf("vibrating bar (linear) h = %.4g m: L2 error of u(L, t) %.3e\n", h, errors.back());
  }
  CHECK(errors[2] < 2e-3);
  CHECK(order(errors[0], errors[1]) > 1.8);
  CHECK(order(errors[1], errors[2]) > 1.8);
}

namespace {
const double kTerzaghiOedometric = an::oedometric_modulus(1e6, 0.3);
const double kTerzaghiCv = an::consolidation_coefficient(7.2873e-4, 1000 * 9.81, kTerzaghiOedometric);
}  // namespace

TEST_CASE("Terzaghi consolidation with a moving skeleton: settlement U(T_v) within 2 %, converging",
          "[verification][mechanics][hydraulic]") {
  TempDir dir;
  REQUIRE(kTerzaghiCv == Approx(0.1).epsilon(1e-4));
  const std::vector<double> Tv = {0.05, 0.2, 0.5};
  // q = 10 kPa (the scene): strains up to 0.74 %, within 2 % of the small-strain series.
  // q = 100 Pa: small strain, where the series is the limit: the errors shrink with h.
  for (double q : {1e4, 1e2}) {
    std::vector<std::vector<double>> errors;
    for (int cells : {10, 20, 40}) {
      const auto t = run_scene(dir, verification_scene("terzaghi_consolidation.yaml"),
                               column(cells, {"time.end=5", "boundary_conditions.3.value=" + exact_number(q)}),
                               "tz" + exact_number(q) + "_" + std::to_string(cells));
      const double drained = q / kTerzaghiOedometric;
      errors.emplace_back();
      for (double T : Tv) {
        const auto row = std::find_if(t.rows.begin(), t.rows.end(), [&](const auto& r) {
          return std::abs(kTerzaghiCv * r[t.column("time_s")] - T) < 1e-3 * T;
        });
        REQUIRE(row != t.rows.end());
        const double U = (*row)[t.column("settlement")] / drained;
        errors.back().push_back(U / an::terzaghi_degree(T) - 1);
        const double p = (*row)[t.column("p_base")] / q;
        std::printf("Terzaghi q = %g Pa, %2d cells, T_v = %.2f: U = %.5f (exact %.5f, %+.3f %%), p_base/q = %.5f (exact %.5f)\n", q,
                    cells, T, U, an::terzaghi_degree(T), 100 * errors.back().back(), p, an::terzaghi_pressure(1.0, T));
        CHECK(std::abs(errors.back().back()) < 0.02);
        CHECK(p == Approx(an::terzaghi_pressure(1.0, T)).margin(0.01));
      }
    }
    if (q < 1e3)
      for (std::size_t k = 0; k < Tv.size(); ++k) {
        CHECK(std::abs(errors[2][k]) < 1e-3);
        CHECK(order(errors[0][k], errors[2][k]) / 2 > 1.5);
      }
  }
}

TEST_CASE("mass scaling: Terzaghi's settlement does not change while the kinetic energy stays small against the "
          "work, and the ratio exposes a scaling that is too large",
          "[verification][mechanics][hydraulic][mass_scaling]") {
  TempDir dir;
  const std::vector<double> Tv = {0.05, 0.2, 0.5};
  auto degrees = [&](double scaling, double& kinetic_to_work) {
    const std::string name = "scaled" + exact_number(scaling);
    const auto t = run_scene(dir, verification_scene("terzaghi_consolidation.yaml"),
                             column(20, {"time.end=5", "time.mass_scaling=" + exact_number(scaling)}), name);
    kinetic_to_work = run_counter(dir.file(name), "mechanical.kinetic_to_work_max");
    std::vector<double> U;
    for (double T : Tv) {
      const auto row = std::find_if(t.rows.begin(), t.rows.end(), [&](const auto& r) {
        return std::abs(kTerzaghiCv * r[t.column("time_s")] - T) < 1e-3 * T;
      });
      REQUIRE(row != t.rows.end());
      U.push_back((*row)[t.column("settlement")] / (1e4 / kTerzaghiOedometric));
    }
    return U;
  };
  double ratio_1 = 0, ratio_100 = 0, ratio_10000 = 0;
  const auto unscaled = degrees(1, ratio_1);
  const auto scaled = degrees(100, ratio_100);
  const auto overscaled = degrees(1e4, ratio_10000);
  for (std::size_t k = 0; k < Tv.size(); ++k) {
    std::printf("mass scaling, T_v = %.2f: U = %.5f (×1), %.5f (×100, %+.3f %%), %.5f (×1e4, %+.1f %%); exact %.5f\n", Tv[k],
                unscaled[k], scaled[k], 100 * (scaled[k] / unscaled[k] - 1), overscaled[k],
                100 * (overscaled[k] / unscaled[k] - 1), an::terzaghi_degree(Tv[k]));
    CHECK(scaled[k] == Approx(unscaled[k]).epsilon(0.01));
    CHECK(std::abs(scaled[k] / an::terzaghi_degree(Tv[k]) - 1) < 0.02);
  }
  std::printf("   kinetic energy / work, max from a tenth of the run on: %.2e (×1), %.2e (×100), %.2e (×1e4)\n", ratio_1,
              ratio_100, ratio_10000);
  CHECK(ratio_1 < 1e-3);
  CHECK(ratio_100 < 0.01);
  // Scaled 1e4 the skeleton's period (≈ 15 s) outlasts the consolidation: the answer is off and
  // the ratio says so.
  CHECK(ratio_10000 > 0.1);
  CHECK(std::abs(overscaled[0] / unscaled[0] - 1) > 0.1);
}

TEST_CASE("undrained limit: with a nearly impermeable soil the water carries a sudden load and the column does "
          "not settle", "[verification][mechanics][hydraulic]") {
  TempDir dir;
  // K = 1e-12 m/s: c_v = 1.4e-10 m²/s, nothing drains in 0.5 s.
  const auto t = run_scene(dir, verification_scene("terzaghi_consolidation.yaml"),
                           column(20, {"time.end=0.5", "materials.soil.absolute_permeability.k0=1.0e-12",
                                       "output.metrics_every=0.05"}),
                           "undrained");
  const double drained = 1e4 / kTerzaghiOedometric;
  for (std::size_t i = 2; i < t.rows.size(); ++i) {
    const auto& row = t.rows[i];
    CHECK(row[t.column("p_base")] == Approx(1e4).epsilon(0.005));
    CHECK(row[t.column("p_mid")] == Approx(1e4).epsilon(0.005));
    // Incompressible grains and water: the column settles only where the top drains at once,
    // the half cell under the drained top node (2 % of the drained settlement at 20 cells).
    CHECK(row[t.column("settlement")] < 0.5 * 0.05 * drained);
  }
}

TEST_CASE("undrained frozen ground under a drained surface loaded on one side: the water carries the load "
          "(B ≈ 1) and the pressure stays bounded beside it", "[verification][mechanics][hydraulic]") {
  TempDir dir;
  const double q = 2e4;  // the surcharge on x ≥ 2 m
  const auto t = run_scene(dir, verification_scene("undrained_surface.yaml"), {}, "light_nodes_free");
  // Under the load the mean total stress of plane strain under a wide strip, (1 + ν)(2/3) q, is
  // carried by water 10⁴ times stiffer than the skeleton: 0.87 q, swinging with the undamped waves.
  const double under_load = t.rows.back()[t.column("p_under_load")];
  CHECK(under_load > 0.7 * q);
  CHECK(under_load < 1.0 * q);
  // Beside it nothing carries more than the load.
  CHECK(largest_magnitude(t, "p_free_row") < q);
  // The fault this guards against: with nodes grazed by the heaving surface moving with their
  // lumped mass, the pore pressure on the free node row under the drained one grows without bound.
  const auto grazed = run_scene(dir, verification_scene("undrained_surface.yaml"),
                                {"physics.mechanical.minimum_node_mass=0"}, "light_nodes_pushed");
  CHECK(largest_magnitude(grazed, "p_free_row") > 5 * q);
}

TEST_CASE("Mandel's problem: the pore pressure at the centre overshoots (Mandel–Cryer) and decays as the series",
          "[verification][mechanics][hydraulic]") {
  TempDir dir;
  const an::MandelSolution exact(0.3);
  const auto peak = exact.centre_pressure_peak();
  REQUIRE(peak.value == Approx(1.07638).epsilon(1e-5));
  REQUIRE(peak.T == Approx(0.0640).margin(5e-4));
  const double c = an::consolidation_coefficient(1.45746e-4, 1000 * 9.81, an::oedometric_modulus(1e6, 0.3));
  REQUIRE(c == Approx(0.02).epsilon(1e-4));
  std::vector<double> peak_error;
  for (double h : {0.1, 0.05}) {
    const int cx = static_cast<int>(std::lround(1.2 / h)), cy = static_cast<int>(std::lround(0.5 / h));
    const auto t = run_scene(dir, verification_scene("mandel.yaml"),
                             {"grid.cells=[" + std::to_string(cx) + ", " + std::to_string(cy) + "]",
                              "grid.cell_size=" + exact_number(h), "time.end=10", "output.metrics_every=0.1"},
                             "mandel" + exact_number(h));
    double best = 0, best_T = 0;
    for (const auto& row : t.rows) {
      const double T = c * row[t.column("time_s")], p = row[t.column("p_centre")] / 1e4;
      // The first instants are the elastic response to the sudden load (damped): the overshoot is later.
      if (T > 0.03 && p > best) best = p, best_T = T;
    }
    peak_error.push_back(best / peak.value - 1);
    std::printf("Mandel h = %.3g m: peak p(0)/p0 = %.5f at T = %.4f (exact %.5f at %.4f, %+.2f %%)\n", h, best, best_T,
                peak.value, peak.T, 100 * peak_error.back());
    for (double T : {0.1, 0.2}) {
      const auto row = std::find_if(t.rows.begin(), t.rows.end(),
                                    [&](const auto& r) { return std::abs(c * r[t.column("time_s")] - T) < 1e-3 * T; });
      REQUIRE(row != t.rows.end());
      const double p = (*row)[t.column("p_centre")] / 1e4;
      std::printf("   T = %.2f: p(0)/p0 = %.5f (exact %.5f)\n", T, p, exact.centre_pressure(T));
      // Coarse grids lag at the drained edge later on: 2.3 % at T = 0.2 on 0.1 m, 1.2 % on 0.05 m.
      CHECK(p == Approx(exact.centre_pressure(T)).epsilon(T < 0.15 ? 0.01 : h > 0.07 ? 0.03 : 0.015));
    }
    CHECK(best > 1.05);  // the Mandel–Cryer overshoot is there
    CHECK(best_T == Approx(peak.T).margin(0.015));
  }
  CHECK(std::abs(peak_error[1]) < 0.01);
  CHECK(std::abs(peak_error[1]) < std::abs(peak_error[0]));
}

TEST_CASE("Neumann thaw in a column translated rigidly across the grid: the same front relative to the material, "
          "energy balance at round-off", "[verification][mechanics][thermal]") {
  TempDir dir;
  // neumann_thaw.yaml at h = 0.01 m on a 0.06 m wide column; moved sideways by 0.05 m over the
  // day (5 cells) by a velocity condition on every node (the skeleton's modulus is negligible:
  // a rigid motion). The probe line x = 0.055 m stays inside the material all day. (On 0.02 m the
  // moved front is 1.6 % deeper: a particle forgets its sub-cell heat as it crosses cells.)
  const double h = 0.01;
  auto sets = [&](bool moving) {
    std::vector<std::string> s = {
        "grid.cells=[12, 150]", "grid.cell_size=" + exact_number(h),
        "regions.0.shape={box: {min: [0, 0], max: [0.06, 1.5]}}",
        "probes.0.from=[0.055, 1.5]", "probes.0.to=[0.055, 0.0]",
        "probes.4.from=[0.055, 1.5]", "probes.4.to=[0.055, 0.0]"};
    if (moving) {
      s.push_back("physics.mechanical={}");
      s.push_back("materials.soil.mechanical_model={model: linear_elastic, youngs_modulus: 1.0e-6, poisson_ratio: 0}");
      s.push_back("boundary_conditions=[{type: temperature, nodes: {face: y_max}, value: 5.0}, {type: velocity, nodes: "
                  "{box: {min: [0, 0], max: [0.12, 1.5]}}, x: " + exact_number(0.05 / 86400) + ", y: 0}]");
    }
    return s;
  };
  const auto rest = run_scene(dir, verification_scene("neumann_thaw.yaml"), sets(false), "rest");
  const auto moved = run_scene(dir, verification_scene("neumann_thaw.yaml"), sets(true), "moved");
  const double front_rest = rest.rows.back()[rest.column("half_thawed_depth")];
  const double front_moved = moved.rows.back()[moved.column("half_thawed_depth")];
  std::printf("Neumann thaw, h = %.2g m: S_l = ½ front %.5f m at rest, %.5f m moved 0.05 m (%+.3f %%)\n", h, front_rest,
              front_moved, 100 * (front_moved / front_rest - 1));
  CHECK(front_moved / front_rest == Approx(1.0).margin(0.005));
  const double balance = run_counter(dir.file("moved"), "thermal.energy_balance_error_relative");
  std::printf("   energy balance error (relative) %.3e\n", balance);
  CHECK(balance < 1e-10);
}

TEST_CASE("Morgenstern–Nixon thaw consolidation: settlement and excess pore pressure of the thawed layer at two "
          "thaw ratios R, converging with the cell size",
          "[verification][mechanics][hydraulic][thermal][thaw_consolidation]") {
  TempDir dir;
  // The scene's thaw front: two-phase Neumann, X = α√t (its header), M = E = 1 MPa (ν = 0).
  const double alpha = 3.2581e-4, M = 1e6, P0 = 1e4, t_end = 86400;
  struct Case {
    double R, k0;
  };
  for (const Case c : {Case{0.5, 1.0414e-9}, Case{1.5, 1.1571e-10}}) {
    const double c_v = an::consolidation_coefficient(c.k0, 1000 * 9.81, M);
    const an::ThawConsolidation mn({alpha, c_v, 0.0, P0, M});
    REQUIRE(mn.R() == Approx(c.R).epsilon(1e-3));
    std::vector<double> errors;
    for (int cells : {30, 60}) {
      const double h = 0.3 / cells;
      const std::string name = "mn" + exact_number(c.R) + "_" + std::to_string(cells);
      const auto t = run_scene(dir, verification_scene("thaw_consolidation_mn.yaml"),
                               {"time.end=" + exact_number(t_end), "grid.cells=[1, " + std::to_string(cells) + "]",
                                "grid.cell_size=" + exact_number(h), "regions.0.shape.box.max=[" + exact_number(h) + ", 0.3]",
                                "materials.soil.absolute_permeability.k0=" + exact_number(c.k0)},
                               name);
      const auto& last = t.rows.back();
      REQUIRE(last[t.column("time_s")] == Approx(t_end));
      const double s = last[t.column("settlement")], X = last[t.column("thaw_depth")];
      errors.push_back(s / mn.settlement(t_end) - 1);
      std::printf("Morgenstern–Nixon R = %.1f, h = %.0f mm: X = %.4f m (Neumann %.4f), settlement %.4f mm (closed form "
                  "%.4f, %+.2f %%)\n",
                  c.R, 1e3 * h, X, mn.front(t_end), 1e3 * s, 1e3 * mn.settlement(t_end), 100 * errors.back());
      CHECK(X == Approx(mn.front(t_end)).epsilon(0.02));
      CHECK(std::abs(errors.back()) < 0.05);
      // Excess pore pressure in the thawed layer, at depths below the settled surface (away from
      // the front, where the jump to the frozen soil's P0 is spread over a cell).
      for (const auto& [probe, depth] : {std::pair{"p_depth_3cm", 0.03}, std::pair{"p_depth_6cm", 0.06}}) {
        const double p = last[t.column(probe)], exact = mn.excess_pore_pressure(depth - s, t_end);
        std::printf("   %s: %.1f Pa (closed form %.1f, %+.2f %% of P0)\n", probe, p, exact, 100 * (p - exact) / P0);
        CHECK(std::abs(p - exact) < 0.02 * P0);
      }
      CHECK(run_counter(dir.file(name), "mechanical.kinetic_to_work_max") < 1e-3);
    }
    // Where the consolidation behind the front is fast (R = 0.5) the smeared front costs the most:
    // it shrinks with the cell.
    if (c.R < 1) CHECK(std::abs(errors[1]) < 0.8 * std::abs(errors[0]));
  }
}

TEST_CASE("rock freezing around a borehole: thermal contraction before the front, freezing-induced pore "
          "pressure behind it, less contraction without the grains' expansion, and less the thermal strain a "
          "contraction that turns to heave",
          "[mechanics][hydraulic][thermal][rock_freezing]") {
  // configs/paper/rock_freezing.yaml on 1 cm cells for 2 h, and on its own 5 mm cells for 2.5 h: no
  // closed form; the paper's qualitative findings (Sec. 5.2.2) as assertions.
  TempDir dir;
  auto run = [&](const std::string& name, const std::vector<std::string>& more) {
    std::vector<std::string> sets = {"time.end=7200", "grid.cells=[23, 15]", "grid.cell_size=0.01",
                                     "boundary_conditions.0.particles.disk.radius=0.028", "output.metrics_every=300"};
    sets.insert(sets.end(), more.begin(), more.end());
    return run_scene(dir, verification_scene("../paper/rock_freezing.yaml"), sets, name);
  };
  struct Summary {
    double contraction = 0, frozen_pressure = 0;  // min ε_rr at A while T_A > 0; max p_A once T_A < 0
  };
  auto summarize = [](const CsvTable& t) {
    Summary s;
    for (const auto& row : t.rows) {
      if (row[t.column("T_A")] > 0) s.contraction = std::min(s.contraction, row[t.column("radial_strain_A")]);
      else s.frozen_pressure = std::max(s.frozen_pressure, row[t.column("p_A")]);
    }
    return s;
  };
  const auto reference = summarize(run("reference", {}));
  const auto no_expansion = summarize(run("beta0", {"materials.rock.solid_thermal_expansion=0"}));
  std::printf("rock freezing, 1 cm: min ε_rr at A before it freezes %.3e (β_s = 0: %.3e); p_A once frozen up to "
              "%.0f Pa\n",
              reference.contraction, no_expansion.contraction, reference.frozen_pressure);
  CHECK(reference.contraction < -5e-5);                                   // contracts as it cools
  CHECK(std::abs(no_expansion.contraction) < 0.8 * std::abs(reference.contraction));
  CHECK(reference.frozen_pressure > 5e4);                                 // the 9 % expansion, trapped
  // Rows every 600 s and a tighter solve take other steps. With the pressure projection on the
  // cell at the borehole wall that holds one particle, this sequence met a local mode that grew
  // to −760 MPa of pore pressure and stopped the run near t = 1260 s (so did the reference's
  // with the present multigrid); run_scene requires both to finish.
  const auto other_steps =
      summarize(run("rows600", {"output.metrics_every=600", "physics.hydraulic.linear_tolerance=1e-12"}));
  CHECK(other_steps.frozen_pressure > 5e4);
  // Without the grains' expansion on the scene's own 5 mm cells the wall's particles move by
  // ~1e-10 m and a node inside the borehole came to be grazed (2e-19 kg of pore water): its
  // pressure solved to −3e10 Pa, the grid pressure's advection carried that into its neighbour and
  // the run stopped near t = 420 s with ±300 MPa at the wall. Measured with the fix: kinetic/work
  // 0.24 from t = 180 s (a run that survived such a burst: 28 to 1000).
  {
    const CsvTable t = run_scene(dir, verification_scene("../paper/rock_freezing.yaml"),
                                 {"materials.rock.solid_thermal_expansion=0", "time.end=1800", "output.every=0"},
                                 "beta0_fine");
    CHECK(run_counter(dir.file("beta0_fine"), "mechanical.kinetic_to_work_max") < 1.0);
    for (const auto& row : t.rows) CHECK(std::abs(row[t.column("p_A")]) < 1e6);
  }

  // The paper's Fig. 17C: the strain the stress answers to — ε_rr less the grains' free thermal
  // strain, what the paper's code writes as its strain — at A contracts while A cools above 0 °C
  // and turns to a heave once it has frozen. On the scene's 5 mm cells for 2.5 h: on 1 cm cells A
  // is one cell from the wall and this strain is positive from the first 10 min but for one row.
  // Measured (5 mm, to 15 h): −58e-6 at 0.17 h, through zero at 1.34 h, +43e-6 at 2 h, +260e-6 at
  // 10 h; to 2.5 h alone, −59e-6 and +96e-6 at the end.
  const CsvTable fine = run_scene(dir, verification_scene("../paper/rock_freezing.yaml"),
                                  {"time.end=9000", "output.metrics_every=300", "output.every=0"}, "fine");
  double contraction = 0, last = 0;
  for (const auto& row : fine.rows) {
    const double strain = row[fine.column("radial_strain_A")] - row[fine.column("thermal_strain_A")];
    if (row[fine.column("T_A")] > 0) contraction = std::min(contraction, strain);
    last = strain;
  }
  std::printf("rock freezing, 5 mm: ε_rr − thermal strain at A: min %.3e while T_A > 0, %.3e at 2.5 h\n", contraction,
              last);
  CHECK(contraction < -2e-5);
  CHECK(last > 3e-5);
}
