#pragma once
// The pieces of a coupled step (docs/architecture.md, "The coupled step"). The kernel owns a
// fixed list of phases, the paper's step (Yu et al. 2024, Sec. 4.1–4.3); each physics hooks
// stages into them and declares the particle and nodal fields every stage reads and writes.
// The kernel orders the stages from those declarations (StepPlan), allocates the nodal fields
// some stage uses, and refuses a scene where a stage reads what nothing provides. Physics
// never call each other: they couple through named fields only.
#include <functional>
#include <string>
#include <vector>

namespace frostmpm {

/// The phases of a step, in the order they run.
enum class Phase {
  MapToGrid,        ///< particles → grid, every phase (mass, momentum, heat)
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

  std::string describe() const;  ///< "particle field 'temperature'", "node field 'liquid_velocity'"
  bool same_field(const FieldRef& other) const { return location == other.location && name == other.name; }
};

inline FieldRef particle_field(std::string name, int components = 1) {
  return {FieldLocation::Particle, std::move(name), components, false};
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

/// One stage of the step; the scheduler times each by name for run.json.
struct Stage {
  std::string name;  ///< "physics.what", e.g. "thermal.solve"
  Phase phase = Phase::MapToGrid;
  /// Fields read at their latest value: written earlier in this step, or state carried from
  /// the last step (every particle field; nodal fields a writer marks `carried`).
  std::vector<FieldRef> reads;
  std::vector<FieldRef> writes;
  std::function<void()> run;
};

}  // namespace frostmpm
