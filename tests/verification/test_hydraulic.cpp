// Pore-water flow (plugins/hydraulic) against closed forms: steady Darcy flow in a column
// (linear pressure, exact flux), a hydrostatic column at rest, and pressure diffusion in a
// column against Terzaghi's series (Terzaghi 1943; fixed skeleton, compressible water).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

/// Runs configs/verification/<scene> on a 1 × cells column of height 1 m with extra overrides.
CsvTable run_column(const TempDir& dir, const std::string& scene, int cells, const std::vector<std::string>& sets,
                    const std::string& name) {
  const double h = 1.0 / cells;
  std::ostringstream cmd;
  cmd.precision(17);
  cmd << "run " << source_dir() << "/configs/verification/" << scene << " -o " << dir.file(name)
      << " --set 'grid.cells=[1," << cells << "]' --set grid.cell_size=" << h
      << " --set 'regions.0.shape={box: {min: [0, 0], max: [" << h << ", 1]}}' --set output.progress=false";
  for (const auto& s : sets) cmd << " --set '" << s << "'";
  const auto r = run_frostmpm(cmd.str());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return read_csv(dir.file(name + "/metrics.csv"));
}

/// u/u0 = Σ (2/M) sin(M z/H) exp(−M² T_v), M = π(2m+1)/2, z from the drained top (H = 1).
double terzaghi(double z, double Tv) {
  double sum = 0;
  for (int m = 0; m < 400; ++m) {
    const double M = M_PI * (2 * m + 1) / 2;
    sum += 2 / M * std::sin(M * z) * std::exp(-M * M * Tv);
  }
  return sum;
}

}  // namespace

TEST_CASE("steady Darcy flow in a column: linear pressure and the exact flux at two resolutions",
          "[verification][hydraulic]") {
  TempDir dir;
  // K = 1e-5 m/s, 1 m head over 1 m: q = 1e-5 m/s upwards; p(0.5) = 4905 Pa; the first particle
  // row (y = h/4) holds 9810 (1 − h/4).
  for (int cells : {10, 40}) {
    INFO(cells << " cells");
    const auto t = run_column(dir, "darcy_column.yaml", cells, {}, "darcy" + std::to_string(cells));
    const auto& last = t.rows.back();
    CHECK(last[t.column("q_min")] == Approx(1e-5).epsilon(1e-7));
    CHECK(last[t.column("q_max")] == Approx(1e-5).epsilon(1e-7));
    CHECK(last[t.column("p_mid")] == Approx(4905.0).epsilon(1e-8));
    CHECK(last[t.column("p_max")] == Approx(9810.0 * (1 - 0.25 / cells)).epsilon(1e-8));
    // run.json keeps the pressure solver's iterations and final residual of every step.
    const std::string json = read_file(dir.file("darcy" + std::to_string(cells) + "/run.json"));
    for (const std::string key : {"hydraulic.linear_iterations", "hydraulic.relative_residual"}) {
      const auto open = json.find("\"" + key + "\": [");
      REQUIRE(open != std::string::npos);
      const auto close = json.find(']', open);
      const std::string list = json.substr(open, close - open);
      CHECK(std::count(list.begin(), list.end(), ',') + 1 == 10);  // 10 steps of 1 s
    }
  }
}

TEST_CASE("a hydrostatic column stays at rest: gravity against a hydrostatic boundary", "[verification][hydraulic]") {
  TempDir dir;
  // Gravity on, the top held hydrostatic with the water table at y = 1 m, the base closed,
  // the column starting at p = 0: it fills to p = ρ g (1 − y) and the flux dies out.
  const auto t = run_column(dir, "darcy_column.yaml", 20,
                            {"boundary_conditions=[{type: pore_pressure, nodes: {face: y_max}, value: 1.0, "
                             "hydrostatic: true}]",
                             "gravity=[0, -9.81]"},
                            "hydrostatic");
  const auto& last = t.rows.back();
  CHECK(last[t.column("p_mid")] == Approx(4905.0).epsilon(1e-8));
  CHECK(last[t.column("p_max")] == Approx(9810.0 * (1 - 0.25 / 20)).epsilon(1e-8));
  CHECK(std::abs(last[t.column("q_min")]) < 1e-12);
  CHECK(std::abs(last[t.column("q_max")]) < 1e-12);
}

