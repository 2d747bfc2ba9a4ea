// The third-party path end to end: install the SDK into a prefix, build an out-of-tree
// example (examples/plugin-template, examples/constitutive-template, examples/drucker-prager)
// against it alone, put it on FROSTMPM_PLUGIN_PATH and run a scene that names it — with the
// already-built frostmpm, nothing of FrostMPM rebuilt.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "test_support.hpp"

using namespace frostmpm::test;
namespace fs = std::filesystem;

namespace {

/// Installs the SDK into dir/prefix, then configures and builds examples/<example> against it
/// in dir/plugin-build; returns the build folder.
std::string build_template(const TempDir& dir, const std::string& example) {
  const std::string prefix = dir.file("prefix");
  const std::string plugin_build = dir.file("plugin-build");

  auto r = run_command("cmake --install " + binary_dir() + " --prefix " + prefix);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(fs::exists(prefix + "/include/frostmpm/models/sfcc_model.hpp"));
  REQUIRE(fs::exists(prefix + "/include/frostmpm/models/mechanical_model.hpp"));
  REQUIRE(fs::exists(prefix + "/lib/cmake/FrostMPM/FrostMPMConfig.cmake"));

  // Configure with the SDK prefix only; the template's source is copied so nothing from the
  // FrostMPM tree (include paths, targets) can leak in.
  fs::copy(source_dir() + "/examples/" + example, dir.file("template"), fs::copy_options::recursive);
  // No CMAKE_BUILD_TYPE: the SDK makes it Release, so a plugin is optimised by default.
  r = run_command("cmake -S " + dir.file("template") + " -B " + plugin_build + " -DCMAKE_PREFIX_PATH=" + prefix);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(read_file(plugin_build + "/CMakeCache.txt").find("CMAKE_BUILD_TYPE:STRING=Release") != std::string::npos);
  r = run_command("cmake --build " + plugin_build + " -j 2");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return plugin_build;
}

/// `frostmpm test-model KIND/NAME` with the plugin's folder on the search path (and `--set`
/// overrides): exit 0 and "contract kept".
void require_contract_kept(const std::string& plugin_build, const std::string& model, const std::string& sets = "") {
  const auto r = run_frostmpm("test-model " + model + " --plugin-path " + plugin_build + sets);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.output.find(model + ": contract kept") != std::string::npos);
}

/// Runs the copied example's scene.yaml into dir/out with the plugin on FROSTMPM_PLUGIN_PATH.
void run_example_scene(const TempDir& dir, const std::string& plugin_build) {
  const auto r = run_command("FROSTMPM_PLUGIN_PATH=" + plugin_build + " " + frostmpm_exe() + " run " +
                             dir.file("template/scene.yaml") + " -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
}

}  // namespace

TEST_CASE("an out-of-tree SFCC plugin builds against the installed SDK and runs", "[sdk]") {
  TempDir dir;
  const std::string plugin_build = build_template(dir, "plugin-template");
  REQUIRE(fs::exists(plugin_build + "/libmy_sfcc.so"));

  const std::string env = "FROSTMPM_PLUGIN_PATH=" + plugin_build + " ";
  auto r = run_command(env + frostmpm_exe() + " plugins");
  INFO(r.output);
  REQUIRE(r.output.find("exponential_decay") != std::string::npos);
  REQUIRE(r.output.find("libmy_sfcc.so") != std::string::npos);

  // The author's contract check passes for the template's model.
  r = run_command(env + frostmpm_exe() + " test-model sfcc/exponential_decay");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.output.find("sfcc/exponential_decay: contract kept") != std::string::npos);

  r = run_command(env + frostmpm_exe() + " run " + dir.file("template/scene.yaml") + " -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  // The curve it produced: S_l = 0.1 + 0.9 exp(T / 0.5) below 0 degC, 1 above (scene values).
  std::ifstream csv(dir.file("out/freezing_curves.csv"));
  std::string line;
  std::getline(csv, line);
  int checked = 0;
  while (std::getline(csv, line)) {
    double T = 0, S = 0;
    REQUIRE(std::sscanf(line.c_str(), "%lf,%lf", &T, &S) == 2);
    const double expected = T >= 0 ? 1.0 : 0.1 + 0.9 * std::exp(T / 0.5);
    REQUIRE(S == Approx(expected).epsilon(1e-9));
    ++checked;
  }
  REQUIRE(checked == 51);
}

