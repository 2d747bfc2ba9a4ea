// Plugins that fail safely: every library the loader cannot use is refused with one line
// naming the file and the reason, the others still load; and `frostmpm test-model`, the
// contract check plugin authors (and the shipped models) run.
#include <catch2/catch.hpp>

#include <filesystem>

#include "frostmpm/plugin/plugin_api.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;
namespace fs = std::filesystem;

namespace {

std::string fixtures() { return binary_dir() + "/test-fixtures"; }

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// The line of `text` that contains `part`, or "".
std::string line_with(const std::string& text, const std::string& part) {
  const auto at = text.find(part);
  if (at == std::string::npos) return "";
  const auto begin = text.rfind('\n', at) == std::string::npos ? 0 : text.rfind('\n', at) + 1;
  return text.substr(begin, text.find('\n', at) - begin);
}

const std::string& kScene = kFreezingCurvesScene;

/// `frostmpm check` of the freezing-curves scene with extra arguments.
CommandResult check_scene(const std::string& extra) {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kScene);
  return run_frostmpm("check " + dir.file("scene.yaml") + " " + extra);
}

}  // namespace

TEST_CASE("plugins lists good plugins and every refused library with its reason, exit 0", "[plugins]") {
  const auto r = run_frostmpm("plugins --plugin-path " + fixtures());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(has(r.output, "broken_sfcc"));  // a good (if wrong) plugin from the same folder
  CHECK(has(r.output, "van_genuchten_cc"));
  const std::string unresolved = line_with(r.output, "libfixture_unresolved_symbol.so");
  CHECK(unresolved.rfind("refused: ", 0) == 0);
  CHECK(has(unresolved, "unresolved symbol 'frostmpm_missing_symbol_for_test()'"));
  const std::string stale = line_with(r.output, "libfixture_stale_abi.so");
  CHECK(has(stale, "built for kernel ABI 'frostmpm-abi-"));
  CHECK(has(stale, std::string("this FrostMPM is '") + frostmpm::kKernelAbiTag + "'"));
  CHECK(!has(stale, std::string("'") + frostmpm::kKernelAbiTag + "', this"));  // the tags differ
  const std::string bad_default = line_with(r.output, "libfixture_bad_default.so");
  CHECK(has(bad_default, "sfcc model 'bad_default'"));
  CHECK(has(bad_default, "default 1 of parameter 'residual_saturation' is outside its own range [0, 1)"));
  CHECK(!has(r.output, "bad_default  "));  // nothing of a refused library stays registered
  const std::string bad_unit = line_with(r.output, "libfixture_bad_unit.so");
  CHECK(has(bad_unit, "sfcc model 'bad_unit': parameter 'width' declares the unit 'celsiuz'"));
  CHECK(has(line_with(r.output, "libfixture_not_a_plugin.so"), "not a FrostMPM plugin"));
}

TEST_CASE("a library named directly that cannot load is one error line", "[plugins][bad-input]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kScene);
  write_file(dir.file("notes.so"), "not a library");
  const std::string run = "run " + dir.file("scene.yaml") + " -o " + dir.file("out") + " --plugin-path ";
  struct Case {
    std::string path, expected;
  } cases[] = {{fixtures() + "/libfixture_unresolved_symbol.so", "unresolved symbol 'frostmpm_missing_symbol_for_test()'"},
               {dir.file("missing.so"), "refused: no such file"},
               {dir.file("notes.so"), "refused: not a shared library ("}};
  for (const auto& c : cases) {
    const auto r = run_frostmpm(run + c.path);
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.rfind("error: --plugin-path " + c.path, 0) == 0);
    CHECK(has(r.output, c.expected));
    CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  }
}

TEST_CASE("a plugin folder that does not exist is a warning", "[plugins]") {
  const auto r = run_frostmpm("plugins");
  const auto w = run_command("FROSTMPM_PLUGIN_PATH=/nonexistent/frostmpm-plugins " + frostmpm_exe() + " plugins");
  INFO(w.output);
  REQUIRE(w.exit_code == 0);
  CHECK(has(w.output, "warning: plugin folder /nonexistent/frostmpm-plugins does not exist; skipped"));
  CHECK(!has(r.output, "warning"));
}

TEST_CASE("an unknown model names the registered ones and the plugin folders searched", "[plugins][bad-input]") {
  const auto r = check_scene("--set material.sfcc.model=painter_karra");
  INFO(r.output);
  REQUIRE(r.exit_code == 2);
  CHECK(has(r.output, "unknown sfcc model 'painter_karra'"));
  CHECK(has(r.output, "Registered: exponential, linear, power_law, table, van_genuchten_cc"));
  CHECK(has(r.output, "Plugin folders searched: " + fs::weakly_canonical(binary_dir() + "/lib/frostmpm/plugins").string()));
}

TEST_CASE("swapping only the model name names the old model's parameters and the one-line swap", "[plugins][bad-input]") {
  auto r = check_scene("--set material.sfcc.model=exponential");
  INFO(r.output);
  REQUIRE(r.exit_code == 2);
  CHECK(has(r.output, "sfcc model 'exponential' does not take lambda (of van_genuchten_cc), p0 (of van_genuchten_cc)"));
  CHECK(has(r.output, "it takes: width, residual_saturation, freezing_point"));
  CHECK(has(r.output, "--set 'material.sfcc={model: exponential, ...}'"));
  r = check_scene("--set 'material.sfcc={model: exponential, width: 0.5, residual_saturation: 0.05}'");
  CHECK(r.exit_code == 0);
}