namespace {

const double kTerzaghiCv = 1e-6 / (0.4 * 1e-8 * 1000 * 9.81);  // K / (n c_w ρ g) = 0.025484 m²/s
const std::vector<double> kIsochrones = {0.05, 0.2, 0.5};

/// Relative L2 errors over 20 heights of the isochrones T_v = 0.05, 0.2, 0.5 of
/// terzaghi_column.yaml on `cells` cells, c_v Δt / h² = 1.
std::vector<double> terzaghi_errors(const TempDir& dir, int cells, const std::vector<std::string>& sets,
                                    const std::string& name) {
  const double t05 = 0.05 / kTerzaghiCv;  // metrics rows at T_v = 0.05 k
  const double h = 1.0 / cells, dt = 0.098115 * (h / 0.05) * (h / 0.05);
  std::ostringstream every, end, step;
  every.precision(17);
  end.precision(17);
  step.precision(17);
  every << "output.metrics_every=" << t05;
  end << "time.end=" << 10 * t05;
  step << "time.dt=" << dt;
  std::vector<std::string> all = {every.str(), end.str(), step.str()};
  all.insert(all.end(), sets.begin(), sets.end());
  const auto t = run_column(dir, "terzaghi_column.yaml", cells, all, name);
  std::vector<double> errors;
  for (double Tv : kIsochrones) {
    const auto& row = t.rows.at(static_cast<std::size_t>(std::lround(Tv / 0.05)));
    REQUIRE(kTerzaghiCv * row[t.column("time_s")] == Approx(Tv).epsilon(1e-9));
    double e2 = 0, u2 = 0;
    for (int k = 0; k < 20; ++k) {
      const double y = 0.025 + 0.05 * k;
      char column[16];
      std::snprintf(column, sizeof column, "p_y%02d", k);
      const double exact = terzaghi(1 - y, Tv), computed = row[t.column(column)] / 1e4;
      e2 += (computed - exact) * (computed - exact);
      u2 += exact * exact;
    }
    errors.push_back(std::sqrt(e2 / u2));
  }
  return errors;
}

}  // namespace

TEST_CASE("pressure diffusion in a column matches Terzaghi's isochrones, second order in h (dt ∝ h²)",
          "[verification][hydraulic]") {
  TempDir dir;
  std::vector<std::vector<double>> error;  // [resolution][isochrone]
  const std::vector<int> resolutions = {10, 20, 40};
  for (int cells : resolutions) error.push_back(terzaghi_errors(dir, cells, {}, "terzaghi" + std::to_string(cells)));
  for (std::size_t i = 0; i < kIsochrones.size(); ++i) {
    INFO("T_v = " << kIsochrones[i] << ": relative L2 errors " << error[0][i] << ", " << error[1][i] << ", "
                  << error[2][i]);
    CHECK(error[2][i] < 0.005);  // measured 0.09 %, 0.02 %, 0.07 %; the acceptance bound is 2 %
    for (std::size_t r = 0; r + 1 < resolutions.size(); ++r) CHECK(std::log2(error[r][i] / error[r + 1][i]) > 1.5);
    CHECK(std::log2(error[0][i] / error[2][i]) / 2 > 1.8);  // measured 1.8–2.3 pairwise, 2.0–2.5 overall
  }
}

TEST_CASE("Terzaghi drained through particles (a surface inside the grid): the face condition's isochrones and order",
          "[verification][hydraulic][particle-condition]") {
  TempDir dir;
  std::vector<std::vector<double>> error;  // [resolution][isochrone]
  const std::vector<int> resolutions = {10, 20, 40};
  for (int cells : resolutions) {
    // The grid reaches 3 cells above the column, and the drained surface is its top layer of
    // particles: the condition holds the node row those particles make up most of.
    std::ostringstream bc;
    bc.precision(17);
    bc << "boundary_conditions.0={type: pore_pressure, particles: {box: {min: [0, " << 1.0 - 0.5 / cells << "], max: ["
       << 1.0 / cells << ", 1]}}, value: 0}";
    error.push_back(terzaghi_errors(dir, cells, {"grid.cells=[1," + std::to_string(cells + 3) + "]", bc.str()},
                                    "particles" + std::to_string(cells)));
  }
  // Measured: the face condition's numbers to every printed digit (T_v = 0.05: 2.64 %, 0.77 %,
  // 0.093 % at 10, 20, 40 cells): the held nodes are the face's, and the empty nodes above carry
  // no unknown.
  for (std::size_t i = 0; i < kIsochrones.size(); ++i) {
    INFO("T_v = " << kIsochrones[i] << ": relative L2 errors " << error[0][i] << ", " << error[1][i] << ", "
                  << error[2][i]);
    CHECK(error[2][i] < 0.005);
    CHECK(std::log2(error[0][i] / error[2][i]) / 2 > 1.8);
  }
}

