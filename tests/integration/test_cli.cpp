// The `frostmpm` command as a user meets it: the default scene, swapping models in YAML, and
// every bad-input case (exit code 2, one clear line, nothing written to the output folder).
#include <catch2/catch.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "frostmpm/plugin/plugin_api.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;
namespace fs = std::filesystem;

namespace {

const std::string& kGoodScene = kFreezingCurvesScene;

std::string fixture(const std::string& name) { return binary_dir() + "/test-fixtures/" + name; }

/// Writes `scene` into a temp folder, runs it, and checks the failure contract.
CommandResult run_bad(const TempDir& dir, const std::string& scene, const std::string& extra = "") {
  write_file(dir.file("scene.yaml"), scene);
  const std::string out = dir.file("out");
  CommandResult r = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + out + " " + extra);
  INFO(r.output);
  REQUIRE(r.exit_code == 2);
  REQUIRE(r.output.rfind("error: ", 0) == 0);                       // one error line first...
  REQUIRE(std::count(r.output.begin(), r.output.end(), '\n') == 1);  // ...and only that line
  REQUIRE(!fs::exists(out));                                         // nothing written
  return r;
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  REQUIRE(pos != std::string::npos);
  return text.replace(pos, from.size(), to);
}

}  // namespace

TEST_CASE("default tutorial scene writes the CSV table and run.json", "[cli]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + source_dir() + "/configs/tutorials/freezing_curves.yaml -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto rows = read_csv(dir.file("out/freezing_curves.csv")).rows;
  REQUIRE(rows.size() == 601);
  REQUIRE(rows.front()[0] == Approx(-5.0));
  REQUIRE(rows.back()[1] == 1.0);  // thawed at +1 degC
  REQUIRE(read_csv(dir.file("out/freezing_curves.csv")).header ==
          std::vector<std::string>{"T_degC", "S_l", "dS_l_dT_per_degC", "dS_l_dp_per_Pa", "k_r", "dk_r_dS_l",
                                   "k_a_m_per_s", "k_m_per_s"});
  REQUIRE(!fs::exists(dir.file("out/freezing_curves.png")));  // figures: scripts/plot.py
  const std::string summary = read_file(dir.file("out/run.json"));
  REQUIRE(summary.find("\"van_genuchten_cc\"") != std::string::npos);
  REQUIRE(summary.find("frostmpm-sfcc") != std::string::npos);
  REQUIRE(!fs::exists(dir.file("out/freezing_curves.csv.partial")));
}

TEST_CASE("swapping the SFCC model in YAML changes the output with nothing rebuilt", "[cli]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  REQUIRE(run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("a")).exit_code == 0);
  const auto r = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("b") +
                              " --set 'material.sfcc={model: exponential, width: 0.5, residual_saturation: 0.05}'");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto a = read_csv(dir.file("a/freezing_curves.csv")).rows;
  const auto b = read_csv(dir.file("b/freezing_curves.csv")).rows;
  REQUIRE(a.size() == b.size());
  // Row 4 is T = -1 degC: van Genuchten-CC gives 0.0887, the Gaussian 0.05 + 0.95 e^-4.
  REQUIRE(a[4][0] == Approx(-1.0));
  REQUIRE(a[4][1] == Approx(0.0886697).epsilon(1e-5));
  REQUIRE(b[4][1] == Approx(0.05 + 0.95 * std::exp(-4.0)).epsilon(1e-9));
}

TEST_CASE("check with --set overrides a scalar and prints the resolved scene with defaults", "[cli]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  const auto r = run_frostmpm("check " + dir.file("scene.yaml") + " --set material.sfcc.lambda=0.25");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.output.find("lambda: 0.25") != std::string::npos);
  REQUIRE(r.output.find("ice_density: 917") != std::string::npos);  // a default, filled in
  REQUIRE(r.output.find("pore_pressure: 0") != std::string::npos);
}

