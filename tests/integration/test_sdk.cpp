// The third-party path end to end: install the SDK into a prefix, build an out-of-tree
// template (examples/plugin-template, examples/constitutive-template) against it alone, put
// it on FROSTMPM_PLUGIN_PATH and run a scene that names it — with the already-built frostmpm,
// nothing of FrostMPM rebuilt.
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
  auto r = run_frostmpm("test-model mechanical_model/temperature_elastic --plugin-path " + plugin_build);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.output.find("mechanical_model/temperature_elastic: contract kept") != std::string::npos);

  const std::string env = "FROSTMPM_PLUGIN_PATH=" + plugin_build + " ";
  r = run_command(env + frostmpm_exe() + " run " + dir.file("template/scene.yaml") + " -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
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
