#pragma once
// A physics plugin contributes coupled equations to the step: it declares the particle fields
// it keeps, the material parameters and model slots it reads, the boundary-condition types it
// owns, and the stages it hooks into the kernel's phases, each with the fields it reads and
// writes (core/frostmpm/step/stage.hpp). Physics couple through those named fields only; the kernel
// orders the step from the declarations and never names a physical model.
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "frostmpm/config/param_schema.hpp"
#include "frostmpm/particles/particle_removal.hpp"
#include "frostmpm/physics/kernel.hpp"
#include "frostmpm/step/stage.hpp"

namespace frostmpm {

/// A model a physics needs from every material, e.g. {"sfcc", "sfcc", required}.
struct ModelSlot {
  std::string key;   ///< key inside the material section
  std::string kind;  ///< registry kind
  bool required = true;
};

/// A named array a physics keeps between steps besides particle fields (e.g. a grid field
/// carried while particles stand still, adaptive-step state, counters). The kernel writes
/// every one into checkpoints and, on restart, resizes and refills it before the next step.
struct PersistentArray {
  std::string name;
  std::vector<double>* values = nullptr;
};

class Physics {
 public:
  static constexpr const char* kKind = "physics";
  virtual ~Physics();

  /// Material-level parameters this physics reads (keys shared with other physics are fine
  /// when their specs agree).
  virtual ParamSchema material_schema() const = 0;
  virtual std::vector<ModelSlot> material_models() const = 0;
  /// Boundary-condition `type:` names this physics owns.
  virtual std::vector<std::string> boundary_types() const = 0;

  /// Called once after particles exist: declare fields, read materials and boundary
  /// conditions from the kernel, validate everything; stages() is valid afterwards. The
  /// kernel stays valid for the physics' lifetime. A physics implements the dimensions it
  /// supports (DimensionalPhysics does both for a physics templated on the dimension); the
  /// other one refuses the scene.
  virtual void setup(Kernel<2>& kernel);
  virtual void setup(Kernel<3>& kernel);
  /// The stages this physics adds to the step, with their phases and the fields they read and
  /// write. Called once, after every physics' setup(); nodal fields exist from initialize() on.
  virtual std::vector<Stage> stages() = 0;

  /// Called once before the first output, after initial values are set: bring derived
  /// fields (e.g. saturation from temperature) in line with the initial state. A restart
  /// calls it the same way, on the scene's initial state, before the checkpoint overwrites
  /// every particle field and persistent array.
  virtual void initialize() {}
  /// Largest stable time step for the current state (infinity when unconditionally stable).
  virtual double stable_time_step() const { return std::numeric_limits<double>::infinity(); }
  /// Called before the stages of a step run, with the step's dt.
  virtual void begin_step(double /*time*/, double /*dt*/) {}
  /// Everything besides particle fields that the next step depends on; a restart that
  /// restores these and the particle fields must continue bit for bit. Any number of arrays
  /// of any length (0 too); a restart resizes each to its stored length. The names must stay
  /// the same for a checkpoint to be restored.
  virtual std::vector<PersistentArray> persistent_state() { return {}; }
  /// Called after a restart has restored the particle fields and persistent_state(): rebuild
  /// or invalidate whatever initialize() derived from the initial state. The first step after
  /// a restart takes its size from the checkpoint, so stable_time_step() is next asked after
  /// that step, exactly as in the uninterrupted run.
  virtual void restored() {}
  /// Called after a checkpoint was written: drop what restored() does not bring back (solver
  /// caches, preconditioners, matrix graphs), so that the run goes on exactly as a restart
  /// from this checkpoint would.
  virtual void checkpoint_written() {}
  /// Particles are about to leave the run (see ParticleRemoval); the kernel's particle fields
  /// still hold them during the call and are compacted right after it.
  virtual void removing_particles(const ParticleRemoval& /*removal*/) {}
  /// The force the boundary condition `bc` (of a type this physics owns) exerts on the
  /// material, [N] per metre of thickness in 2-D, for `reaction` probes; none when the
  /// physics does not track it.
  virtual std::optional<std::array<double, 3>> reaction(const BoundaryCondition& /*bc*/) const { return std::nullopt; }
  /// A rigid body that a boundary condition drives into the material (a footing), for the
  /// footing_* probes: how far it has moved along its direction of motion [m], the force with
  /// which the material resists that motion [N, per m of thickness in 2-D] and the area it
  /// presses on [m², m per m of thickness in 2-D].
  struct RigidBodyMotion {
    double displacement = 0, force = 0, contact_area = 0;
  };
  /// The motion of the rigid body `bc` drives; none for other conditions.
  virtual std::optional<RigidBodyMotion> rigid_body(const BoundaryCondition& /*bc*/) const { return std::nullopt; }
  /// Counters for run.json (e.g. linear iterations); keys are free-form.
  virtual std::vector<std::pair<std::string, double>> statistics() const { return {}; }
  /// One value per step for run.json's `per_step` (e.g. a solver's iterations and final
  /// residual of every step). Keep them in persistent_state() so a restart continues them.
  virtual std::vector<std::pair<std::string, const std::vector<double>*>> step_series() const { return {}; }
};

}  // namespace frostmpm
