#include "thermal_harness.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <fstream>
#include <sstream>

#include "frostmpm/config/config_node.hpp"

namespace frostmpm::test {

ColumnRun run_column(const ColumnSetup& s) {
  ConfigNode file = ConfigNode::load_file(source_dir() + "/configs/verification/" + s.scene);
  YAML::Node tree = file.raw();
  const long cells = std::lround(s.length / s.cell);
  const std::string along = std::to_string(cells), across = "1", l = std::to_string(s.length), w = std::to_string(s.cell);
  std::vector<std::string> overrides = {
      "grid.cells=[" + (s.along_x ? along + ", " + across : across + ", " + along) + "]",
      "grid.cell_size=" + std::to_string(s.cell),
      "regions.0.shape={box: {min: [0, 0], max: [" + (s.along_x ? l + ", " + w : w + ", " + l) + "]}}",
      "physics.thermal.scheme=" + s.scheme,
      "output.progress=false",
  };
  if (s.dt > 0) overrides.push_back("time.dt=" + std::to_string(s.dt));
  overrides.insert(overrides.end(), s.overrides.begin(), s.overrides.end());
  for (const auto& o : overrides) apply_override(tree, o);
  ConfigNode root(tree, s.scene);
  const Registry& registry = builtin_registry();
  root.child("task");
  Simulation sim(registry, root);
  root.finish({"task", "grid", "time", "physics", "materials", "regions", "boundary_conditions", "output", "probes"});

  TempDir dir;
  OutputDir out(dir.path());
  const auto start = std::chrono::steady_clock::now();
  sim.run(out, RunOptions{});
  ColumnRun run;
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.steps = sim.statistics().steps;
  run.mean_dt = run.steps ? sim.statistics().dt_sum / double(run.steps) : 0;
  const auto pos = sim.particles().field("position");
  const auto T = sim.particles().field("temperature");
  const auto Tp = sim.particles().field("temperature_pic");
  for (std::size_t p = 0; p < sim.particles().size(); ++p) {
    run.depth.push_back(s.along_x ? pos[p * kDim] : s.length - pos[p * kDim + 1]);
    run.temperature.push_back(T[p]);
    run.temperature_pic.push_back(Tp[p]);
  }
  for (const auto& physics : sim.physics())
    for (const auto& [key, value] : physics->statistics()) run.counters[key] = value;
  const CsvTable metrics = read_csv(dir.file("metrics.csv"));
  run.metrics_header = metrics.header;
  run.metrics = metrics.rows;
  return run;
}

double ColumnRun::last(const std::string& probe) const {
  const auto it = std::find(metrics_header.begin(), metrics_header.end(), probe);
  if (it == metrics_header.end()) throw std::out_of_range("metrics.csv has no column " + probe);
  return metrics.back()[static_cast<std::size_t>(it - metrics_header.begin())];
}

std::string describe(const ColumnSetup& s, const ColumnRun& run, const std::string& errors) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%-8s h=%.4g m dt=%.4g s steps=%ld wall=%.2f s  ", s.scheme.c_str(), s.cell,
                run.mean_dt, run.steps, run.wall_seconds);
  return buffer + errors;
}

}  // namespace frostmpm::test
