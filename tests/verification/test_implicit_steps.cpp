// The implicit scheme's nonlinear solve across time steps and freezing windows: Neumann thaw
// and freezing (Kurylyk et al. 2014) at Δx = 2.5 mm for Δt = 1 s … 3600 s and
// W = 0.005, 0.02, 0.5 °C. Every step converges (a step Newton cannot finish is retried in
// halves, never accepted — the run stops instead), energy is conserved to round-off, and the
// front error shrinks monotonically as Δt does.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "thermal_harness.hpp"
#include "verification/analytic/heat_conduction.hpp"

using namespace frostmpm::test;
namespace an = frostmpm::analytic;

namespace {

constexpr double kDay = 86400.0;

struct Sweep {
  const char* scene;
  double length;
  const char* front_probe;  ///< S_l = ½ contour
  double exact_front;       ///< closed form at 1 d (sharp front)
};

// Closed-form fronts at 1 d (the same parameters as test_neumann.cpp).
double front(double k1, double k2, double C1, double C2, double L_v, double Ts, double Ti, int s) {
  an::NeumannParams p{k1, k2, C1, C2, L_v, Ts, Ti, 0.0, s};
  return an::NeumannSolution(p).front(kDay);
}
const double kThawed = 0.5 * 1000 * 4182 + 0.5 * 2500 * 889;
const Sweep kThaw{"neumann_thaw.yaml", 1.5, "half_thawed_depth",
                  front(1.839, 2.619, kThawed, 2.169e6, 0.5 * 1000 * 334000, 5, -5, -1)};
const Sweep kFreeze{"neumann_freezing.yaml", 2.0, "half_frozen_depth",
                    front(2.619, 1.839, 0.5 * 2500 * 889 + 0.5 * 917 * 2115.5, kThawed, 0.5 * 917 * 334000, -5, 5, 1)};

void sweep(const Sweep& sw, double width) {
  const std::vector<double> steps = {3600, 900, 300, 60, 10, 1};
  std::vector<double> fronts;
  for (double dt : steps) {
    ColumnSetup s{sw.scene, sw.length, 0.0025, "implicit", dt, {"materials.soil.sfcc.width=" + std::to_string(width)}};
    const ColumnRun run = run_column(s);
    fronts.push_back(run.last(sw.front_probe));
    const auto& c = run.counters;
    char line[200];
    std::snprintf(line, sizeof line, "W=%g front %+.3f %%, Newton max %g, rejected half-steps %g", width,
                  100 * (fronts.back() / sw.exact_front - 1), c.at("thermal.nonlinear_iterations_max"),
                  c.at("thermal.rejected_substeps"));
    WARN(sw.scene << " " << describe(s, run, line));
    INFO("dt = " << dt);
    REQUIRE(run.metrics.back()[0] == Approx(kDay));  // reached the end: no step was given up
    CHECK(c.at("thermal.substeps_total") >= kDay / dt - 1e-9);
    CHECK(c.at("thermal.energy_balance_error_relative") <= 1e-9);
    CHECK(run.last("T_max") <= 5.0 + 1e-9);
    CHECK(run.last("T_min") >= -5.0 - 1e-9);
  }
  // Δt → 0 converges monotonically: the distance to the Δt = 1 s front never grows as Δt shrinks.
  for (std::size_t k = 1; k + 1 < steps.size(); ++k) {
    INFO("dt " << steps[k - 1] << " -> " << steps[k]);
    CHECK(std::abs(fronts[k] - fronts.back()) <= std::abs(fronts[k - 1] - fronts.back()) + 1e-6 * sw.exact_front);
  }
  if (width <= 0.02) {
    // A narrow window is the sharp closed form's problem: the error itself shrinks with Δt
    // (space and time errors have one sign at 2.5 mm) and ends within 1 %.
    for (std::size_t k = 1; k < steps.size(); ++k) {
      INFO("dt " << steps[k - 1] << " -> " << steps[k]);
      CHECK(std::abs(fronts[k] - sw.exact_front) <= std::abs(fronts[k - 1] - sw.exact_front) + 1e-6 * sw.exact_front);
    }
    CHECK(std::abs(fronts.back() - sw.exact_front) <= 0.01 * sw.exact_front);
  }
}

}  // namespace

TEST_CASE("implicit Neumann thaw, W = 0.005 degC, dt 1 s to 3600 s: every step converges, error shrinks with dt",
          "[verification][implicit-steps]") {
  sweep(kThaw, 0.005);
}
TEST_CASE("implicit Neumann thaw, W = 0.02 degC, dt 1 s to 3600 s", "[verification][implicit-steps]") {
  sweep(kThaw, 0.02);
}
TEST_CASE("implicit Neumann thaw, W = 0.5 degC, dt 1 s to 3600 s", "[verification][implicit-steps]") {
  sweep(kThaw, 0.5);
}
TEST_CASE("implicit Neumann freezing, W = 0.005 degC, dt 1 s to 3600 s", "[verification][implicit-steps]") {
  sweep(kFreeze, 0.005);
}
TEST_CASE("implicit Neumann freezing, W = 0.02 degC, dt 1 s to 3600 s", "[verification][implicit-steps]") {
  sweep(kFreeze, 0.02);
}
TEST_CASE("implicit Neumann freezing, W = 0.5 degC, dt 1 s to 3600 s", "[verification][implicit-steps]") {
  sweep(kFreeze, 0.5);
}