TEST_CASE("plugins lists the built-in models with their libraries, describe shows schemas", "[cli]") {
  const auto r = run_frostmpm("plugins");
  REQUIRE(r.exit_code == 0);
  for (const char* name : {"van_genuchten_cc", "exponential", "power_law", "linear", "van_genuchten_mualem",
                           "impedance", "kozeny_carman"})
    CHECK(r.output.find(name) != std::string::npos);
  REQUIRE(r.output.find("libfrostmpm_sfcc.so") != std::string::npos);
  REQUIRE(r.output.find("libfrostmpm_permeability.so") != std::string::npos);

  const auto d = run_frostmpm("describe sfcc/exponential");
  REQUIRE(d.exit_code == 0);
  REQUIRE(d.output.find("residual_saturation") != std::string::npos);
  REQUIRE(d.output.find("degC") != std::string::npos);
  for (const char* sub : {"run", "check", "plugins", "describe"}) {
    const auto h = run_frostmpm(std::string(sub) + " --help");
    INFO(sub);
    REQUIRE(h.exit_code == 0);
    REQUIRE(h.output.find("Usage") != std::string::npos);
  }
}

TEST_CASE("bad input: malformed YAML names file, line and column", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, "task: freezing_curves\nmaterial: {porosity: 0.3\n  sfcc: [\n");
  REQUIRE(r.output.find("scene.yaml:") != std::string::npos);
  REQUIRE(r.output.find("malformed YAML") != std::string::npos);
}

TEST_CASE("bad input: unknown key suggests the closest valid one, with path and line", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, replace(kGoodScene, "    lambda: 0.5", "    lamda: 0.5"));
  REQUIRE(r.output.find("scene.yaml:6:") != std::string::npos);
  REQUIRE(r.output.find("material.sfcc.lamda") != std::string::npos);
  REQUIRE(r.output.find("did you mean 'lambda'") != std::string::npos);
}

TEST_CASE("bad input: missing required parameter", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, replace(kGoodScene, "    p0: 1.0e5\n", ""));
  REQUIRE(r.output.find("missing required parameter 'p0'") != std::string::npos);
  REQUIRE(r.output.find("material.sfcc") != std::string::npos);
}

TEST_CASE("bad input: wrong type", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, replace(kGoodScene, "lambda: 0.5", "lambda: abc"));
  REQUIRE(r.output.find("expected a number, got 'abc'") != std::string::npos);
  REQUIRE(r.output.find("scene.yaml:6:") != std::string::npos);
}

TEST_CASE("bad input: values out of range name the allowed range", "[cli][bad-input]") {
  TempDir dir;
  auto r = run_bad(dir, replace(kGoodScene, "porosity: 0.3", "porosity: 1.5"));
  REQUIRE(r.output.find("material.porosity") != std::string::npos);
  REQUIRE(r.output.find("out of range; allowed (0, 1)") != std::string::npos);
  r = run_bad(dir, replace(kGoodScene, "k0: 1.0e-7", "k0: -1.0e-7"));
  REQUIRE(r.output.find("material.absolute_permeability.k0") != std::string::npos);
  REQUIRE(r.output.find("allowed (0, 10] m/s") != std::string::npos);
}

TEST_CASE("bad input: unknown model name lists the registered ones", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, replace(kGoodScene, "model: van_genuchten_cc", "model: van_genuchten"));
  REQUIRE(r.output.find("unknown sfcc model 'van_genuchten'") != std::string::npos);
  REQUIRE(r.output.find("exponential, linear, power_law, table, van_genuchten_cc") != std::string::npos);
}

TEST_CASE("bad input: a library that is not a FrostMPM plugin is refused by name", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, "plugin_paths: [" + fixture("libfixture_not_a_plugin.so") + "]\n" + kGoodScene);
  REQUIRE(r.output.find("libfixture_not_a_plugin.so") != std::string::npos);
  REQUIRE(r.output.find("not a FrostMPM plugin") != std::string::npos);
}

TEST_CASE("bad input: a plugin with the wrong ABI tag is refused naming both tags", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_bad(dir, "plugin_paths: [" + fixture("libfixture_wrong_abi.so") + "]\n" + kGoodScene);
  REQUIRE(r.output.find("libfixture_wrong_abi.so") != std::string::npos);
  REQUIRE(r.output.find("frostmpm-abi-0") != std::string::npos);
  REQUIRE(r.output.find(frostmpm::kKernelAbiTag) != std::string::npos);
}

