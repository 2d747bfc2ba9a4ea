#include "run_summary.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <vector>

#include "frostmpm/config/input_error.hpp"
#include "frostmpm/config/units.hpp"

namespace frostmpm::app {

namespace {

/// The files the run left in `dir`, sorted; fields.xdmf says what opens it.
std::string outputs_in(const std::string& dir) {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
    if (entry.is_regular_file(ec)) found.push_back(entry.path().filename().string());
  std::sort(found.begin(), found.end());
  for (auto& name : found)
    if (name == "fields.xdmf") name += " (open it in ParaView)";
  return found.empty() ? "" : ": " + join(found);
}

/// `parent[key]` when it is an object, else an empty one (a task without a summary has null).
nlohmann::json object_at(const nlohmann::json& parent, const char* key) {
  const auto it = parent.find(key);
  return it != parent.end() && it->is_object() ? *it : nlohmann::json::object();
}

std::string significant(double value, int digits) {
  std::ostringstream text;
  text.precision(digits);
  text << value;
  return text.str();
}

}  // namespace

std::string run_summary(const nlohmann::json& summary, const std::string& dir) {
  std::string text = "frostmpm: task '" + summary.value("task", std::string("?")) + "' finished; results in " + dir +
                     outputs_in(dir) + ".";
  const nlohmann::json run = object_at(summary, "run");
  if (run.contains("steps") && run.contains("simulated_seconds")) {
    text += " " + std::to_string(run["steps"].get<long>()) + " steps to t = " +
            units::readable_duration(run["simulated_seconds"].get<double>());
    if (const auto dt = object_at(run, "dt"); dt.contains("min") && dt.contains("max"))
      text += " (dt " + units::readable_duration(dt["min"].get<double>()) + " to " +
              units::readable_duration(dt["max"].get<double>()) + ")";
  } else {
    text += " It ran";
  }
  if (summary.contains("wall_seconds"))
    text += " in " + units::readable_duration(summary["wall_seconds"].get<double>()) + " of wall time";
  if (summary.contains("threads")) text += " on " + std::to_string(summary["threads"].get<int>()) + " thread(s)";
  const nlohmann::json counters = object_at(run, "counters");
  if (const auto it = counters.find("thermal.energy_balance_error_relative"); it != counters.end())
    text += "; the heat balance closes to " + significant(it->get<double>(), 2) +
            " of the heat stored or exchanged (thermal.energy_balance_error_relative)";
  return text + ".";
}

}  // namespace frostmpm::app