TEST_CASE("the pressure projection (τ = 1) costs Terzaghi nothing when τ/(2G) matches the storage, and damps "
          "it when it is far larger",
          "[verification][hydraulic][stabilization]") {
  TempDir dir;
  const auto bare = terzaghi_errors(dir, 20, {}, "bare");
  // n c_w = 4e-9 1/Pa: G = 1.25e8 Pa makes τ/(2G) equal to it; G = 1e6 Pa makes it 125 times it
  const auto matched = terzaghi_errors(dir, 20, {"materials.soil.shear_modulus=1.25e8"}, "matched");
  const auto soft = terzaghi_errors(dir, 20, {"materials.soil.shear_modulus=1.0e6"}, "soft");
  for (std::size_t i = 0; i < kIsochrones.size(); ++i) {
    INFO("T_v = " << kIsochrones[i] << ": relative L2 errors " << bare[i] << " (τ = 0), " << matched[i]
                  << " (G = 1.25e8 Pa), " << soft[i] << " (G = 1e6 Pa)");
    CHECK(std::abs(matched[i] - bare[i]) < 1e-3);  // measured +0.00–0.03 %-points
    CHECK(matched[i] < 0.02);
    CHECK(soft[i] > 4 * bare[i]);  // measured 10.0 / 4.1 / 7.9 % against 0.8 / 0.5 / 0.5 %
  }
}

TEST_CASE("thaw with advection (Kurylyk et al. 2014, benchmarks 2 and 3): fronts of the quasi-steady closed form",
          "[verification][hydraulic][thermo-hydraulic]") {
  TempDir dir;
  // X + (e^{−βX} − 1)/β = κ T_s β t / L_v, β = ρ_l c_l q / κ (1–2 % approximate:
  // it neglects the thawed zone's sensible heat, Stefan number 0.019), solved by bisection.
  auto closed_form = [](double q, double t) {
    const double kappa = 1.839, beta = 1000 * 4182 * q / kappa, rhs = kappa * 1.0 * beta * t / 1.67e8;
    double lo = 0, hi = 1;
    for (int i = 0; i < 200; ++i) {
      const double X = 0.5 * (lo + hi);
      (X + (std::exp(-beta * X) - 1) / beta < rhs ? lo : hi) = X;
    }
    return 0.5 * (lo + hi);
  };
  // The published values the closed form must reproduce first.
  const double q10 = 10.0 / (365.25 * 86400), q100 = 100.0 / (365.25 * 86400);
  CHECK(closed_form(q10, 86400) == Approx(0.0439).margin(5e-5));
  CHECK(closed_form(q10, 4 * 86400) == Approx(0.0882).margin(5e-5));
  CHECK(closed_form(q100, 2 * 86400) == Approx(0.0666).margin(5e-5));
  CHECK(closed_form(q100, 4 * 86400) == Approx(0.0974).margin(5e-5));
  for (double q : {q10, q100}) {
    std::vector<double> errors;
    for (int cells : {100, 200}) {  // Δx = 5 and 2.5 mm
      std::ostringstream flux;
      flux.precision(17);
      flux << "boundary_conditions.1.value=" << q;
      const double h = 0.5 / cells;
      std::ostringstream cmd;
      cmd.precision(17);
      cmd << "run " << source_dir() << "/configs/verification/kurylyk_advection.yaml -o " << dir.file("run")
          << " --set 'grid.cells=[1," << cells << "]' --set grid.cell_size=" << h
          << " --set 'regions.0.shape={box: {min: [0, 0], max: [" << h << ", 0.5]}}' --set '" << flux.str()
          << "' --set output.progress=false --overwrite";  // one folder for every run
      const auto r = run_frostmpm(cmd.str());
      INFO(r.output);
      REQUIRE(r.exit_code == 0);
      const auto t = read_csv(dir.file("run/metrics.csv"));
      REQUIRE(t.rows.size() == 5);  // t = 0 … 4 d
      double worst = 0;
      for (int day : {1, 2, 4}) {
        const double X = t.rows[day][t.column("half_thawed_depth")], exact = closed_form(q, day * 86400.0);
        INFO("q = " << q << " m/s, Δx = " << h << " m, day " << day << ": front " << X << " m, closed form " << exact);
        CHECK(std::abs(X - exact) / exact < 0.025);
        worst = std::max(worst, std::abs(X - exact) / exact);
        // The flux passes the frozen column unchanged (mass balance).
        CHECK(t.rows[day][t.column("q_y_min")] == Approx(-q).epsilon(1e-6));
        CHECK(t.rows[day][t.column("q_y_max")] == Approx(-q).epsilon(1e-6));
      }
      errors.push_back(worst);
    }
    WARN("Kurylyk advection q = " << q << " m/s: worst front error " << errors[0] << " (5 mm), " << errors[1]
                                  << " (2.5 mm) against the quasi-steady closed form");
  }
}