TEST_CASE("refused libraries found in a plugin folder are warnings, the rest still load", "[cli][plugins]") {
  // The fixture folder holds every refusable library (not a plugin, wrong or stale ABI tag,
  // an unresolved symbol, a bad default); a scene needing only good plugins still runs.
  TempDir dir;
  write_file(dir.file("scene.yaml"), "plugin_paths: [" + binary_dir() + "/test-fixtures]\n" + kGoodScene);
  const auto r = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.output.find("warning: ") != std::string::npos);
  REQUIRE(r.output.find("not a FrostMPM plugin") != std::string::npos);
  REQUIRE(r.output.find("libfixture_unresolved_symbol.so: refused: unresolved symbol") != std::string::npos);
  REQUIRE(r.output.find("libfixture_stale_abi.so: refused: built for kernel ABI") != std::string::npos);
  REQUIRE(fs::exists(dir.file("out/freezing_curves.csv")));
}

TEST_CASE("bad input: scene file that does not exist", "[cli][bad-input]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + dir.file("nope.yaml") + " -o " + dir.file("out"));
  REQUIRE(r.exit_code == 2);
  REQUIRE(r.output.find("nope.yaml: scene file does not exist") != std::string::npos);
  REQUIRE(!fs::exists(dir.file("out")));
}

TEST_CASE("bad input: output folder that cannot be written", "[cli][bad-input]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  write_file(dir.file("blocker"), "a file where a folder should go");
  const auto r = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("blocker/out"));
  REQUIRE(r.exit_code == 2);
  REQUIRE(r.output.find("output folder") != std::string::npos);
  REQUIRE(r.output.find("blocker/out") != std::string::npos);
  REQUIRE(read_file(dir.file("blocker")) == "a file where a folder should go");
}

TEST_CASE("bad input: --set path that does not exist", "[cli][bad-input]") {
  TempDir dir;
  auto r = run_bad(dir, kGoodScene, "--set material.sfccc.lambda=0.4");
  REQUIRE(r.output.find("path does not exist") != std::string::npos);
  REQUIRE(r.output.find("did you mean 'sfcc'") != std::string::npos);
  r = run_bad(dir, kGoodScene, "--set material.sfcc.lamda=0.4");  // new leaf: caught by the schema
  REQUIRE(r.output.find("unknown key 'lamda'") != std::string::npos);
}

TEST_CASE("a failed run leaves an earlier complete output untouched", "[cli][bad-input]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  REQUIRE(run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("out")).exit_code == 0);
  const std::string before = read_file(dir.file("out/freezing_curves.csv"));
  const auto r = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("out") + " --set material.porosity=2");
  REQUIRE(r.exit_code == 2);
  REQUIRE(read_file(dir.file("out/freezing_curves.csv")) == before);
}

TEST_CASE("bad input found inside plugin code exits 2 with the YAML location", "[cli][bad-input]") {
  // The linear SFCC checks mushy_end < freezing_point in its constructor (plugin code).
  TempDir dir;
  const auto r = run_bad(dir, replace(kGoodScene, "    model: van_genuchten_cc\n    lambda: 0.5\n    p0: 1.0e5\n",
                                      "    model: linear\n    mushy_end: 1.0\n    residual_saturation: 0.1\n"));
  REQUIRE(r.output.find("material.sfcc.mushy_end") != std::string::npos);
  REQUIRE(r.output.find("mushy_end must be below freezing_point") != std::string::npos);
}

TEST_CASE("a numerical blow-up stops with where and when, exit 3, earlier output readable", "[cli][blow-up]") {
  TempDir dir;
  // A boundary value that is NaN from t = 7300 s to 7900 s only: between the times at which
  // setup evaluates it (every 900 s here), so only the run meets it (at the step to 7800 s).
  const std::string scene = read_file(source_dir() + "/configs/tutorials/frozen_inclusion.yaml");
  write_file(dir.file("scene.yaml"), scene);
  const auto r = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("out") +
                              " --set time.end=14400 --set output.every=3600"
                              " --set 'boundary_conditions.0.value={expression: \"if(t > 7300 && t < 7900, log(-1), 5)\"}'");
  INFO(r.output);
  REQUIRE(r.exit_code == 3);
  REQUIRE(r.output.find("numerical blow-up: temperature") != std::string::npos);
  REQUIRE(r.output.find("step ") != std::string::npos);
  REQUIRE(r.output.find("at t = ") != std::string::npos);
  REQUIRE(r.output.find("(x = ") != std::string::npos);
  // Frames at t = 0 and 3600 s were written before the blow-up and still read.
  const auto py = run_command("/usr/bin/python3 " + source_dir() + "/scripts/read_fields.py " + dir.file("out"));
  INFO(py.output);
  REQUIRE(py.exit_code == 0);
  REQUIRE(py.output.find("3600") != std::string::npos);
}

