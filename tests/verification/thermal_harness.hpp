#pragma once
// Runs a verification scene from configs/verification in-process at a chosen resolution and
// time scheme, and returns the particle temperatures as depth profiles.
#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "test_support.hpp"

namespace frostmpm::test {

struct ColumnRun {
  std::vector<double> depth;        ///< distance below the surface of every particle [m] (along_x: x)
  std::vector<double> temperature;  ///< FLIP (state) temperature
  std::vector<double> temperature_pic;
  std::vector<std::string> metrics_header;
  std::vector<std::vector<double>> metrics;  ///< rows of metrics.csv
  double wall_seconds = 0;
  long steps = 0;
  double mean_dt = 0;
  std::map<std::string, double> counters;  ///< the physics' run.json counters
  /// Last metrics.csv value of a probe (fails the test when the column is missing).
  double last(const std::string& probe) const;
};

struct ColumnSetup {
  std::string scene;        ///< file name under configs/verification
  double length = 1.0;      ///< column length [m] (surface at y = length)
  double cell = 0.01;       ///< cell size [m]
  std::string scheme = "explicit";
  double dt = 0;            ///< implicit step [s]
  std::vector<std::string> overrides;
  bool along_x = false;     ///< a bar along x from x = 0 (one cell tall) instead of a column
};

ColumnRun run_column(const ColumnSetup& setup);

/// One line for the test log: scheme, h, dt, steps, wall, and the named errors.
std::string describe(const ColumnSetup& setup, const ColumnRun& run, const std::string& errors);

}  // namespace frostmpm::test
