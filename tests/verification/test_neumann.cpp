// Two-phase Neumann problems (Kurylyk et al. 2014): thaw (Kurylyk et al. 2014, benchmark 1)
// and the same column frozen from the surface, with ice lighter than water (917 kg/m³) and the
// latent heat counted with the density of ice. Both time schemes, three resolutions, and the
// FLIP, PIC and blended particle updates.
//
// The front. A continuous SFCC releases its latent heat over a window of width ~W below 0 °C,
// the closed form at one temperature. The front compared is where half the pore water has
// changed phase (S_l = ½, the centre of the latent release), which the closed form's sharp
// front is the limit of as W → 0; the 0 °C isotherm, the window's thawed edge, sits about
// W/|∇T| away from it (≈ 1 % of X for W = 0.02 °C) and is printed alongside.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "thermal_harness.hpp"
#include "verification/analytic/heat_conduction.hpp"

using namespace frostmpm::test;
namespace an = frostmpm::analytic;

namespace {

constexpr double kDay = 86400.0;
constexpr double kThawedCapacity = 0.5 * 1000 * 4182 + 0.5 * 2500 * 889;

struct Direction {
  const char* scene;
  double length;           ///< column length [m]
  const char* half_front;  ///< probe: S_l = ½ contour
  const char* zero_front;  ///< probe: 0 °C isotherm
  an::NeumannSolution exact;
};

Direction thaw() {
  an::NeumannParams p{};
  p.k1 = 1.839;  // thawed (changed phase)
  p.k2 = 2.619;  // frozen
  p.C1 = kThawedCapacity;
  p.C2 = 2.169e6;
  p.L_v = 0.5 * 1000 * 334000;
  p.Ts = 5;
  p.Ti = -5;
  p.Tf = 0;
  p.s = -1;
  return {"neumann_thaw.yaml", 1.5, "half_thawed_depth", "thaw_depth", an::NeumannSolution(p)};
}

Direction freezing() {
  an::NeumannParams p{};
  p.k1 = 2.619;  // frozen (changed phase): 0.5·3.078 + 0.5·2.16
  p.k2 = 1.839;
  p.C1 = 0.5 * 2500 * 889 + 0.5 * 917 * 2115.5;  // ice at 917 kg/m³
  p.C2 = kThawedCapacity;
  p.L_v = 0.5 * 917 * 334000;  // latent heat with the density of ice
  p.Ts = -5;
  p.Ti = 5;
  p.Tf = 0;
  p.s = 1;
  return {"neumann_freezing.yaml", 2.0, "half_frozen_depth", "freeze_depth", an::NeumannSolution(p)};
}

/// The sand of the frozen-inclusion benchmark (κ_s = 9 W/m/K, porosity 0.37) frozen from the
/// surface: the solid carries most of the heat (neumann_freezing_conductive.yaml).
Direction conductive_freezing() {
  an::NeumannParams p{};
  p.k1 = 0.63 * 9.0 + 0.37 * 2.14;  // frozen
  p.k2 = 0.63 * 9.0 + 0.37 * 0.6;
  p.C1 = 0.63 * 2650 * 835 + 0.37 * 920 * 2060;
  p.C2 = 0.63 * 2650 * 835 + 0.37 * 1000 * 4182;
  p.L_v = 0.37 * 920 * 3.34e5;
  p.Ts = -5;
  p.Ti = 5;
  p.Tf = 0;
  p.s = 1;
  return {"neumann_freezing_conductive.yaml", 2.0, "half_frozen_depth", "freeze_depth", an::NeumannSolution(p)};
}

struct Level {
  double h = 0, dt = 0, front = 0, zero_front = 0, rmse = 0, max_error = 0, t_min = 0, t_max = 0;
  double energy_error = 0;
  ColumnRun run;
};

Level run_level(const Direction& dir, double h, const std::string& scheme, std::vector<std::string> overrides = {}) {
  ColumnSetup s{dir.scene, dir.length, h, scheme};
  if (scheme == "implicit") s.dt = 60;
  s.overrides = std::move(overrides);
  Level l;
  l.run = run_column(s);
  l.h = h;
  l.dt = l.run.mean_dt;
  l.front = l.run.last(dir.half_front);
  l.zero_front = l.run.last(dir.zero_front);
  REQUIRE(l.run.metrics.back()[0] == Approx(kDay));
  // Profile over the top 1 m (the published profile ends at 0.5 m; the far end is adiabatic).
  std::vector<double> depth, T;
  for (std::size_t p = 0; p < l.run.depth.size(); ++p)
    if (l.run.depth[p] <= 1.0) {
      depth.push_back(l.run.depth[p]);
      T.push_back(l.run.temperature[p]);
    }
  const auto e = an::profile_error(depth, T, [&](double x) { return dir.exact(x, kDay); });
  l.rmse = e.rmse;
  l.max_error = e.max_abs;
  l.t_min = *std::min_element(l.run.temperature.begin(), l.run.temperature.end());
  l.t_max = *std::max_element(l.run.temperature.begin(), l.run.temperature.end());
  l.energy_error = l.run.counters.at("thermal.energy_balance_error_relative");
  const double X = dir.exact.front(kDay);
  char line[240];
  std::snprintf(line, sizeof line, "front S=1/2 %.5f m (%+.2f %%), 0 degC %.5f m (%+.2f %%), RMSE %.4f max %.3f degC",
                l.front, 100 * (l.front / X - 1), l.zero_front, 100 * (l.zero_front / X - 1), l.rmse, l.max_error);
  WARN(dir.scene << " " << describe(s, l.run, line));
  return l;
}

/// Three resolutions (or more, finest last): the front within max(1 %, Δx/2) at each and 1 % at
/// 2.5 mm, the profile error and its order from 1 cm to 2.5 mm, the maximum principle and the
/// energy balance. Returns the levels.
std::vector<Level> verify(const Direction& dir, const std::string& scheme,
                          const std::vector<double>& cells = {0.01, 0.005, 0.0025}) {
  const double X = dir.exact.front(kDay);
  std::vector<Level> levels;
  for (double h : cells) levels.push_back(run_level(dir, h, scheme));
  for (const auto& l : levels) {
    INFO("h = " << l.h << ": front " << l.front << " m, closed form " << X << " m");
    CHECK(std::abs(l.front - X) <= std::max(0.01 * X, l.h / 2));
    // Maximum principle: nothing leaves the range of the initial and boundary values.
    CHECK(l.t_max <= 5.0 + 1e-9);
    CHECK(l.t_min >= -5.0 - 1e-9);
    CHECK(l.energy_error <= 1e-9);
  }
  const Level& fine = levels[2];  // 2.5 mm
  CHECK(std::abs(fine.front - X) <= 0.01 * X);
  // Measured (both directions, both schemes): RMSE 0.052–0.061 → 0.0071–0.0093 °C, order ≈ 1.4.
  CHECK(fine.rmse <= 0.012);
  const double order = an::observed_order(levels.front().rmse, fine.rmse, levels.front().h, fine.h);
  INFO("observed RMSE order " << order);
  CHECK(order >= 1.0);
  return levels;
}

}  // namespace