TEST_CASE("overrides work before or after the scene, and a bad value names its --set", "[cli][bad-input]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  const auto before = run_frostmpm("run --set freezing_curves.samples=5 " + dir.file("scene.yaml") + " -o " + dir.file("a") +
                                   " --set material.porosity=0.25");
  INFO(before.output);
  REQUIRE(before.exit_code == 0);
  REQUIRE(read_csv(dir.file("a/freezing_curves.csv")).rows.size() == 5);

  const auto bad = run_bad(dir, kGoodScene, "--set freezing_curves.samples=abc");
  REQUIRE(bad.output.rfind("error: --set freezing_curves.samples=abc: at 'freezing_curves.samples': ", 0) == 0);
  REQUIRE(bad.output.find("scene.yaml:") == std::string::npos);
  // Inside a section given with --set, the error still names that override.
  const auto deep = run_bad(dir, kGoodScene, "--set 'material.sfcc={model: exponential, width: -1, residual_saturation: 0}'");
  REQUIRE(deep.output.find("error: --set material.sfcc={model: exponential, width: -1, residual_saturation: 0}: "
                           "at 'material.sfcc.width'") == 0);
  // Keys from the scene file keep their file and line.
  const auto file_error = run_bad(dir, replace(kGoodScene, "porosity: 0.3", "porosity: 3"), "--set freezing_curves.samples=5");
  REQUIRE(file_error.output.find("scene.yaml:3:") != std::string::npos);
  REQUIRE(run_bad(dir, kGoodScene, "--set 'material.sfcc={model: '").output.find("not valid YAML") != std::string::npos);
}

TEST_CASE("run.json writes counts as JSON integers", "[cli]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  REQUIRE(run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("out")).exit_code == 0);
  const std::string summary = read_file(dir.file("out/run.json"));
  REQUIRE(summary.find("\"samples\": 7,") != std::string::npos);
  REQUIRE(summary.find("\"porosity\": 0.3") != std::string::npos);
}

TEST_CASE("run with --quiet keeps warnings and errors only, with --verbose adds debug lines", "[cli]") {
  TempDir dir;
  const std::string scene = source_dir() + "/configs/tutorials/frozen_inclusion.yaml --set time.end=1200";
  const auto normal = run_frostmpm("run " + scene + " -o " + dir.file("a"));
  REQUIRE(normal.exit_code == 0);
  REQUIRE(normal.output.find("frostmpm: task 'simulation' finished; results in " + dir.file("a")) != std::string::npos);
  REQUIRE(normal.output.find("plugin frostmpm-thermal") == std::string::npos);
  // An explicit step above the stability limit warns, and the warning stays under --quiet.
  const auto quiet = run_frostmpm("run " + scene + " -o " + dir.file("b") +
                                  " --quiet --set physics.thermal.scheme=explicit --set time.dt=1e6");
  INFO(quiet.output);
  REQUIRE(quiet.exit_code == 0);
  REQUIRE(quiet.output.find("finished") == std::string::npos);
  REQUIRE(quiet.output.rfind("warning: time.dt = 1e+06 s exceeds the stability limit", 0) == 0);
  const auto verbose = run_frostmpm("run -v " + scene + " -o " + dir.file("c"));
  REQUIRE(verbose.exit_code == 0);
  REQUIRE(verbose.output.find("plugin frostmpm-thermal") != std::string::npos);
  REQUIRE(verbose.output.find("finished") != std::string::npos);
  REQUIRE(run_frostmpm("run -q -v " + scene + " -o " + dir.file("d")).exit_code != 0);  // one or the other
}

TEST_CASE("describe aligns its columns and prints defaults in their shortest form", "[cli]") {
  const auto d = run_frostmpm("describe relative_permeability/van_genuchten_mualem");
  INFO(d.output);
  REQUIRE(d.exit_code == 0);
  REQUIRE(d.output.find("  floor  real  -  1e-12     (0, 1)  smallest k_r") != std::string::npos);
  REQUIRE(d.output.find("9.99999") == std::string::npos);
}

