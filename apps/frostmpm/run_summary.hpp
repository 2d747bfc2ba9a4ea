#pragma once
// The paragraph `frostmpm run` ends with, read from what run.json holds.
#include <string>

#include <nlohmann/json.hpp>

namespace frostmpm::app {

/// "frostmpm: task 'simulation' finished; results in DIR: checkpoint.h5, fields.h5, ... N steps
/// took it to t = 50 h ... in 2.3 s of wall time ...; the heat balance closes to ...": the task,
/// where its outputs are (those in `dir`), the steps, simulated and wall time, and the energy
/// balance when the thermal physics ran. `summary` is run.json's content.
std::string run_summary(const nlohmann::json& summary, const std::string& dir);

}  // namespace frostmpm::app