TEST_CASE("an out-of-tree constitutive model builds against the installed SDK, keeps its contract and runs", "[sdk]") {
  TempDir dir;
  const std::string plugin_build = build_template(dir, "constitutive-template");
  REQUIRE(fs::exists(plugin_build + "/libmy_constitutive.so"));

  // The author's contract check, as the template's README runs it.
  require_contract_kept(plugin_build, "mechanical_model/temperature_elastic");
  run_example_scene(dir, plugin_build);
  // The two-layer small-strain settlement of the scene's header: 0.542 mm with the frozen top
  // (0.725 mm if it were thawed); the base carries the column's weight.
  const CsvTable metrics = read_csv(dir.file("out/metrics.csv"));
  const auto& last = metrics.rows.back();
  CHECK(last[metrics.column("time_s")] == Approx(0.5));
  CHECK(last[metrics.column("settlement")] == Approx(5.4185e-4).epsilon(0.01));
  CHECK(last[metrics.column("base_reaction")] == Approx((0.5 * 1990 + 0.5 * 1959.6) * 9.81 * 0.05).epsilon(1e-3));
  // The model's internal variable is a particle field of the run.
  CHECK(read_file(dir.file("out/run.json")).find("\"accumulated_shear_strain\"") != std::string::npos);
}

TEST_CASE("an out-of-tree plasticity model (Drucker-Prager) keeps its contract and reaches the closed-form strength",
          "[sdk]") {
  TempDir dir;
  const std::string plugin_build = build_template(dir, "drucker-prager");
  REQUIRE(fs::exists(plugin_build + "/libmy_drucker_prager.so"));

  // The contract, as the example's README runs it: the picked parameters (and each at 1 % and
  // 99 % of its range), then the scene's soil; both return to the cone and to its apex.
  require_contract_kept(plugin_build, "mechanical_model/drucker_prager");
  require_contract_kept(plugin_build, "mechanical_model/drucker_prager",
                        " --set youngs_modulus=4e7 --set cohesion=1e4 --set friction_angle=30 --set dilation_angle=30");
  run_example_scene(dir, plugin_build);
  // Plane-strain unconfined compression with associated flow: the plane-strain-matched cone is
  // Mohr-Coulomb's, so the axial stress levels off at 2c cos(phi)/(1 - sin(phi)) (c = 10 kPa,
  // phi = 30 degrees). sigma_v = -platen reaction / current width; the width follows the outermost
  // particle columns, 0.95 m apart at the start.
  const double phi = 30 * M_PI / 180, strength = 2 * 1.0e4 * std::cos(phi) / (1 - std::sin(phi));
  REQUIRE(strength == Approx(34641.016).epsilon(1e-6));
  const CsvTable metrics = read_csv(dir.file("out/metrics.csv"));
  const std::size_t time_s = metrics.column("time_s"), platen = metrics.column("platen_reaction"),
                    base = metrics.column("base_reaction"), left = metrics.column("u_left"),
                    right = metrics.column("u_right");
  CHECK(metrics.rows.back()[time_s] == Approx(12.0));
  int plateau = 0;
  for (const auto& row : metrics.rows) {
    // Before 2 s the block is elastic, well below its strength: the plateau is reached by plastic flow.
    if (row[time_s] <= 2.0) CHECK(-row[platen] < 0.6 * strength);
    if (row[time_s] < 9.0 - 1e-6) continue;  // the plateau: from 0.2 % vertical strain on
    INFO("t = " << row[time_s] << " s");
    const double width = 1.0 + (row[right] - row[left]) / 0.95;
    CHECK(-row[platen] / width == Approx(strength).epsilon(0.02));
    CHECK(row[base] == Approx(-row[platen]).epsilon(0.01));  // quasi-static: the base balances the platen
    ++plateau;
  }
  CHECK(plateau >= 30);
  // The model's internal variables are particle fields of the run.
  const std::string run_json = read_file(dir.file("out/run.json"));
  CHECK(run_json.find("\"plastic_shear_strain\"") != std::string::npos);
  CHECK(run_json.find("\"yielded\"") != std::string::npos);
}
