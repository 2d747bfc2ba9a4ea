#pragma once
// A physics plugin contributes coupled equations to the step: it declares the particle fields
// it keeps, the material parameters and model slots it reads, the boundary-condition types it
// owns, and the stages it hooks into the kernel's phases, each with the fields it reads and
// writes (core/frostmpm/step/stage.hpp). Physics couple through those named fields only; the kernel
// orders the step from the declarations and never names a physical model.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "frostmpm/config/param_schema.hpp"
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

/// Particles leaving the run (`grid.particles_leaving: remove`): `leaving[p]` is 1 for each,
/// `new_index[p]` the index particle p keeps afterwards (-1 when it leaves). A physics counts
/// what the leaving particles carry (its balances stay closed), then compacts its own
/// per-particle arrays and particle lists with compact() and remap().
struct ParticleRemoval {
  std::span<const std::uint8_t> leaving;
  std::vector<std::int64_t> new_index;
  std::size_t remaining = 0;
  bool restoring = false;  ///< a restart re-applying earlier removals: nothing to count

  explicit ParticleRemoval(std::span<const std::uint8_t> leaving_particles) : leaving(leaving_particles) {
    new_index.resize(leaving.size());
    for (std::size_t p = 0; p < leaving.size(); ++p)
      new_index[p] = leaving[p] ? -1 : static_cast<std::int64_t>(remaining++);
  }
  /// Keeps the values of every remaining particle, in order (an array of any whole number of
  /// values per particle; one of another length, such as an empty one, is left alone).
  template <class T>
  void compact(std::vector<T>& values) const {
    if (leaving.empty() || values.empty() || values.size() % leaving.size() != 0) return;
    const std::size_t per_particle = values.size() / leaving.size();
    std::size_t out = 0;
    for (std::size_t p = 0; p < leaving.size(); ++p) {
      if (leaving[p]) continue;
      for (std::size_t c = 0; c < per_particle; ++c) values[out * per_particle + c] = values[p * per_particle + c];
      ++out;
    }
    values.resize(out * per_particle);
  }
  /// A list of particle indices: the leaving ones dropped, the others renumbered.
  void remap(std::vector<std::size_t>& particles) const {
    std::size_t out = 0;
    for (std::size_t p : particles)
      if (!leaving[p]) particles[out++] = static_cast<std::size_t>(new_index[p]);
    particles.resize(out);
  }
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
  /// Counters for run.json (e.g. linear iterations); keys are free-form.
  virtual std::vector<std::pair<std::string, double>> statistics() const { return {}; }
  /// One value per step for run.json's `per_step` (e.g. a solver's iterations and final
  /// residual of every step). Keep them in persistent_state() so a restart continues them.
  virtual std::vector<std::pair<std::string, const std::vector<double>*>> step_series() const { return {}; }
};

}  // namespace frostmpm
