#pragma once
// The kernel's state and step loop: grid, particles (structure of arrays), the transfer
// service, materials, boundary conditions, the physics in play and their stages, output and
// probes. It implements Kernel<2>, the narrow interface physics see; 2-D today, while grid,
// shape functions, stencils, transfer and the physics interface are templated on the dimension.
//
// The jobs are split by file: reading the scene (scene_reading.cpp), probes (probes.cpp), the
// step and the run loop with checkpoints (simulation.cpp).
#include <chrono>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/io/checkpoint.hpp"
#include "frostmpm/particles/particle_store.hpp"
#include "frostmpm/physics/kernel.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/plugin/registry.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "frostmpm/simulation/probes.hpp"
#include "frostmpm/simulation/step_statistics.hpp"
#include "frostmpm/step/node_fields.hpp"
#include "frostmpm/step/step_plan.hpp"
#include "frostmpm/transfer/transfer.hpp"

namespace frostmpm {

class OutputDir;
class ParticleFieldWriter;

inline constexpr int kDim = 2;

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

/// What happens to a particle whose shape-function support leaves the grid.
enum class LeavingPolicy { Stop, Remove };

class Simulation final : public Kernel<kDim> {
 public:
  /// Reads and validates every section of a simulation scene (grid, time, gravity, materials,
  /// physics, regions, boundary_conditions, output, probes) and builds the initial state the first
  /// step starts from (stencils, every physics' initialize()), so that `frostmpm check` refuses
  /// all that `run` would before its first step. Throws InputError.
  Simulation(const Registry& registry, const ConfigNode& root);
  ~Simulation() override;

  static std::vector<std::string> sections();
  /// The schemas of the kernel's own sections (grid, time, output, checkpoint), by section.
  static std::vector<std::pair<std::string, ParamSchema>> section_schemas();
  YAML::Node resolved() const { return resolved_; }

  /// Runs to the end time, writing fields.h5/.xdmf, metrics.csv into `out`, and checkpoints
  /// when the scene's `checkpoint:` section says so. A restart re-creates the state of the
  /// checkpoint exactly, so the run continues bit for bit as if it had never stopped. At the
  /// normal end the checkpoint is deleted (there is nothing left to resume). Throws
  /// RunInterrupted after SIGINT/SIGTERM, InputError when a checkpoint cannot be read or written.
  void run(const OutputDir& out, const RunOptions& options);

  // ---- Kernel<2>: what physics see ----
  const UniformGrid<kDim>& grid() const override { return grid_; }
  const std::vector<Material>& materials() const override { return materials_; }
  const Registry& registry() const override { return registry_; }
  std::vector<BoundaryCondition*> boundary_conditions(const std::string& type) override;
  std::array<double, kDim> gravity() const override { return gravity_; }
  double end_time() const override { return end_time_; }
  double fixed_dt() const override { return fixed_dt_; }
  const ParamSet& time_params() const override { return time_params_; }
  std::vector<std::string> physics_names() const override { return physics_keys_; }
  std::size_t particle_count() const override { return particles_.size(); }
  const std::vector<ParticleRange>& particle_ranges() const override { return particles_.ranges(); }
  void declare_state_field(const std::string& name, const std::string& unit, int components, double default_value,
                           double max_magnitude = std::numeric_limits<double>::infinity(),
                           FieldKind kind = FieldKind::Other) override;
  void declare_field(const std::string& name, const std::string& unit, int components = 1, double initial = 0.0,
                     FieldKind kind = FieldKind::Other) override;
  void declare_history(const std::string& name, const std::string& unit, int components = 1, double initial = 0.0,
                       FieldKind kind = FieldKind::Other) override;
  bool has_particle_field(const std::string& name) const override { return particles_.has(name); }
  void fill_from_materials(const std::string& field, const std::string& parameter) override;
  const Transfer<kDim>& transfer() const override { return transfer_; }
  double time() const override { return time_; }
  double dt() const override { return dt_; }
  long step() const override { return step_; }
  std::string describe_particle(std::size_t p) const override;

  // ---- for the application, tests and benchmarks ----
  ParticleStore& particles() { return particles_; }
  const ParticleStore& particles() const { return particles_; }
  /// Nodal fields the stages of this scene read or write (allocated after every setup()).
  const NodeFields& node_fields() const { return node_fields_; }
  /// The resolved step: stages in order, with their phases, reads and writes.
  const StepPlan& step_plan() const { return plan_; }
  /// One line per boundary condition on nodes: how many of its nodes carry material at the start.
  const std::string& boundary_report() const { return boundary_report_; }
  const StepStatistics& statistics() const { return stats_; }
  /// How often this run was restarted from a checkpoint.
  long restarts() const { return restarts_; }
  const std::vector<std::shared_ptr<Physics>>& physics() const { return physics_; }
  bool particles_move() const override { return moving_; }
  /// (column, unit) of every metrics.csv column, in its order.
  std::vector<std::pair<std::string, std::string>> metrics_units() const { return probes_.column_units(); }
  /// Particles removed after leaving the grid (grid.particles_leaving: remove).
  long removed_particles() const { return static_cast<long>(initial_particles_ - particles_.size()); }

