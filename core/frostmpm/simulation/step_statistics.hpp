#pragma once
// Counters the run loop keeps for run.json; checkpoints carry them across restarts.
#include <map>
#include <string>

namespace frostmpm {

struct StepStatistics {
  long steps = 0;
  double dt_min = 0, dt_max = 0, dt_sum = 0;
  std::map<std::string, double> stage_seconds;  ///< wall time per stage name
};

}  // namespace frostmpm