TEST_CASE("Neumann thaw (Kurylyk benchmark 1), explicit: front within 1 % at 2.5 mm, first-order profile",
          "[verification][neumann]") {
  verify(thaw(), "explicit");
}

TEST_CASE("Neumann thaw (Kurylyk benchmark 1), implicit at 60 s: front within 1 % at 2.5 mm",
          "[verification][neumann]") {
  verify(thaw(), "implicit");
}

TEST_CASE("Neumann freezing, ice lighter than water, explicit: front within 1 % at 2.5 mm",
          "[verification][neumann]") {
  verify(freezing(), "explicit");
}

TEST_CASE("Neumann freezing, ice lighter than water, implicit at 60 s: front within 1 % at 2.5 mm",
          "[verification][neumann]") {
  verify(freezing(), "implicit");
}

// The 0 °C isotherm of this soil was 1.4–1.7 % ahead of the closed form at 5 mm. Two parts: the
// SFCC window's thawed edge lies ahead of the centre of the latent release in the model itself
// (+0.580 % of X for W = 0.02 °C: a finite-volume enthalpy solution of the same model on 0.25 mm
// cells, scripts/neumann_window_reference.py), and the rest is the first-order error of the
// temperature where each node takes up its latent heat in turn. The S_l = ½ front carries
// neither and is within 0.5 % from 5 mm down.
TEST_CASE("Neumann freezing of a soil with a conductive solid, implicit at 60 s: S_l = 1/2 front within 0.5 %, "
          "0 degC isotherm converging",
          "[verification][neumann]") {
  const Direction dir = conductive_freezing();
  const double X = dir.exact.front(kDay);
  REQUIRE(X == Approx(0.184246).epsilon(1e-5));
  const auto all = verify(dir, "implicit", {0.01, 0.005, 0.0025, 0.00125});
  const std::vector<Level> levels(all.begin() + 1, all.end());  // 5, 2.5, 1.25 mm
  // Measured: S_l = ½ −0.44 / −0.26 / −0.23 %; 0 °C +1.43 / +0.99 / +0.79 %.
  for (const auto& l : levels) CHECK(std::abs(l.front / X - 1) <= 0.005);
  CHECK(std::abs(levels[1].front / X - 1) <= 0.003);
  CHECK(std::abs(levels[2].front / X - 1) <= 0.003);
  // The isotherm approaches the window's edge (+0.580 %) at first order: its distance to it
  // halves with h (measured ratios 2.1 and 1.9 from 5 to 1.25 mm).
  const double edge = 1.00580 * X;
  const double ratio = (levels[0].zero_front - edge) / (levels[1].zero_front - edge);
  const double ratio_fine = (levels[1].zero_front - edge) / (levels[2].zero_front - edge);
  INFO("0 degC isotherm: distance to the window's edge shrinks by " << ratio << " then " << ratio_fine);
  CHECK(levels[2].zero_front > edge);
  CHECK(ratio >= 1.6);
  CHECK(ratio_fine >= 1.6);
}

TEST_CASE("Neumann thaw and freezing with PIC and a 0.95 blend: the fronts of FLIP, energy exact",
          "[verification][neumann]") {
  for (const auto& dir : {thaw(), freezing()})
    for (const char* scheme : {"explicit", "implicit"}) {
      const double X = dir.exact.front(kDay);
      const Level flip = run_level(dir, 0.0025, scheme);
      for (const char* fraction : {"0", "0.95"}) {
        INFO(dir.scene << ", " << scheme << ", flip_fraction " << fraction);
        const Level blend = run_level(dir, 0.0025, scheme, {std::string("physics.thermal.flip_fraction=") + fraction});
        CHECK(std::abs(blend.front - X) <= 0.01 * X);
        CHECK(std::abs(blend.front - flip.front) <= 1e-3 * X);
        CHECK(blend.rmse <= 1.1 * flip.rmse + 1e-3);
        CHECK(blend.t_max <= 5.0 + 1e-9);
        CHECK(blend.t_min >= -5.0 - 1e-9);
        CHECK(blend.energy_error <= 1e-9);
      }
    }
}