TEST_CASE("test-model: every shipped SFCC, permeability and mechanical model keeps its contract",
          "[plugins][contract]") {
  const auto& registry = builtin_registry();
  int checked = 0;
  for (const std::string kind : {"sfcc", "relative_permeability", "absolute_permeability", "mechanical_model"})
    for (const auto* entry : registry.entries(kind)) {
      // Required parameters are picked inside their ranges; linear's mushy_end has no range, and
      // a table has no default points.
      const std::string extra =
          entry->name == "linear"  ? " --set mushy_end=-1"
          : entry->name == "table" ? " --set 'temperatures=[-5, -2, -1, -0.5, 0]' --set 'saturations=[0.05, 0.1, 0.2, 0.5, 1]'"
                                   : "";
      const auto r = run_frostmpm("test-model " + kind + "/" + entry->name + extra);
      INFO(r.output);
      CHECK(r.exit_code == 0);
      CHECK(has(r.output, kind + "/" + entry->name + ": contract kept"));
      ++checked;
    }
  CHECK(checked >= 10);
}

TEST_CASE("test-model mechanical_model/linear_elastic samples its parameter ranges", "[plugins][contract]") {
  auto r = run_frostmpm("test-model mechanical_model/linear_elastic");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(has(r.output, "youngs_modulus=5e+12 (picked), poisson_ratio=-0.25 (picked), frozen_youngs_modulus=0"));
  CHECK(has(r.output, "parameter sets: 7 (the above, and each of youngs_modulus, poisson_ratio, frozen_youngs_modulus "
                      "at 1 % and 99 % of its range)"));
  CHECK(has(r.output, "mechanical_model/linear_elastic: contract kept"));
  // A parameter given with --set stays fixed.
  r = run_frostmpm("test-model mechanical_model/linear_elastic --set youngs_modulus=1e6 --set poisson_ratio=0.3 "
                   "--samples 100");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(has(r.output, "parameter sets: 3 (the above, and each of frozen_youngs_modulus at 1 % and 99 % of its range)"));
  CHECK(has(r.output, "sampled: 100 states per set"));
}

TEST_CASE("test-model flags a deliberately broken model, one line per violated rule, exit 1", "[plugins][contract]") {
  const std::string plugin = " --plugin-path " + fixtures() + "/libfixture_broken_models.so";
  auto r = run_frostmpm("test-model sfcc/broken_sfcc" + plugin);
  INFO(r.output);
  REQUIRE(r.exit_code == 1);
  for (const char* rule : {"is outside [0, 1]", "S_l decreases as T rises", "dS_l/dT(T = ", "S_l jumps at the freezing point",
                           "dS_l/dp_l(T = "})
    CHECK(has(line_with(r.output, rule), "violation: "));
  CHECK(has(r.output, "sfcc/broken_sfcc: 5 contract rule(s) broken"));
  r = run_frostmpm("test-model relative_permeability/broken_relative" + plugin);
  CHECK(r.exit_code == 1);
  CHECK(has(r.output, "violation: k_r(S_l = "));
  CHECK(has(r.output, "must be 1 when fully saturated"));
  r = run_frostmpm("test-model absolute_permeability/broken_absolute" + plugin);
  CHECK(r.exit_code == 1);
  CHECK(has(r.output, "violation: k_a(porosity = 0.01) = -1e-07 must be positive"));
  r = run_frostmpm("test-model mechanical_model/broken_elastic" + plugin);
  CHECK(r.exit_code == 1);
  for (const char* rule : {"tangent dstress_yz/dstrain_yz = ", "not objective: ", "stress_xx and stress_yy do not swap",
                           "is outside (0, max_p_wave_modulus() = "})
    CHECK(has(line_with(r.output, rule), "violation: "));
  CHECK(has(r.output, "parameter sets: 3 (the above, and each of youngs_modulus at 1 % and 99 % of its range)"));
  CHECK(has(line_with(r.output, "tangent dstress_yz"), "(and 6002 more samples)"));  // 2001 states in each set
  CHECK(has(r.output, "mechanical_model/broken_elastic: 4 contract rule(s) broken"));
  r = run_frostmpm("test-model mechanical_model/broken_creep" + plugin);
  CHECK(r.exit_code == 1);
  for (const char* rule : {"initial_state() has 2 entries", "a zero strain increment changes the stress",
                           "state 'creep_strain' = nan", "the integration fails (", "shear_modulus = nan"})
    CHECK(has(line_with(r.output, rule), "violation: "));
  CHECK(has(line_with(r.output, "shear_modulus = nan"), "no T, S_c or p_l given"));
  CHECK(has(r.output, "mechanical_model/broken_creep: 5 contract rule(s) broken"));
  r = run_frostmpm("test-model physics/thermal");
  CHECK(r.exit_code == 2);
  CHECK(has(r.output, "no contract check for kind 'physics'; it checks sfcc, relative_permeability, "
                      "absolute_permeability and mechanical_model models"));
  r = run_frostmpm("test-model boundary_conditions/temperature");  // a description, not a model
  CHECK(r.exit_code == 2);
  CHECK(has(r.output, "no contract check for kind 'boundary_conditions'"));
}