TEST_CASE("more than one MPI rank is refused with one line, and --version and run.json say one rank", "[cli][bad-input]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  // As Open MPI's and MPICH's launchers announce a 3-rank world to each process.
  for (const std::string variable : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const std::string out = dir.file("out_" + variable);
    const auto r = run_command(variable + "=3 " + frostmpm_exe() + " run " + dir.file("scene.yaml") + " -o " + out);
    INFO(r.output);
    REQUIRE(r.exit_code == 2);
    REQUIRE(r.output.rfind("error: frostmpm runs on one MPI rank (this launch has 3", 0) == 0);
    REQUIRE(r.output.find("--threads") != std::string::npos);
    REQUIRE(std::count(r.output.begin(), r.output.end(), '\n') == 1);
    REQUIRE(!fs::exists(out));
  }
  if (fs::exists("/usr/bin/mpirun")) {  // the real launcher: every rank refuses, nothing is written
    const std::string out = dir.file("out_mpirun");
    const auto r = run_command("/usr/bin/mpirun --allow-run-as-root --oversubscribe -np 2 " + frostmpm_exe() + " run " +
                               dir.file("scene.yaml") + " -o " + out);
    INFO(r.output);
    REQUIRE(r.exit_code == 2);
    REQUIRE(r.output.find("error: frostmpm runs on one MPI rank (this launch has 2") != std::string::npos);
    REQUIRE(!fs::exists(out));
  }
  const auto version = run_frostmpm("--version");
  REQUIRE(version.exit_code == 0);
  REQUIRE_THAT(version.output, Catch::Contains("MPI") && Catch::Contains("runs on one rank"));
  const auto ok = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + dir.file("one"));
  REQUIRE(ok.exit_code == 0);
  REQUIRE(run_json(dir.file("one"), "['mpi']['ranks']") == "1");
}

TEST_CASE("bad input: nested YAML aliases that expand exponentially are refused at once, naming the file",
          "[cli][bad-input]") {
  // 600 bytes that expand to 10^10 nodes ("billion laughs"): each level repeats the one below ten times.
  std::string bomb = "task: freezing_curves\na0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int level = 1; level < 10; ++level) {
    bomb += "a" + std::to_string(level) + ": &a" + std::to_string(level) + " [";
    for (int k = 0; k < 10; ++k) bomb += (k ? ", *a" : "*a") + std::to_string(level - 1);
    bomb += "]\n";
  }
  bomb += "material: *a9\n";
  TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_bad(dir, bomb);
  REQUIRE(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
  REQUIRE_THAT(r.output, Catch::Contains("scene.yaml:") && Catch::Contains("aliases (*name) expand it to more than"));
  // Aliases as a user writes them (a value given once, used twice) still work.
  const std::string reused = replace(replace(kGoodScene, "    lambda: 0.5", "    lambda: &half 0.5"), "m: 0.5}", "m: *half}");
  write_file(dir.file("reused.yaml"), reused);
  const auto ok = run_frostmpm("check " + dir.file("reused.yaml"));
  INFO(ok.output);
  REQUIRE(ok.exit_code == 0);
  REQUIRE(ok.output.find("m: 0.5") != std::string::npos);
}

TEST_CASE("run into a folder that holds an earlier run's results is refused without --overwrite", "[cli][bad-input]") {
  TempDir dir;
  write_file(dir.file("scene.yaml"), kGoodScene);
  const std::string out = dir.file("out");
  REQUIRE(run_frostmpm("run " + dir.file("scene.yaml") + " -o " + out).exit_code == 0);
  const std::string first = read_file(out + "/run.json");
  const auto again = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + out);
  INFO(again.output);
  REQUIRE(again.exit_code == 2);
  REQUIRE(again.output.rfind("error: " + out + ": holds the results of an earlier run (run.json", 0) == 0);
  REQUIRE(again.output.find("--overwrite") != std::string::npos);
  REQUIRE(std::count(again.output.begin(), again.output.end(), '\n') == 1);
  REQUIRE(read_file(out + "/run.json") == first);  // untouched
  // A folder with a checkpoint also says how to continue it.
  write_file(out + "/checkpoint.h5", "");
  const auto stopped = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + out);
  REQUIRE(stopped.exit_code == 2);
  REQUIRE(stopped.output.find("checkpoint.h5); give another -o, add --overwrite to replace them, or continue that run "
                              "with: ") != std::string::npos);
  // --overwrite replaces the results and drops the old checkpoint.
  const auto replaced = run_frostmpm("run " + dir.file("scene.yaml") + " -o " + out + " --overwrite");
  INFO(replaced.output);
  REQUIRE(replaced.exit_code == 0);
  REQUIRE(!fs::exists(out + "/checkpoint.h5"));
  REQUIRE(run_frostmpm("run --restart " + out + " --overwrite").exit_code == 2);
}

