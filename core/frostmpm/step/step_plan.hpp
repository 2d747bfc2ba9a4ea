#pragma once
// The resolved step: every stage of every physics in the order it runs, and the fields it
// needs. Resolved once per scene, not per step.
//
// Order: phases in their fixed order; inside a phase a stage that reads a field runs after the
// stages that write it (ties keep the order of the physics in the scene, then of their stages;
// two writers of one field keep that order too). Checks: every field a stage reads is written
// by an earlier stage, or is state carried from the last step (a particle field the scene has,
// or a nodal field its writer marks carried); one field has one component count (and one unit,
// where stages give one); a particle field only a stage creates has a unit; the order has no
// cycle. A failed check is one InputError naming the stage, the field and the physics
// section.
#include <string>
#include <vector>

#include "frostmpm/config/input_error.hpp"
#include "frostmpm/step/stage.hpp"

namespace frostmpm {

class StepPlan {
 public:
  /// A stage as a physics declared it, with the scene section that made the physics (for errors).
  struct Declared {
    Stage stage;
    std::string physics;    ///< the physics' key in the scene, e.g. "thermal"
    SourceLocation where;   ///< its section
  };

  StepPlan() = default;
  /// `particle_fields`: the particle fields that exist before the first step (state).
  static StepPlan resolve(std::vector<Declared> stages, const std::vector<std::string>& particle_fields);

  const std::vector<Stage>& stages() const { return stages_; }
  std::vector<Stage>& stages() { return stages_; }
  /// Nodal fields some stage reads or writes (name, components, carried), by name.
  const std::vector<FieldRef>& node_fields() const { return node_fields_; }
  /// Particle fields a stage writes that did not exist before, with the unit a stage gave: the
  /// kernel declares them.
  const std::vector<FieldRef>& new_particle_fields() const { return new_particle_fields_; }

  /// The step as `frostmpm check` prints it: phase, stage, reads, writes, skipped phases.
  std::string describe() const;

 private:
  std::vector<Stage> stages_;
  std::vector<std::string> physics_;  ///< owner of each stage
  std::vector<FieldRef> node_fields_, new_particle_fields_;
};

}  // namespace frostmpm
