// The paper's thermo-hydraulic examples (Sec. 5.1; INTERFROST TH2 and TH3, Grenier et al.
// 2018) at a coarse 0.04 m grid, the size CI affords: the frozen inclusion's thaw time against
// the range of the 13 INTERFROST codes, its liquid volume from 1.0710 to 1.1100 m³, the energy
// balance with heat advected by the flow, and the talik closing at 3 % and opening at 9 %.
// bench/frozen_inclusion runs the paper's 0.01 m resolution (docs/verification.md).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

CsvTable run_paper(const TempDir& dir, const std::string& scene, const std::string& grid, double h,
                   const std::string& extra = "") {
  std::ostringstream cmd;
  cmd << "run " << source_dir() << "/configs/paper/" << scene << ".yaml -o " << dir.file(scene) << " --set 'grid.cells=["
      << grid << "]' --set grid.cell_size=" << h << " --set output.every=0 --set output.progress=false " << extra;
  const auto r = run_frostmpm(cmd.str());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return read_csv(dir.file(scene + "/metrics.csv"));
}

/// First time T_min rises through 0 °C, interpolated between metrics rows [h].
double thaw_hours(const CsvTable& t) {
  const auto T = t.column("T_min"), time = t.column("time_s");
  for (std::size_t i = 1; i < t.rows.size(); ++i) {
    const double a = t.rows[i - 1][T], b = t.rows[i][T];
    if (a <= 0 && b > 0) {
      const double ta = t.rows[i - 1][time], tb = t.rows[i][time];
      return (ta + (tb - ta) * (0 - a) / (b - a)) / 3600;
    }
  }
  return NAN;
}

double counter(const std::string& run_json, const std::string& name) {
  const auto at = run_json.find("\"" + name + "\":");
  REQUIRE(at != std::string::npos);
  return std::stod(run_json.substr(at + name.size() + 3));
}

}  // namespace

TEST_CASE("frozen inclusion in a 3 % and a 9 % gradient: thaw times of the INTERFROST codes, V_l, energy",
          "[verification][thermo-hydraulic]") {
  TempDir dir;
  struct Case {
    std::string scene;
    double lo, hi;  // INTERFROST 13-code range [h]
  };
  for (const Case& c : {Case{"frozen_inclusion_case2", 18.1, 20.7}, Case{"frozen_inclusion_case3", 10.8, 12.8}}) {
    INFO(c.scene);
    // 2 × 2 particles per cell (the scenes use 3 × 3, which at 0.04 m would sample the square
    // 0.34 m wide): the square sampled 0.32 m wide.
    const auto t = run_paper(dir, c.scene, "75,25", 0.04, "--set grid.particles_per_cell=2");
    const double thaw = thaw_hours(t);
    INFO("thaw at " << thaw << " h");
    // At 0.04 m case 2 thaws at 19.2 h (inside the range) and case 3 at 13.0 h, 2 % past its
    // upper end; at the paper's 0.01 m both are inside (19.0 and 12.0 h, bench/frozen_inclusion).
    CHECK(thaw >= c.lo);
    CHECK(thaw <= c.hi * 1.05);
    // Flow thaws faster than conduction alone (case 1: 32–37 h at these grids).
    CHECK(thaw < 25);
    // The inclusion's ice (16 × 16 particles of 0.02 m at 0.04 m: 0.1024 m², V_l 1.0740) all melts.
    CHECK(t.rows.front()[t.column("liquid_volume_m3")] == Approx(1.11 - 0.37 * 0.95 * 0.1024).epsilon(1e-9));
    CHECK(t.rows.back()[t.column("liquid_volume_m3")] == Approx(1.11).epsilon(1e-9));
    // Far from the inclusion the Darcy flux is K ∇h (7.11e-4 m/s × gradient) once it has thawed.
    const double gradient = c.scene.back() == '2' ? 0.03 : 0.09;
    CHECK(t.rows.back()[t.column("q_x_max")] == Approx(1.3e-10 * 1000 * 9.81 / 1.793e-3 * gradient).epsilon(1e-3));
    const std::string json = read_file(dir.file(c.scene + "/run.json"));
    CHECK(counter(json, "thermal.energy_balance_error_relative") < 1e-9);
    CHECK(counter(json, "thermal.energy_advected_in_J") > 0);
    CHECK(counter(json, "hydraulic.relative_residual_max") <= 1e-8);
  }
}

TEST_CASE("frozen inclusion in a 9 % gradient as shipped (0.02 m, 3 x 3 particles per cell): the exact square, "
          "thaw inside the INTERFROST range",
          "[verification][thermo-hydraulic]") {
  TempDir dir;
  const auto t = run_paper(dir, "frozen_inclusion_case3", "150,50", 0.02);
  // The lattice of h/3 holds the 1/3 m square exactly: V_l = 0.37 (3 − 0.95/9) m³ per metre
  // (INTERFROST: 1.0710).
  CHECK(t.rows.front()[t.column("liquid_volume_m3")] == Approx(0.37 * (3 - 0.95 / 9)).epsilon(1e-9));
  CHECK(t.rows.back()[t.column("liquid_volume_m3")] == Approx(1.11).epsilon(1e-9));
  // Measured 12.80 h (12.20 h at 0.01 m, first order: about 11.6 h in the limit); with 2 × 2
  // particles (the square sampled 0.34 m wide) 13.22 h, past the range.
  const double thaw = thaw_hours(t);
  INFO("thaw at " << thaw << " h");
  CHECK(thaw >= 10.8);
  CHECK(thaw <= 12.8 * 1.01);
}

TEST_CASE("talik: closes in a 3 % gradient, opens in a 9 % gradient (T at the centre, k_eq at the outlet)",
          "[verification][thermo-hydraulic]") {
  TempDir dir;
  const auto closing = run_paper(dir, "talik_case2", "25,25", 0.04);
  const auto opening = run_paper(dir, "talik_case3", "25,25", 0.04);
  auto column = [](const CsvTable& t, const std::string& name) {
    std::vector<double> v;
    for (const auto& row : t.rows) v.push_back(row[t.column(name)]);
    return v;
  };
  const auto T2 = column(closing, "T_center"), k2 = column(closing, "k_eq_m_per_s");
  const auto T3 = column(opening, "T_center"), k3 = column(opening, "k_eq_m_per_s");
  // 3 %: the centre freezes and the flow path closes (k_eq → 0).
  CHECK(T2.back() < 0);
  CHECK(k2.back() < 1e-3 * *std::max_element(k2.begin(), k2.end()));
  // 9 %: the centre stays above 0 °C and warms again; k_eq keeps rising.
  CHECK(*std::min_element(T3.begin(), T3.end()) > 0);
  CHECK(T3.back() > *std::min_element(T3.begin(), T3.end()) + 1);
  CHECK(k3.back() == *std::max_element(k3.begin(), k3.end()));
  CHECK(k3.back() > 1.2 * k3[1]);
}
