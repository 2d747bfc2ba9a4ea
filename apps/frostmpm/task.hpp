#pragma once
// What `frostmpm run` executes: a task named by the scene's `task:` key. A task reads and
// validates all of its input in its constructor (so `check` runs the same code), and only
// execute() writes to the output folder.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/io/checkpoint.hpp"
#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/plugin/plugin_loader.hpp"

namespace frostmpm::app {

struct TaskContext {
  const Registry& registry;
  const PluginLoader& loader;
  const ConfigNode& root;  ///< scene root; a task consumes the sections it owns
};

/// How `frostmpm run` starts a task.
struct RunRequest {
  SceneSource scene;     ///< what a checkpoint must keep to re-create the scene
  bool restart = false;  ///< continue from OUT/checkpoint.h5
};

class Task {
 public:
  virtual ~Task() = default;
  /// Top-level keys this task owns (besides `task` and `plugin_paths`).
  virtual std::vector<std::string> sections() const = 0;
  /// The scene as it will run: every section with defaults filled in.
  virtual YAML::Node resolved() const = 0;
  virtual void execute(const OutputDir& out, const RunRequest& request) = 0;
  /// What one step runs (phases, stages, fields), for `frostmpm check`; empty when the task
  /// has no steps.
  virtual std::string step_description() const { return {}; }
  /// Task-specific facts for run.json (steps, timings, counters).
  virtual YAML::Node summary() const { return {}; }
  /// (column, unit) of every column of the metrics.csv the task writes (none: it writes none),
  /// for run.json's metrics_units.
  virtual std::vector<std::pair<std::string, std::string>> metrics_units() const { return {}; }
};

using TaskFactory = std::function<std::unique_ptr<Task>(const TaskContext&)>;
/// Registered tasks by name.
const std::map<std::string, TaskFactory>& tasks();

std::unique_ptr<Task> make_freezing_curves_task(const TaskContext& context);
std::unique_ptr<Task> make_simulation_task(const TaskContext& context);

}  // namespace frostmpm::app
