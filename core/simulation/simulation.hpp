#pragma once
// The kernel's state and step loop: grid, particles (structure of arrays), stencil cache,
// materials, boundary conditions, the physics in play and their stages, output and probes.
// 2-D today; grid, shape functions and stencils are templated on the dimension.
#include <chrono>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/io/checkpoint.hpp"
#include "frostmpm/particles/particle_store.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/plugin/registry.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "frostmpm/shape/stencil_cache.hpp"
#include "frostmpm/simulation/step_statistics.hpp"
#include "frostmpm/step/node_fields.hpp"
#include "frostmpm/step/step_plan.hpp"

namespace frostmpm {

class OutputDir;
class ParticleFieldWriter;

inline constexpr int kDim = 2;

struct Material {
  std::string name;
  ParamSet params;                               ///< merged schema of every active physics
  std::map<std::string, ModelSection> models;    ///< by slot key, e.g. "sfcc"
};

/// A boundary condition as the kernel parsed it: where it acts; the physics owning `type`
/// reads its own keys from `node` (and must call node.finish()).
struct BoundaryCondition {
  std::string type;
  std::string target_text;              ///< e.g. "face y_max", for messages
  std::vector<std::size_t> nodes;       ///< node targets
  std::vector<double> node_areas;       ///< face area per node (0 for box node sets)
  std::vector<std::size_t> particles;   ///< particle targets
  bool on_particles = false;
  std::unique_ptr<ConfigNode> node;
  /// "temperature condition 'boundary_conditions.0' on face x_min": for messages, naming the key.
  std::string label() const { return type + " condition '" + node->path() + "' on " + target_text; }
};

/// Thrown when the solution stops being finite; the message says where and when.
class NumericalBlowUp : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
inline constexpr int kBlowUpExitCode = 3;

/// Thrown by Simulation::run when SIGINT or SIGTERM asked it to stop (see interrupt.hpp): the
/// step in progress was finished, and the checkpoint, the current frame and the metrics row
/// were written.
class RunInterrupted : public std::runtime_error {
 public:
  RunInterrupted(int signal, double time, long step);
  int signal;
  double time;
  long step;
};

/// How Simulation::run starts.
struct RunOptions {
  bool progress = false;  ///< a progress line on stderr every 2 s of wall time
  bool restart = false;   ///< continue from out/checkpoint.h5 and append to the outputs there
  SceneSource scene;      ///< saved in every checkpoint, so a restart needs nothing else
};

class Simulation {
 public:
  /// Reads and validates every section of a simulation scene (grid, time, materials,
  /// physics, regions, boundary_conditions, output, probes). Throws InputError.
  Simulation(const Registry& registry, const ConfigNode& root);
  ~Simulation();

  static std::vector<std::string> sections();
  YAML::Node resolved() const { return resolved_; }

  /// Runs to the end time, writing fields.h5/.xdmf, metrics.csv into `out`, and checkpoints
  /// when the scene's `checkpoint:` section says so. A restart re-creates the state of the
  /// checkpoint exactly, so the run continues bit for bit as if it had never stopped. At the
  /// normal end the checkpoint is deleted (there is nothing left to resume). Throws
  /// RunInterrupted after SIGINT/SIGTERM, InputError when a checkpoint cannot be read or written.
  void run(const OutputDir& out, const RunOptions& options);

  // ---- what physics plugins use ----
  const UniformGrid<kDim>& grid() const { return grid_; }
  ParticleStore& particles() { return particles_; }
  const ParticleStore& particles() const { return particles_; }
  const StencilCache<kDim>& stencil() const { return stencil_; }
  /// Nodal fields the stages of this scene read or write (allocated after every setup()).
  NodeFields& node_fields() { return node_fields_; }
  const NodeFields& node_fields() const { return node_fields_; }
  /// The resolved step: stages in order, with their phases, reads and writes.
  const StepPlan& step_plan() const { return plan_; }
  const std::vector<Material>& materials() const { return materials_; }
  const Registry& registry() const { return registry_; }
  /// Boundary conditions whose type a physics owns.
  std::vector<BoundaryCondition*> boundary_conditions(const std::string& type);
  /// The material index of every particle.
  std::vector<std::uint16_t> particle_materials() const;
  /// Sets a particle field to each particle's material parameter (before regions' `initial:`).
  void fill_from_materials(const std::string& field, const std::string& parameter);
  /// Declares a particle field that regions may initialise with `initial: {name: value}`;
  /// an initial value of larger magnitude than `max_magnitude` is refused as a typo.
  void declare_state_field(const std::string& name, int components, double default_value,
                           double max_magnitude = std::numeric_limits<double>::infinity());
  /// Fields a physics can offer to output and probes (declared state or derived fields).
  double time() const { return time_; }
  double dt() const { return dt_; }
  long step() const { return step_; }
  double end_time() const { return end_time_; }
  /// User-fixed time step (0 when automatic).
  double fixed_dt() const { return fixed_dt_; }
  /// The `time:` section as read, for errors about its keys (e.g. a scheme that needs time.dt).
  const ParamSet& time_params() const { return time_params_; }

