#pragma once
// The pieces of a coupled step (docs/architecture.md, "The coupled step"). The kernel owns a
// fixed list of phases, the paper's step (Yu et al. 2024, Sec. 4.1–4.3); each physics hooks
// stages into them and declares the particle and nodal fields every stage reads and writes.
// The kernel orders the stages from those declarations (StepPlan), allocates the nodal fields
// some stage uses, and refuses a scene where a stage reads what nothing provides. Physics
// never call each other: they couple through named fields only.
//
// Declared fields are also the only way in: a physics holds a FieldHandle per field, declares
// its stages' reads and writes through the handles, and the kernel binds each handle to the
// field's storage once the step is resolved. A handle a stage only reads is bound read-only;
// a handle no stage declares stays unbound, and using it is a logic error naming the field
// (Uintah refuses an undeclared access at its data warehouse the same way).
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "frostmpm/particles/particle_store.hpp"

namespace frostmpm {

/// The phases of a step, in the order they run.
enum class Phase {
  MapToGrid,        ///< particles → grid, every phase (mass, momentum, heat); stress update (USF)
  Energy,           ///< heat balance on the grid
  PredictMomentum,  ///< intermediate velocities (explicit forces, Darcy drag)
  Pressure,         ///< pore-pressure Poisson equation
  CorrectMomentum,  ///< velocity correction with the new pressure gradient
  MapToParticles,   ///< grid → particles; particles move
  UpdateMaterials,  ///< stress and material state at the particles
};
inline constexpr int kPhaseCount = 7;

/// "map_to_grid", "energy", … (the names `frostmpm check` prints).
const char* phase_name(Phase phase);

enum class FieldLocation { Particle, Node };

class FieldHandle;

/// A named field: a particle field (a column of the ParticleStore) or a nodal field (a column
/// the kernel allocates on the grid, `components` values per node).
struct FieldRef {
  FieldLocation location = FieldLocation::Particle;
  std::string name;
  int components = 1;
  /// For a nodal field a stage writes: its value is kept from one step to the next, so a
  /// stage that runs before the writer reads the last step's value (and checkpoints keep it).
  bool carried = false;
  /// For a read: used when the scene provides it, dropped from the step otherwise (e.g. the
  /// thermal physics' convective term reads the Darcy flux only when some physics writes it).
  bool optional = false;
  /// The physics' handle the kernel binds to this field's storage (none: declaration only).
  FieldHandle* handle = nullptr;
  FieldKind kind = FieldKind::Other;
  /// For a particle field no physics declares in setup(), which the kernel creates because a
  /// stage writes it: its unit ("m/s", "1"; frostmpm/config/units.hpp). A writer must give it.
  std::string unit;

  std::string describe() const;  ///< "particle field 'temperature'", "node field 'liquid_velocity'"
  bool same_field(const FieldRef& other) const { return location == other.location && name == other.name; }
};

/// `unit`: see FieldRef::unit.
inline FieldRef particle_field(std::string name, int components = 1, std::string unit = {}) {
  FieldRef f{FieldLocation::Particle, std::move(name), components, false};
  f.unit = std::move(unit);
  return f;
}
inline FieldRef node_field(std::string name, int components = 1) {
  return {FieldLocation::Node, std::move(name), components, false};
}
/// A read the stage can do without (see FieldRef::optional).
inline FieldRef optional_read(FieldRef f) {
  f.optional = true;
  return f;
}
/// A nodal field kept between steps (see FieldRef::carried).
inline FieldRef carried_node_field(std::string name, int components = 1) {
  return {FieldLocation::Node, std::move(name), components, true};
}

/// A physics' access to one declared field. Declare with read()/write()/optional_read() in a
/// stage's lists; from initialize() on, values() (any bound handle) and mutable_values() (a
/// handle some stage writes) give the storage.
class FieldHandle {
 public:
  FieldHandle() = default;
  FieldHandle(FieldLocation location, std::string name, int components = 1, FieldKind kind = FieldKind::Other,
              std::string unit = {})
      : location_(location), name_(std::move(name)), components_(components), kind_(kind), unit_(std::move(unit)) {}
  /// `unit`: see FieldRef::unit (a field some physics declares in setup() needs none here).
  static FieldHandle particle(std::string name, int components = 1, FieldKind kind = FieldKind::Other,
                              std::string unit = {}) {
    return {FieldLocation::Particle, std::move(name), components, kind, std::move(unit)};
  }
  static FieldHandle node(std::string name, int components = 1, FieldKind kind = FieldKind::Other) {
    return {FieldLocation::Node, std::move(name), components, kind};
  }
  // Copying a handle would copy a binding the kernel does not know about.
  FieldHandle(const FieldHandle&) = delete;
  FieldHandle& operator=(const FieldHandle&) = delete;
  FieldHandle(FieldHandle&&) = default;
  FieldHandle& operator=(FieldHandle&&) = default;

  /// Declarations for a stage's `reads` / `writes`.
  FieldRef read() { return ref(false, false); }
  FieldRef optional_read() { return ref(true, false); }
  FieldRef write() { return ref(false, false); }
  /// A nodal field kept between steps (see FieldRef::carried).
  FieldRef carried_write() { return ref(false, true); }

  const std::string& name() const { return name_; }
  int components() const { return components_; }
  FieldLocation location() const { return location_; }
  /// Bound: some stage of the resolved step declares the field (an optional read nothing
  /// provides stays unbound).
  bool bound() const { return column_ != nullptr; }
  bool writable() const { return writable_; }

  std::span<const double> values() const { return storage(); }
  std::span<double> mutable_values() const;
  const double* data() const { return storage().data(); }
  double* mutable_data() const { return mutable_values().data(); }
  /// The storage vector, for routines that take one (its size may change with the particle count).
  std::vector<double>& vector() const;

  /// Called by the kernel once the step is resolved.
  void bind(std::vector<double>* column, bool writable) {
    column_ = column;
    writable_ = writable_ || writable;
  }

 private:
  FieldRef ref(bool optional, bool carried) {
    return FieldRef{location_, name_, components_, carried, optional, this, kind_, unit_};
  }
  std::span<double> storage() const;

  FieldLocation location_ = FieldLocation::Particle;
  std::string name_;
  int components_ = 1;
  FieldKind kind_ = FieldKind::Other;
  std::string unit_;
  std::vector<double>* column_ = nullptr;
  bool writable_ = false;
};

/// One stage of the step; the scheduler times each by name for run.json.
struct Stage {
  std::string name;  ///< "physics.what", e.g. "thermal.solve"
  Phase phase = Phase::MapToGrid;
  /// Fields read at their latest value: written earlier in this step, or state carried from
  /// the last step (every particle field; nodal fields a writer marks `carried`).
  std::vector<FieldRef> reads;
  std::vector<FieldRef> writes;
  std::function<void()> run;
  /// Runs only when another stage of the scene reads something it writes (e.g. what a physics
  /// hands to a partner physics the scene may not have): otherwise the kernel drops it.
  bool skippable = false;
};

}  // namespace frostmpm
