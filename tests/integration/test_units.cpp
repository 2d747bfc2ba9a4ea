// Quantities with units through the whole program: a scene written with units runs as the same
// scene in SI numbers to the last bit and resolves to the same values; `--set` takes units; a run
// ends with its summary paragraph.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <yaml-cpp/yaml.h>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

const std::string kSi = "configs/tutorials/frozen_inclusion.yaml";
const std::string kUnits = "configs/tutorials/frozen_inclusion_units.yaml";

/// The resolved scene `frostmpm check` prints, parsed (its first line names the scene file).
YAML::Node resolved(const std::string& scene, const std::string& overrides = "") {
  const auto r = run_frostmpm("check " + source_dir() + "/" + scene + overrides);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return YAML::Load(r.output.substr(r.output.find('\n') + 1));
}

/// Equal trees, numbers compared as numbers (5.0 and 5 agree), at `path` for the message.
void require_same(const YAML::Node& a, const YAML::Node& b, const std::string& path) {
  INFO("at " << path);
  REQUIRE(a.Type() == b.Type());
  if (a.IsMap()) {
    REQUIRE(a.size() == b.size());
    for (const auto& kv : a) {
      const std::string key = kv.first.as<std::string>();
      REQUIRE(b[key].IsDefined());
      require_same(kv.second, b[key], path + "." + key);
    }
  } else if (a.IsSequence()) {
    REQUIRE(a.size() == b.size());
    for (std::size_t i = 0; i < a.size(); ++i) require_same(a[i], b[i], path + "." + std::to_string(i));
  } else if (a.IsScalar()) {
    double x = 0, y = 0;
    if (YAML::convert<double>::decode(a, x) && YAML::convert<double>::decode(b, y)) CHECK(x == y);
    else CHECK(a.Scalar() == b.Scalar());
  }
}

}  // namespace

TEST_CASE("a scene written with units runs bit for bit as the same scene in SI numbers", "[units][cli]") {
  TempDir dir;
  const auto si = run_frostmpm("run " + source_dir() + "/" + kSi + " -o " + dir.file("si") + " --set time.end=7200");
  INFO(si.output);
  REQUIRE(si.exit_code == 0);
  const auto with_units =
      run_frostmpm("run " + source_dir() + "/" + kUnits + " -o " + dir.file("units") + " --set 'time.end=2 h'");
  INFO(with_units.output);
  REQUIRE(with_units.exit_code == 0);
  const std::string metrics = read_file(dir.file("si/metrics.csv"));
  REQUIRE(std::count(metrics.begin(), metrics.end(), '\n') == 6);  // t = 0 and every 30 min
  CHECK(read_file(dir.file("units/metrics.csv")) == metrics);
}

TEST_CASE("the resolved scene of a scene with units holds the SI numbers", "[units][cli]") {
  // Every place a number is read: kernel sections, materials and their models, regions and
  // their initial values, boundary conditions, probes.
  const YAML::Node si = resolved(kSi);
  const YAML::Node units = resolved(kUnits);
  require_same(si, units, "");
  CHECK(units["time"]["end"].as<double>() == 180000.0);
  CHECK(units["boundary_conditions"][0]["value"].as<double>() == 5.0);
  CHECK(units["regions"][1]["initial"]["temperature"].as<double>() == -5.0);
}

TEST_CASE("a --set value may carry a unit, and check prints the SI number", "[units][cli]") {
  const YAML::Node scene = resolved(kSi, " --set 'time.end=90 d' --set 'probes.3.point=[50 cm, 0.5]'");
  CHECK(scene["time"]["end"].as<double>() == 7776000.0);
  CHECK(scene["probes"][3]["point"][0].as<double>() == 0.5);
  const auto bad = run_frostmpm("check " + source_dir() + "/" + kSi + " --set 'time.end=20 kPa'");
  CHECK(bad.exit_code == 2);
  CHECK(bad.output == "error: --set time.end=20 kPa: at 'time.end': '20 kPa' is not a time: its unit kPa is not "
                      "convertible to s\n");
}

TEST_CASE("a run ends with one paragraph: outputs, steps, times and the heat balance", "[units][cli]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + source_dir() + "/" + kSi + " -o " + dir.file("out") + " --set time.end=1200");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.output, Catch::Contains("frostmpm: task 'simulation' finished; results in " + dir.file("out") +
                                       ": checkpoint.h5, fields.h5, fields.xdmf (open it in ParaView), metrics.csv, "
                                       "run.json. 2 steps to t = 20 min (dt 10 min to 10 min) in "));
  CHECK_THAT(r.output, Catch::Contains("; the heat balance closes to "));
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);  // one paragraph, one line
}

TEST_CASE("a task without steps ends with the paragraph too", "[units][cli]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + source_dir() + "/configs/tutorials/freezing_curves.yaml -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.output, Catch::Contains("frostmpm: task 'freezing_curves' finished; results in " + dir.file("out") +
                                       ": freezing_curves.csv, run.json. It ran in "));
}
