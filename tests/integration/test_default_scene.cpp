// README command (1): the default scene, INTERFROST TH2 without flow (frozen inclusion thawing
// by conduction). Checks what a user gets: the thaw time against the 13-code range, the liquid
// volume against the benchmark's PM3 values, a maximum principle, a thermal-only field set and
// stage list, and fields.xdmf + fields.h5 read back by a real reader.
#include <catch2/catch.hpp>

#include <fstream>
#include <set>
#include <sstream>

#include "test_support.hpp"

using namespace frostmpm::test;


TEST_CASE("default scene: frozen inclusion thaws within the INTERFROST range", "[default-scene]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + source_dir() + "/configs/tutorials/frozen_inclusion.yaml -o " + dir.file("out"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);

  const CsvTable metrics = read_csv(dir.file("out/metrics.csv"));
  const auto& rows = metrics.rows;
  const auto t_min = metrics.column("T_min"), t_max = metrics.column("T_max");
  const auto volume = metrics.column("liquid_volume_m3");
  // PM3 (Grenier et al. 2018): 1.0710 m³ of liquid per metre at t = 0, 1.1100 m³ thawed.
  CHECK(rows.front()[volume] == Approx(1.0710).margin(5e-4));
  CHECK(rows.back()[volume] == Approx(1.1100).margin(5e-4));
  // PM1: the time T_min rises above 0 °C. INTERFROST 0 % gradient: 32.4–41.7 h over 13 codes.
  double thaw_hours = -1;
  for (const auto& row : rows)
    if (row[t_min] > 0) {
      thaw_hours = row[0] / 3600.0;
      break;
    }
  INFO("thaw time " << thaw_hours << " h");
  CHECK(thaw_hours >= 32.4);
  CHECK(thaw_hours <= 41.7);
  // Maximum principle: no source, so T stays within [−5, 5] °C.
  for (const auto& row : rows) {
    CHECK(row[t_min] >= -5.0 - 1e-9);
    CHECK(row[t_max] <= 5.0 + 1e-9);
  }
}

TEST_CASE("maximum principle: extreme conductivity in one implicit step, and explicit without latent heat",
          "[default-scene][max-principle]") {
  // Initial values span [−5, 5] °C, the left face holds 5 °C, nothing else adds heat: no particle
  // may leave [−5, 5] °C. FLIP keeps each particle's sub-cell deviation from the grid field (the
  // inclusion's edge starts inside cells); a particle above its nodes would be pushed past 5 °C
  // as its nodes warm towards it, unless the update keeps it within its old value and its
  // nodes' new ones (the overshoot it sheds goes to the grid, energy stays exact).
  const std::string scene = source_dir() + "/configs/tutorials/frozen_inclusion.yaml";
  const std::string k = "materials.saturated_sand.";
  struct Case {
    const char* name;
    std::string overrides;
  };
  for (const Case& c : {Case{"implicit, k = 1e3 W/m/K, one 36,000 s step",
                             " --set time.dt=36000 --set time.end=36000 --set output.metrics_every=0 --set " + k +
                                 "solid_conductivity=1000 --set " + k + "water_conductivity=1000 --set " + k +
                                 "ice_conductivity=1000"},
                        Case{"explicit, no latent heat", " --set physics.thermal.scheme=explicit --set time.dt=0 --set " +
                                                             k + "latent_heat=0 --set time.end=36000"},
                        Case{"explicit, FLIP without sub-grid relaxation",
                             " --set physics.thermal.scheme=explicit --set time.dt=0 --set "
                             "physics.thermal.subgrid_relaxation=0 --set time.end=36000"}}) {
    INFO(c.name);
    TempDir dir;
    const auto r = run_frostmpm("run " + scene + " -o " + dir.file("out") + c.overrides);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const CsvTable metrics = read_csv(dir.file("out/metrics.csv"));
    for (const auto& row : metrics.rows) {
      CHECK(row[metrics.column("T_max")] <= 5.0 + 1e-9);
      CHECK(row[metrics.column("T_min")] >= -5.0 - 1e-9);
    }
  }
}

TEST_CASE("a thermal-only run allocates no hydraulic or mechanical fields and runs only thermal stages",
          "[default-scene]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + source_dir() + "/configs/tutorials/frozen_inclusion.yaml -o " +
                              dir.file("out") + " --set time.end=3600");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  // run.json read with a real JSON parser: fields allocated and stages run.
  const auto py = run_command("/usr/bin/python3 -c \"import json; r=json.load(open('" + dir.file("out/run.json") +
                              "'))['run']; print(' '.join(r['particle_fields'])); print(' '.join(r['stage_wall_seconds']))\"");
  INFO(py.output);
  REQUIRE(py.exit_code == 0);
  std::stringstream lines(py.output);
  std::string fields, stages;
  std::getline(lines, fields);
  std::getline(lines, stages);
  for (const char* absent : {"pressure", "velocity", "stress", "displacement", "strain"}) {
    INFO(absent);
    CHECK(fields.find(absent) == std::string::npos);
  }
  CHECK(fields.find("temperature") != std::string::npos);
  std::stringstream names(stages);
  std::set<std::string> ran;
  for (std::string name; names >> name;) {
    INFO(name);
    CHECK((name.rfind("thermal.", 0) == 0 || name.rfind("kernel.", 0) == 0));
    ran.insert(name);
  }
  for (const char* stage : {"thermal.map_to_grid", "thermal.solve", "thermal.map_to_particles"}) CHECK(ran.count(stage) == 1);
}

