// `task: simulation` — a material point simulation: the kernel plus the scene's physics.
#include <sys/resource.h>

#include <sstream>

#include "frostmpm/io/log.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "task.hpp"

namespace frostmpm::app {
namespace {

class SimulationTask final : public Task {
 public:
  explicit SimulationTask(const TaskContext& ctx) : sim_(ctx.registry, ctx.root) {}

  std::vector<std::string> sections() const override { return Simulation::sections(); }
  YAML::Node resolved() const override { return sim_.resolved(); }
  std::string step_description() const override {
    return sim_.step_plan().describe() +
           (sim_.boundary_report().empty() ? "" : "boundary conditions at the start:\n" + sim_.boundary_report());
  }
  void execute(const OutputDir& out, const RunRequest& request) override {
    RunOptions options;
    options.progress = sim_.resolved()["output"]["progress"].as<bool>();
    options.restart = request.restart;
    options.scene = request.scene;
    sim_.run(out, options);
    // Counters named *unconverged* flag steps whose iteration hit its cap; say so, not just
    // in run.json.
    for (const auto& physics : sim_.physics())
      for (const auto& [key, value] : physics->statistics())
        if (key.find("unconverged") != std::string::npos && value > 0) {
          std::ostringstream message;
          message << key << " = " << value << " of " << sim_.statistics().steps
                  << " steps (see run.json; a smaller time.dt or a looser tolerance helps)";
          log::warning(message.str());
        }
  }

  std::vector<std::pair<std::string, std::string>> metrics_units() const override { return sim_.metrics_units(); }

  YAML::Node summary() const override {
    YAML::Node s;
    const auto& st = sim_.statistics();
    s["steps"] = st.steps;
    s["restarts"] = sim_.restarts();
    s["simulated_seconds"] = sim_.time();
    s["dt"]["min"] = st.dt_min;
    s["dt"]["max"] = st.dt_max;
    s["dt"]["mean"] = st.steps ? st.dt_sum / double(st.steps) : 0.0;
    for (const auto& [name, seconds] : st.stage_seconds) s["stage_wall_seconds"][name] = seconds;
    s["physics"] = sim_.physics_names();
    for (const auto& physics : sim_.physics())
      for (const auto& [key, value] : physics->statistics()) s["counters"][key] = value;
    for (const auto& physics : sim_.physics())
      for (const auto& [key, values] : physics->step_series()) {
        YAML::Node list(YAML::NodeType::Sequence);
        for (double v : *values) list.push_back(v);
        s["per_step"][key] = list;
      }
    s["particles"] = static_cast<long>(sim_.particles().size());
    s["removed_particles"] = sim_.removed_particles();  // grid.particles_leaving: remove
    s["grid_nodes"] = static_cast<long>(sim_.grid().node_count());
    s["particle_fields"] = sim_.particles().field_names();
    s["particle_field_bytes"] = static_cast<long>(sim_.particles().bytes());
    struct rusage usage {};
    getrusage(RUSAGE_SELF, &usage);
    s["peak_memory_mib"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
    return s;
  }

 private:
  Simulation sim_;
};

}  // namespace

std::unique_ptr<Task> make_simulation_task(const TaskContext& context) {
  return std::make_unique<SimulationTask>(context);
}

}  // namespace frostmpm::app