  /// Advances one step of size dt (exposed for tests and benchmarks).
  void advance(double dt);

 private:
  struct RegionInit {
    ParticleRange range;
    std::unique_ptr<ConfigNode> node;  ///< `initial:` section, checked once fields exist
  };

  // scene_reading.cpp
  void read_grid(const ConfigNode& node);
  void read_time(const ConfigNode& node);
  void read_gravity(const ConfigNode* node);
  void read_physics(const ConfigNode& node);
  void read_materials(const ConfigNode& node);
  void read_regions(const ConfigNode& node);
  void read_boundary_conditions(const ConfigNode& node);
  void read_output(const ConfigNode& node);
  void read_checkpoint(const ConfigNode& node);

  // simulation.cpp
  void resolve_step();
  /// Stencils and every physics' initialize() on the initial state, then the step budget.
  void initialize_state();
  /// Warns about scene keys no physics of the scene uses (gravity without a momentum balance).
  void warn_unused_keys() const;
  void bind_handles();
  /// Nodal fields kept between steps, for checkpoints.
  std::vector<PersistentArray> carried_node_fields();
  void apply_initial_values();
  template <class Set>
  void assign_from_run(const ConfigNode& node, const std::string& field, const ParticleRange& range, int k, int n,
                       Set&& set);
  /// Positions moved: GIMP domains and volumes from the deformation gradient, stencils.
  void update_geometry();
  /// Periodic positions wrapped and the stencils rebuilt; returns the first particle outside the
  /// grid, or −1.
  long locate_particles();
  /// locate_particles, then particles off the grid removed (grid.particles_leaving: remove) or
  /// the run stopped.
  void update_stencil();
  /// Drops the particles flagged in `leaving` from the particle fields, the transfer's materials,
  /// the boundary conditions' and probes' particle lists and every physics (which counts what
  /// they carry unless `restoring`).
  void remove_particles(std::span<const std::uint8_t> leaving, bool restoring);
  void check_finite() const;
  /// Refuses a run whose physics' stable step would need more than time.max_steps steps.
  void check_step_budget() const;
  /// The scene keys a blow-up at `particle` may come from: its region, the boundary conditions.
  std::string suspects(std::size_t particle) const;
  /// The next step: stability limits, then cut to land on the next output, metrics or end time.
  double plan_step(const LoopState& loop) const;
  void save_checkpoint(const std::string& dir, LoopState& loop, const SceneSource& scene);
  /// Kernel state, particle fields and persistent arrays from <dir>/checkpoint.h5.
  LoopState restore_checkpoint(const std::string& dir);
  /// The physics owning the condition's type (it reports the condition's reaction, rigid body).
  const Physics& owner_of(const BoundaryCondition& bc) const;
  /// The boundary condition with this `name:` (probes name only conditions that exist).
  const BoundaryCondition& named_condition(const std::string& name) const;
  /// The reaction force of the condition named `name`, and the rigid body it drives (a footing);
  /// NaN when its physics does not report them (probes name only those that do).
  std::array<double, 3> reaction(const std::string& name) const;
  Physics::RigidBodyMotion rigid_body(const std::string& name) const;

  const Registry& registry_;
  UniformGrid<kDim> grid_;
  ShapeKind shape_ = ShapeKind::Gimp;
  LeavingPolicy leaving_ = LeavingPolicy::Stop;
  Transfer<kDim> transfer_;
  ParticleStore particles_;
  std::array<double, kDim> gravity_{};
  std::optional<SourceLocation> gravity_where_;  ///< where the scene gave `gravity:`, for warnings
  std::vector<Material> materials_;
  std::vector<BoundaryCondition> bcs_;
  std::vector<std::shared_ptr<Physics>> physics_;
  std::vector<std::string> physics_keys_;
  std::vector<SourceLocation> physics_where_;  ///< each physics' section, for errors
  std::map<std::string, std::string> bc_owner_;  ///< boundary-condition type → physics key
  StepPlan plan_;
  NodeFields node_fields_;
  std::vector<RegionInit> region_inits_;
  Probes probes_;
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
  bool checkpoint_at_end_ = true;
  std::string boundary_report_;  ///< see boundary_report()
  void check_boundary_reach();
  bool positions_changed_ = true;
  bool moving_ = false;
  std::size_t initial_particles_ = 0;  ///< as the scene made them
  long clamped_domains_ = 0;  ///< GIMP half-widths held at half a cell (large stretch)
  mutable bool warned_dt_cut_ = false;  ///< the fixed-step warning is given once
  StepStatistics stats_;
  YAML::Node resolved_;
};

}  // namespace frostmpm