TEST_CASE("fields.xdmf and fields.h5 load in a real reader with the values written", "[default-scene][io]") {
  TempDir dir;
  const auto r = run_frostmpm("run " + source_dir() + "/configs/tutorials/frozen_inclusion.yaml -o " +
                              dir.file("out") + " --set time.end=7200");
  REQUIRE(r.exit_code == 0);
  // The reader parses the XDMF, opens every DataItem with h5py, checks shapes, and prints the
  // last frame's temperature range; it must equal the T_min/T_max the run recorded itself.
  const auto py = run_command("/usr/bin/python3 -c \"\nimport json,subprocess,sys\n"
                              "s=json.loads(subprocess.check_output([sys.executable,'" + source_dir() +
                              "/scripts/read_fields.py','" + dir.file("out") + "','--dump']))\n"
                              "import numpy as np\n"
                              "f=s['frames'][-1]\n"
                              "T=np.array(f['fields']['temperature']['values'],dtype=float).ravel()\n"
                              "print(len(s['frames']), repr(T.min()), repr(T.max()), f['time'])\n\"");
  INFO(py.output);
  REQUIRE(py.exit_code == 0);
  std::stringstream ss(py.output);
  double frames = 0, low = 0, high = 0, time = 0;
  ss >> frames >> low >> high >> time;
  CHECK(frames == 2);  // t = 0 and t = 7200 s (output every 7200 s)
  CHECK(time == 7200);
  const CsvTable metrics = read_csv(dir.file("out/metrics.csv"));
  // metrics.csv carries 12 significant digits.
  CHECK(low == Approx(metrics.rows.back()[metrics.column("T_min")]).epsilon(1e-10));
  CHECK(high == Approx(metrics.rows.back()[metrics.column("T_max")]).epsilon(1e-10));
}

TEST_CASE("results are bitwise the same on 1 and 2 threads, explicit and implicit", "[default-scene][threads]") {
  const std::string scene = source_dir() + "/configs/tutorials/frozen_inclusion.yaml";
  for (const char* scheme : {"--set physics.thermal.scheme=explicit --set time.dt=0 --set time.end=3600",
                             "--set time.end=7200"}) {
    INFO(scheme);
    TempDir one, two;
    const auto a = run_command("OMP_NUM_THREADS=1 " + frostmpm_exe() + " run " + scene + " -o " + one.file("out") + " " +
                               scheme + " 2>&1");
    const auto b = run_command("OMP_NUM_THREADS=2 " + frostmpm_exe() + " run " + scene + " -o " + two.file("out") + " " +
                               scheme + " 2>&1");
    REQUIRE(a.exit_code == 0);
    REQUIRE(b.exit_code == 0);
    CHECK(read_file(one.file("out/metrics.csv")) == read_file(two.file("out/metrics.csv")));
    // Every field of every frame, bitwise (numpy array_equal on what h5py reads).
    const auto py = run_command("/usr/bin/python3 -c \"import sys; sys.path.insert(0, '" + source_dir() +
                                "/scripts'); import read_fields, numpy as np\n"
                                "a = read_fields.read_frames('" + one.file("out") + "')\n"
                                "b = read_fields.read_frames('" + two.file("out") + "')\n"
                                "ok = len(a) == len(b) and all(np.array_equal(fa['fields'][k], fb['fields'][k]) "
                                "for fa, fb in zip(a, b) for k in fa['fields'])\n"
                                "print('same' if ok else 'differ')\"");
    INFO(py.output);
    CHECK(py.output.find("same") != std::string::npos);
  }
}

TEST_CASE("a mechanical run's metrics and energy counters are bitwise the same on 1 and 2 threads",
          "[threads][mechanics]") {
  // The elastic block under gravity of bench/mechanical_throughput, 120 000 particles, 100 steps:
  // the kinetic and elastic energies in run.json are sums over all particles, which must not
  // depend on how the threads split them (an OpenMP reduction made them differ in the 13th digit).
  const std::string scene = source_dir() + "/configs/verification/self_weight_column.yaml";
  const std::string options = " --set 'grid.cells=[300,100]' --set grid.cell_size=0.01 --set 'regions.0.shape.box.max=[3,1]'"
                              " --set time.end=0.0193 --set output.every=0.0193 --set output.metrics_every=0.002";
  TempDir one, two;
  const auto a = run_command("OMP_NUM_THREADS=1 " + frostmpm_exe() + " run " + scene + " -o " + one.file("out") + options + " 2>&1");
  const auto b = run_command("OMP_NUM_THREADS=2 " + frostmpm_exe() + " run " + scene + " -o " + two.file("out") + options + " 2>&1");
  INFO(a.output << b.output);
  REQUIRE(a.exit_code == 0);
  REQUIRE(b.exit_code == 0);
  CHECK(read_file(one.file("out/metrics.csv")) == read_file(two.file("out/metrics.csv")));
  for (const char* counter : {"mechanical.kinetic_energy_J", "mechanical.elastic_energy_J", "mechanical.kinetic_to_work_max"}) {
    INFO(counter);
    const std::string path = std::string("['run']['counters']['") + counter + "']";
    const std::string value = run_json(one.file("out"), path);
    CHECK(value != "0.0");
    CHECK(value == run_json(two.file("out"), path));
  }
}
