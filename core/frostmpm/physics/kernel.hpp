#pragma once
// What a physics sees of the kernel: a narrow interface instead of the whole Simulation, so a
// change inside the kernel (its loop, its scene reading, its output) changes no plugin-facing
// header and no plugin ABI. Dimension is a template parameter: Kernel<2> runs today; Kernel<3>
// is declared so that physics written for both compile against it now.
//
// Two moments:
//  - setup (Physics::setup): the scene (grid, materials, boundary conditions, gravity, time),
//    declaring particle fields and history, filling fields from material parameters;
//  - steps (stages, initialize, stable_time_step, statistics...): the transfer service,
//    time and step, and the fields the physics declared — through its FieldHandles only.
#include <array>
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "frostmpm/config/param_schema.hpp"
#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/particles/particle_store.hpp"
#include "frostmpm/plugin/registry.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "frostmpm/transfer/transfer.hpp"

namespace frostmpm {

struct Material {
  std::string name;
  ParamSet params;                               ///< merged schema of every active physics
  std::map<std::string, ModelSection> models;    ///< by slot key, e.g. "sfcc"
};

/// A boundary condition as the kernel parsed it: where it acts; the physics owning `type`
/// reads its own keys from `node` (and must call node.finish()).
struct BoundaryCondition {
  std::string type;
  std::string name;                     ///< optional `name:`, for probes (reaction) and messages
  std::string target_text;              ///< e.g. "face y_max", for messages
  std::vector<std::size_t> nodes;       ///< node targets
  std::vector<double> node_areas;       ///< face area per node (0 for box node sets)
  int face_axis = -1, face_side = 0;    ///< the grid face, for face targets (axis -1 otherwise)
  std::vector<std::size_t> particles;   ///< particle targets
  bool on_particles = false;
  std::unique_ptr<ConfigNode> node;
  /// "temperature condition 'boundary_conditions.0' on face x_min": for messages, naming the key.
  std::string label() const { return type + " condition '" + node->path() + "' on " + target_text; }
  /// Refuses any key besides the kernel's (type, name, nodes, particles) and `keys`, the keys of
  /// this condition's type. A physics calls it before reading them, so that a typo is reported as
  /// itself and not as the missing key it causes.
  void accept_keys(std::vector<std::string> keys) const {
    keys.insert(keys.end(), {"type", "name", "nodes", "particles"});
    node->reject_unknown(keys);
  }
};

/// Thrown when the solution stops being finite; the message says where and when.
class NumericalBlowUp : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
inline constexpr int kBlowUpExitCode = 3;

template <int Dim>
class Kernel {
 public:
  static constexpr int kDim = Dim;
  virtual ~Kernel() = default;

  // ---- the scene ------------------------------------------------------------------------------
  virtual const UniformGrid<Dim>& grid() const = 0;
  virtual const std::vector<Material>& materials() const = 0;
  virtual const Registry& registry() const = 0;
  /// Boundary conditions whose type a physics owns.
  virtual std::vector<BoundaryCondition*> boundary_conditions(const std::string& type) = 0;
  /// The scene's body force per unit mass (`gravity:`, default zero).
  virtual std::array<double, Dim> gravity() const = 0;
  virtual double end_time() const = 0;
  /// User-fixed time step (0 when automatic).
  virtual double fixed_dt() const = 0;
  /// The `time:` section as read, for errors about its keys (e.g. a scheme that needs time.dt).
  virtual const ParamSet& time_params() const = 0;
  /// Every physics of the scene, by its key ("thermal", "hydraulic", ...), in scene order.
  virtual std::vector<std::string> physics_names() const = 0;

  // ---- particle fields (setup) ------------------------------------------------------------------
  virtual std::size_t particle_count() const = 0;
  /// Contiguous runs of particles of one material (one per region): models are evaluated in
  /// batches over these, one virtual call per range.
  virtual const std::vector<ParticleRange>& particle_ranges() const = 0;
  // Every particle field is declared with its unit, UDUNITS-2 text ("degC", "Pa", "m/s", "1"
  // when dimensionless; frostmpm/config/units.hpp): fields.h5 and the probes' columns carry it.
  // Two physics that declare one field must agree on its components and unit.

  /// A particle field that regions may initialise with `initial: {name: value}` (a value given
  /// with another unit is converted to `unit`); an initial value of larger magnitude than `max_magnitude` is refused as a typo.
  virtual void declare_state_field(const std::string& name, const std::string& unit, int components,
                                   double default_value, double max_magnitude = std::numeric_limits<double>::infinity(),
                                   FieldKind kind = FieldKind::Other) = 0;
  /// A particle field the physics keeps (not set by regions).
  virtual void declare_field(const std::string& name, const std::string& unit, int components = 1,
                             double initial = 0.0, FieldKind kind = FieldKind::Other) = 0;
  /// A particle field with a step-start copy (ParticleStore::declare_history): a model or a
  /// retried step starts from the values the step began with.
  virtual void declare_history(const std::string& name, const std::string& unit, int components = 1,
                               double initial = 0.0, FieldKind kind = FieldKind::Other) = 0;
  /// Whether the scene has a particle field of this name (after every physics' setup).
  virtual bool has_particle_field(const std::string& name) const = 0;
  /// Sets a particle field to each particle's material parameter (before regions' `initial:`).
  virtual void fill_from_materials(const std::string& field, const std::string& parameter) = 0;

  // ---- the step ---------------------------------------------------------------------------------
  /// Stencils, coloured blocks, material indices and G2P helpers (valid from initialize() on).
  virtual const Transfer<Dim>& transfer() const = 0;
  virtual double time() const = 0;
  virtual double dt() const = 0;
  virtual long step() const = 0;
  /// True when some stage writes the particle positions (valid from initialize() on): the
  /// kernel then recomputes stencils, volumes and GIMP domains every step, and grid state
  /// derived from particles must be derived again.
  virtual bool particles_move() const = 0;
  /// "particle 12 at (0.5, 0.25) in regions.0 (material 'soil')": for messages.
  virtual std::string describe_particle(std::size_t p) const = 0;
};

}  // namespace frostmpm