  const StepStatistics& statistics() const { return stats_; }
  /// How often this run was restarted from a checkpoint.
  long restarts() const { return restarts_; }
  const std::vector<std::shared_ptr<Physics>>& physics() const { return physics_; }
  std::vector<std::string> physics_names() const;

  /// Advances one step of size dt (exposed for tests and benchmarks).
  void advance(double dt);
  /// Value of a particle field (a scalar, or a component "name.x") interpolated to a point
  /// through the grid (volume-weighted).
  double sample_field(const std::string& field, const std::array<double, kDim>& point) const;

 private:
  // Recomputes every particle's stencil; a particle whose support leaves the grid stops the run.
  void update_stencil();
  // Refuses a run whose physics' stable step would need more than time.max_steps steps.
  void check_step_budget() const;
  // The scene keys a blow-up at `particle` may come from: its region, the boundary conditions.
  std::string suspects(std::size_t particle) const;
  struct Probe;
  struct RegionInit;
  /// A scalar field or one component of a vector field ("water_flux.y"): value p is
  /// values[p * stride + component].
  struct ScalarColumn {
    std::span<const double> values;
    std::size_t component = 0, stride = 1;
  };
  ScalarColumn scalar_column(const std::string& name) const;
  const Registry& registry_;
  UniformGrid<kDim> grid_;
  ShapeKind shape_ = ShapeKind::Gimp;
  StencilCache<kDim> stencil_;
  ParticleStore particles_;
  std::vector<Material> materials_;
  std::vector<BoundaryCondition> bcs_;
  std::vector<std::shared_ptr<Physics>> physics_;
  std::vector<std::string> physics_keys_;
  std::vector<SourceLocation> physics_where_;  ///< each physics' section, for errors
  StepPlan plan_;
  NodeFields node_fields_;
  std::vector<RegionInit> region_inits_;
  std::vector<std::unique_ptr<Probe>> probes_;
  std::vector<std::string> output_fields_;
  std::map<std::string, double> state_defaults_;
  std::map<std::string, double> state_bounds_;  ///< largest plausible |initial value| per field
  ParamSchema material_schema_;  ///< every physics' material keys; also bounds `initial:` values
  ParamSet time_params_;
  long max_steps_ = 0;
  double time_ = 0, dt_ = 0, end_time_ = 0, fixed_dt_ = 0, max_dt_ = 0;
  double output_every_ = 0, metrics_every_ = 0;
  long step_ = 0, restarts_ = 0;
  long checkpoint_every_steps_ = 0;
  double checkpoint_every_minutes_ = 0;
  bool positions_changed_ = true;
  mutable bool warned_dt_cut_ = false;  ///< the fixed-step warning is given once
  StepStatistics stats_;
  YAML::Node resolved_;

  void read_grid(const ConfigNode& node);
  void read_time(const ConfigNode& node);
  void read_physics(const ConfigNode& node);
  void read_materials(const ConfigNode& node);
  void read_regions(const ConfigNode& node);
  void read_boundary_conditions(const ConfigNode& node);
  void read_output(const ConfigNode& node);
  void read_probes(const ConfigNode* node);
  void read_checkpoint(const ConfigNode& node);
  void resolve_step();
  /// Nodal fields kept between steps, for checkpoints.
  std::vector<PersistentArray> carried_node_fields();
  void apply_initial_values();
  void check_finite() const;
  std::vector<double> evaluate_probes() const;
  std::string metrics_header() const;
  /// The next step: stability limits, then cut to land on the next output, metrics or end time.
  double plan_step(const LoopState& loop) const;
  void save_checkpoint(const std::string& dir, LoopState& loop, const SceneSource& scene);
  /// Kernel state, particle fields and persistent arrays from <dir>/checkpoint.h5.
  LoopState restore_checkpoint(const std::string& dir);
};

}  // namespace frostmpm