TEST_CASE("a model parameter named like a material constant takes the material's value", "[cli]") {
  // The rock-freezing scene's freezing curve names neither ice_density nor latent_heat: it reads
  // the material's, so changing the material changes the curve (one source for a constant).
  const std::string scene = source_dir() + "/configs/paper/rock_freezing.yaml";
  const auto r = run_frostmpm("check " + scene + " --set materials.rock.ice_density=920 --set materials.rock.latent_heat=3.3e5");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto sfcc = r.output.find("model: van_genuchten_cc");
  REQUIRE(sfcc != std::string::npos);
  const std::string section = r.output.substr(sfcc, r.output.find("absolute_permeability", sfcc) - sfcc);
  CHECK(section.find("ice_density: 920") != std::string::npos);
  CHECK(section.find("latent_heat: 330000") != std::string::npos);
}

TEST_CASE("describe: a mistyped kind gets a suggestion, a kernel section says where its keys are", "[cli][bad-input]") {
  auto r = run_frostmpm("describe sfc/x");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("unknown kind 'sfc'; did you mean 'sfcc'?") != std::string::npos);
  CHECK(r.output.find("plugin path") == std::string::npos);  // not blamed on the plugin folders
  r = run_frostmpm("describe regions");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("'regions' is a scene section whose keys depend on the physics") != std::string::npos);
  CHECK(r.output.find("docs/config-reference.md") != std::string::npos);
  CHECK(r.output.find("Described here: grid, time, output, checkpoint") != std::string::npos);
  r = run_frostmpm("describe boundary_conditions/tempreature");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("unknown boundary_conditions type 'tempreature'; did you mean 'temperature'?") != std::string::npos);
}

TEST_CASE("describe boundary_conditions: every physics' condition types with their keys, units and ranges", "[cli]") {
  auto r = run_frostmpm("describe boundary_conditions/temperature");
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("boundary_conditions/temperature — a prescribed temperature") != std::string::npos);
  CHECK(r.output.find("from frostmpm-thermal") != std::string::npos);
  CHECK(r.output.find("YAML: boundary_conditions: [{type: temperature,") != std::string::npos);
  CHECK(r.output.find("value  real  degC  required  [-10000, 10000]") != std::string::npos);
  r = run_frostmpm("describe boundary_conditions");
  INFO(r.output);
  CHECK(r.exit_code == 0);
  // One entry per type of every shipped physics, each naming its plugin.
  for (const char* type : {"temperature", "heat_flux", "convective", "pore_pressure", "water_flux", "fixed", "roller",
                           "velocity", "traction", "surcharge", "rigid_plate", "footing", "friction"})
    CHECK(r.output.find(std::string("boundary_conditions/") + type + " — ") != std::string::npos);
  CHECK(r.output.find("friction_angle  real  degree  required  [0, 90)") != std::string::npos);
  // A type of a physics the scene does not enable says which physics it belongs to.
  r = run_frostmpm("check " + source_dir() + "/configs/verification/conduction_erf.yaml" +
                   " --set 'boundary_conditions.0={type: pore_pressure, nodes: {face: y_max}, value: 0}'");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("boundary condition type 'pore_pressure' belongs to the physics 'hydraulic', which this scene "
                      "does not enable") != std::string::npos);
}

TEST_CASE("describe grid, time, output and checkpoint: the kernel's sections with units, defaults and ranges",
          "[cli]") {
  auto r = run_frostmpm("describe grid");
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("grid — a scene section the kernel reads") != std::string::npos);
  CHECK(r.output.find("cell_size") != std::string::npos);
  CHECK(r.output.find("particles_per_cell") != std::string::npos);
  r = run_frostmpm("describe time");
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("mass_scaling") != std::string::npos);
  for (const char* section : {"output", "checkpoint"}) CHECK(run_frostmpm(std::string("describe ") + section).exit_code == 0);
}

TEST_CASE("check reports how many of each condition's nodes carry material", "[cli]") {
  const auto r = run_frostmpm("check " + source_dir() + "/configs/verification/neumann_freezing.yaml");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK(r.output.find("# temperature condition 'boundary_conditions.0' on face y_max: 2 of 2 nodes carry material") !=
        std::string::npos);
  // A condition that reaches no material is refused: the corpus has those cases.
}
