// The coupled step: phases owned by the kernel, stages ordered from their declared reads and
// writes, nodal fields shared through the registry, `frostmpm check` printing the step, and a
// third-party physics (tests/plugins/grid_sampler, outside plugins/) coupling to the thermal
// physics through the registry alone.
#include <catch2/catch.hpp>

#include <cmath>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

const std::string kScene = "configs/tutorials/frozen_inclusion.yaml";

std::string sampler_path() { return "--plugin-path " + binary_dir() + "/test-plugins"; }

/// The default scene with the grid sampler listed before the thermal physics, so that any
/// order the step has comes from the declarations, not from the scene.
std::string scene_with_sampler_first(const TempDir& dir, const std::string& sampler) {
  std::string text = read_file(source_dir() + "/" + kScene);
  const auto at = text.find("physics:\n");
  REQUIRE(at != std::string::npos);
  text.insert(at + 9, "  grid_sampler: " + sampler + "\n");
  const std::string path = dir.file("scene.yaml");
  write_file(path, text);
  return path;
}

std::size_t line_of(const std::string& text, const std::string& what) {
  const auto at = text.find(what);
  INFO("looking for: " << what);
  REQUIRE(at != std::string::npos);
  return at;
}

}  // namespace

TEST_CASE("check prints the resolved step of a thermal scene: phases, stages, reads, writes, skipped phases",
          "[step]") {
  const auto r = run_frostmpm("check " + source_dir() + "/" + kScene);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const std::size_t grid = line_of(r.output, "#   1. map_to_grid\n#     thermal.map_to_grid\n");
  const std::size_t solve = line_of(r.output, "#   2. energy\n#     thermal.solve\n");
  const std::size_t back = line_of(r.output, "#   6. map_to_particles\n#     thermal.map_to_particles\n");
  CHECK(grid < solve);
  CHECK(solve < back);
  for (const char* skipped : {"3. predict_momentum", "4. pressure", "5. correct_momentum", "7. update_materials"})
    CHECK(r.output.find(std::string(skipped) + ": skipped (no stage)") != std::string::npos);
  CHECK(r.output.find("writes particle: temperature, heat_deviation, temperature_pic, liquid_saturation") !=
        std::string::npos);
  // A thermal scene allocates one shared nodal field, and no velocity or pressure.
  CHECK(r.output.find("# nodal fields allocated: temperature\n") != std::string::npos);
}

TEST_CASE("a third-party physics reads the thermal nodal temperature through the registry alone", "[step]") {
  TempDir dir;
  const std::string common = " --set time.end=36000 --set output.progress=false --set output.every=0";
  // Without the sampler, then with it in the phase where the thermal physics maps back: the
  // sampled value Σ S_ip T_i is the thermal physics' own PIC temperature.
  const auto plain = run_frostmpm("run " + source_dir() + "/" + kScene + " -o " + dir.file("plain") + common);
  REQUIRE(plain.exit_code == 0);
  const std::string probes =
      " --set 'probes=[{name: T_min, type: min, field: temperature}, {name: pic_min, type: min, field: "
      "temperature_pic}, {name: sampled_min, type: min, field: temperature_sampled}, {name: pic_max, type: max, field: "
      "temperature_pic}, {name: sampled_max, type: max, field: temperature_sampled}, {name: pic_heat, type: integral, "
      "fields: [temperature_pic]}, {name: sampled_heat, type: integral, fields: [temperature_sampled]}]'";
  const auto coupled = run_frostmpm("run " + source_dir() + "/" + kScene + " -o " + dir.file("coupled") + " " +
                                    sampler_path() + " --set 'physics.grid_sampler={phase: map_to_particles}'" +
                                    common + probes);
  INFO(coupled.output);
  REQUIRE(coupled.exit_code == 0);
  const auto table = read_csv(dir.file("coupled/metrics.csv"));
  REQUIRE(table.rows.size() > 10);
  for (const auto& row : table.rows) {
    if (row[table.column("time_s")] == 0) continue;  // before the first step nothing was sampled
    for (const std::string q : {"min", "max", "heat"}) {
      const double pic = row[table.column("pic_" + q)], sampled = row[table.column("sampled_" + q)];
      INFO(q << " at t = " << row[table.column("time_s")]);
      CHECK(std::abs(sampled - pic) <= 1e-12 * std::max(1.0, std::abs(pic)));
    }
  }
  // A physics that only reads changes nothing: the thermal results are the same bits.
  const auto T_plain = read_csv(dir.file("plain/metrics.csv"));
  REQUIRE(T_plain.rows.size() == table.rows.size());
  for (std::size_t i = 0; i < table.rows.size(); ++i)
    CHECK(T_plain.rows[i][T_plain.column("T_min")] == table.rows[i][table.column("T_min")]);
  CHECK(read_file(dir.file("plain/fields.h5")).size() > 0);
}

TEST_CASE("the kernel runs a reader after the writer of its field, whatever the order of physics in the scene",
          "[step]") {
  TempDir dir;
  // Listed first, in the phase where the thermal physics writes the nodal temperature: the
  // sampler must still run after thermal.map_to_grid; in the energy phase after thermal.solve.
  for (const std::string phase : {"map_to_grid", "energy"}) {
    const auto r = run_frostmpm("check " + scene_with_sampler_first(dir, "{phase: " + phase + "}") + " " +
                                sampler_path());
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const std::size_t writer = line_of(r.output, phase == "energy" ? "thermal.solve" : "thermal.map_to_grid");
    CHECK(writer < line_of(r.output, "grid_sampler.sample"));
  }
}

TEST_CASE("a stage that reads a field nothing writes is refused at setup, naming the stage and the field", "[step]") {
  TempDir dir;
  const auto r = run_frostmpm("check " + scene_with_sampler_first(dir, "{field: liquid_velocity}") + " " +
                              sampler_path());
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("error: " + dir.file("scene.yaml") + ":") != std::string::npos);
  CHECK(r.output.find("at 'physics.grid_sampler': stage 'grid_sampler.sample' (phase update_materials) reads node "
                      "field 'liquid_velocity', which no earlier stage writes; no stage of this scene's physics "
                      "(grid_sampler, thermal) writes it") != std::string::npos);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
}
