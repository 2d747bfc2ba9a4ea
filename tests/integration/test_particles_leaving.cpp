// Particles that leave the grid: by default the run stops with one line naming the particle, its
// region and the time (exit 3); with `grid.particles_leaving: remove` they are dropped and what
// they carried is counted in run.json (heat, mass), the balances stay closed, and a run stopped
// with SIGTERM after some left continues with `--restart` to the metrics of an uninterrupted run,
// and so does a checkpoint taken between the step that moved particles off and their removal.
#include <catch2/catch.hpp>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <thread>

#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

// configs/verification/flying_block.yaml — a free elastic block 0.3 m × 0.2 m at 5 °C flying at
// 0.25 m/s — on a grid whose x_max edge (x = 1 m) it crosses. Particle columns (spacing 0.01 m,
// half-width 0.005 m) start at x_k = 0.505 + 0.01 k, k = 0..29, 20 rows each; column k is outside
// the grid once its domain's left edge passes x = 1: 0.5 + 0.01 k + 0.25 t > 1. At t = 1.606 s that
// is k ≥ 10 (k = 9 ends 8.5 mm inside, k = 10 1.5 mm outside): 20 columns, 400 particles leave,
// 200 remain.
const std::string kBlock =
    verification_scene("flying_block.yaml") +
    " --set 'grid.cells=[50, 20]' --set grid.particles_leaving=remove --set time.end=1.606"
    " --set 'output={every: 0.2, metrics_every: 0.01, fields: [temperature, particle_id, solid_velocity],"
    " progress: false}' --set 'checkpoint={every_steps: 2000}'"
    " --set 'probes=[{name: T_min, type: min, field: temperature}, {name: T_max, type: max, field: temperature}]'";

}  // namespace

TEST_CASE("particles leaving the grid: a clean stop by default, or removed with their heat and mass counted",
          "[leaving]") {
  TempDir dir;

  SECTION("stop (the default) names the particle, its region and the time, exit 3") {
    const auto r = run_frostmpm("run " + kBlock + " -o " + dir.file("stop") +
                                " --set grid.particles_leaving=stop --set 'output.fields=[temperature]'");
    INFO(r.output);
    REQUIRE(r.exit_code == 3);
    REQUIRE_THAT(r.output, Catch::Contains("has left the grid") && Catch::Contains("in regions.0") &&
                               Catch::Contains("grid.particles_leaving: remove"));
    // The block's first column leaves at t = (1 − 0.79) / 0.25 = 0.84 s.
    const auto at = r.output.find("at t = ");
    REQUIRE(at != std::string::npos);
    CHECK(std::stod(r.output.substr(at + 7)) == Approx(0.84).margin(0.002));
  }

  SECTION("remove: the closed-form count leaves, heat and mass are accounted, the rest flies on") {
    const std::string out = dir.file("remove");
    const auto r = run_frostmpm("run " + kBlock + " -o " + out);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(run_json(out, "['run']['removed_particles']") == "400");
    CHECK(run_json(out, "['run']['particles']") == "200");
    // Mass: 400 × V_p ρ_m, V_p = 1e-4 m², ρ_m = 0.7 · 2000 + 0.3 · 1000 (liquid water at 5 °C).
    CHECK(run_counter(out, "mechanical.mass_removed_kg") == Approx(400 * 1e-4 * 1700).epsilon(1e-9));
    // The 200 left move on at 0.25 m/s: ½ m v², measured 5e-13 off. A domain clipped at the edge
    // narrows to ~1e-11 cells on its last step: with its gradients from the closed form the rigid
    // motion strained it and the rest took 2e-6 of the energy.
    CHECK(run_counter(out, "mechanical.kinetic_energy_J") == Approx(0.5 * 200 * 1e-4 * 1700 * 0.0625).epsilon(1e-10));
    // Heat: nothing enters, so the stored heat falls by what left, two thirds of the block's.
    const double removed = run_counter(out, "thermal.energy_removed_J");
    CHECK(removed > 0);
    CHECK(-run_counter(out, "thermal.energy_stored_change_J") == Approx(removed).epsilon(1e-8));
    CHECK(run_counter(out, "thermal.energy_balance_error_relative") < 1e-10);
    // The temperature of the particles that remain is untouched by the removal.
    const auto metrics = read_csv(out + "/metrics.csv");
    for (const auto& row : metrics.rows) {
      CHECK(row[metrics.column("T_min")] == Approx(5.0).epsilon(1e-9));
      CHECK(row[metrics.column("T_max")] == Approx(5.0).epsilon(1e-9));
    }
  }

  SECTION("a restart whose checkpoint holds particles the last step moved off the grid counts them") {
    // Column k = 28's domain passes x = 1 at t = 0.88 s: the run ending 5 µs later checkpoints
    // after the step that moved it off, before the next step would remove it. (Metrics every
    // 0.0123 s: a row at 0.88 s would land a step on the crossing itself, where round-off
    // decides on which side the column stands.)
    const std::string out = dir.file("edge");
    const auto first = run_frostmpm("run " + kBlock + " -o " + out +
                                    " --set time.end=0.880005 --set output.metrics_every=0.0123");
    REQUIRE(first.exit_code == 0);
    const auto removed_before = std::stoi(run_json(out, "['run']['removed_particles']"));
    CHECK(removed_before >= 20);
    CHECK(removed_before < 40);
    const auto resumed = run_frostmpm("run --restart " + out + " --set time.end=1.606");
    INFO(resumed.output);
    REQUIRE(resumed.exit_code == 0);
    CHECK(run_json(out, "['run']['removed_particles']") == "400");
    CHECK(run_counter(out, "mechanical.mass_removed_kg") == Approx(400 * 1e-4 * 1700).epsilon(1e-9));
    const double removed = run_counter(out, "thermal.energy_removed_J");
    CHECK(-run_counter(out, "thermal.energy_stored_change_J") == Approx(removed).epsilon(1e-8));
  }

  SECTION("a run stopped after particles left continues with --restart to the same metrics") {
    const auto reference = run_frostmpm("run " + kBlock + " -o " + dir.file("reference"));
    REQUIRE(reference.exit_code == 0);
    const std::string out = dir.file("stopped");
    {
      BackgroundRun run("run " + kBlock + " -o " + out, dir.file("stdout"), dir.file("stderr"));
      // Stop once the metrics pass 1.0 s, when 80 particles have left (the checkpoint at the
      // stop holds fewer particles than the scene makes).
      const auto start = std::chrono::steady_clock::now();
      for (;;) {
        REQUIRE(run.running());
        const auto rows = read_csv(out + "/metrics.csv").rows;
        if (!rows.empty() && rows.back()[0] >= 1.0) break;
        REQUIRE(std::chrono::steady_clock::now() - start < std::chrono::seconds(120));
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      run.signal(SIGTERM);
      REQUIRE(run.wait() == 128 + SIGTERM);
    }
    REQUIRE(read_csv(out + "/metrics.csv").rows.back()[0] < 1.606);
    const auto resumed = run_frostmpm("run --restart " + out);
    INFO(resumed.output);
    REQUIRE(resumed.exit_code == 0);
    CHECK(read_file(out + "/metrics.csv") == read_file(dir.file("reference") + "/metrics.csv"));
    CHECK(run_json(out, "['run']['removed_particles']") == "400");
    CHECK(run_counter(out, "thermal.energy_removed_J") == run_counter(dir.file("reference"), "thermal.energy_removed_J"));
    CHECK(run_counter(out, "mechanical.mass_removed_kg") ==
          run_counter(dir.file("reference"), "mechanical.mass_removed_kg"));
  }
}
