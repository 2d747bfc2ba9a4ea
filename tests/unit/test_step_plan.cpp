// StepPlan: stages ordered from their declared reads and writes, and every read provided.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "frostmpm/step/step_plan.hpp"

using namespace frostmpm;

namespace {

StepPlan::Declared stage(const std::string& name, Phase phase, std::vector<FieldRef> reads, std::vector<FieldRef> writes,
                         const std::string& physics = "a") {
  SourceLocation where;
  where.file = "scene.yaml";
  where.path = "physics." + physics;
  where.line = 3;
  where.column = 3;
  return {Stage{name, phase, std::move(reads), std::move(writes), [] {}}, physics, where};
}

std::vector<std::string> names(const StepPlan& plan) {
  std::vector<std::string> out;
  for (const auto& s : plan.stages()) out.push_back(s.name);
  return out;
}

std::string error_of(std::vector<StepPlan::Declared> stages, const std::vector<std::string>& particle_fields = {}) {
  try {
    StepPlan::resolve(std::move(stages), particle_fields);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("step plan: phases run in their order, and inside a phase readers after writers", "[step]") {
  // Declared in the worst order: the THM step's stages backwards.
  const auto plan = StepPlan::resolve(
      {stage("m.stress", Phase::UpdateMaterials, {particle_field("velocity", 2)}, {particle_field("stress", 3, "Pa")}),
       stage("h.correct", Phase::CorrectMomentum, {node_field("pressure"), node_field("v_star", 2)},
             {node_field("velocity", 2)}),
       stage("h.pressure", Phase::Pressure, {node_field("v_star", 2)}, {node_field("pressure")}),
       stage("h.predict", Phase::PredictMomentum, {node_field("velocity", 2), node_field("temperature")},
             {node_field("v_star", 2)}),
       stage("t.solve", Phase::Energy, {node_field("temperature"), node_field("velocity", 2)},
             {node_field("temperature")}),
       stage("h.to_grid", Phase::MapToGrid, {particle_field("velocity", 2)}, {node_field("velocity", 2)}),
       // Same phase, reader declared before its writer.
       stage("x.reads_grid_T", Phase::MapToGrid, {node_field("temperature")}, {particle_field("probe", 1, "degC")}),
       stage("t.to_grid", Phase::MapToGrid, {particle_field("temperature")}, {node_field("temperature")}),
       stage("h.to_particles", Phase::MapToParticles, {node_field("velocity", 2)}, {particle_field("velocity", 2)})},
      {"temperature", "velocity"});
  CHECK(names(plan) == std::vector<std::string>{"h.to_grid", "t.to_grid", "x.reads_grid_T", "t.solve", "h.predict",
                                                "h.pressure", "h.correct", "h.to_particles", "m.stress"});
  // Node fields some stage uses, by name; particle fields the scene did not have yet.
  std::vector<std::string> nodal;
  for (const auto& f : plan.node_fields()) nodal.push_back(f.name);
  CHECK(nodal == std::vector<std::string>{"pressure", "temperature", "v_star", "velocity"});
  std::vector<std::string> added;
  for (const auto& f : plan.new_particle_fields()) added.push_back(f.name + " [" + f.unit + "]");
  CHECK(added == std::vector<std::string>{"probe [degC]", "stress [Pa]"});
  const std::string text = plan.describe();
  CHECK(text.find("  2. energy\n    t.solve\n      reads  node:     temperature, velocity[2]\n") != std::string::npos);
  CHECK(text.find("nodal fields allocated: pressure, temperature, v_star[2], velocity[2]") != std::string::npos);
}

TEST_CASE("step plan: two writers of one field keep their declared order", "[step]") {
  const auto plan = StepPlan::resolve({stage("b.force", Phase::PredictMomentum, {node_field("force")}, {node_field("force")}),
                                       stage("a.force", Phase::PredictMomentum, {node_field("force")}, {node_field("force")}),
                                       stage("zero", Phase::MapToGrid, {}, {node_field("force")})},
                                      {});
  CHECK(names(plan) == std::vector<std::string>{"zero", "b.force", "a.force"});
}

TEST_CASE("step plan: a read needs an earlier writer, a carried nodal field or a particle field", "[step]") {
  // Read before its writer: named, with where the writer is.
  CHECK(error_of({stage("h.predict", Phase::PredictMomentum, {node_field("pressure")}, {node_field("v_star")}, "hydraulic"),
                  stage("h.pressure", Phase::Pressure, {}, {node_field("pressure")}, "hydraulic")}) ==
        "scene.yaml:3:3: at 'physics.hydraulic': stage 'h.predict' (phase predict_momentum) reads node field "
        "'pressure', which no earlier stage writes; stage 'h.pressure' writes it later, in phase pressure");
  // Carried from the last step: fine.
  CHECK(error_of({stage("h.predict", Phase::PredictMomentum, {node_field("pressure")}, {node_field("v_star")}),
                  stage("h.pressure", Phase::Pressure, {}, {carried_node_field("pressure")})})
            .empty());
  // A particle field the scene has is state; one it has not needs a writer.
  CHECK(error_of({stage("t.solve", Phase::Energy, {particle_field("temperature")}, {})}, {"temperature"}).empty());
  CHECK(error_of({stage("t.solve", Phase::Energy, {particle_field("stress", 3)}, {})}, {"temperature"}) ==
        "scene.yaml:3:3: at 'physics.a': stage 't.solve' (phase energy) reads particle field 'stress', which no "
        "earlier stage writes; no stage of this scene's physics (a) writes it");
}

TEST_CASE("step plan: a cycle and a field with two shapes are refused", "[step]") {
  const auto cycle = error_of({stage("p", Phase::Pressure, {node_field("x")}, {node_field("y")}),
                               stage("q", Phase::Pressure, {node_field("y")}, {node_field("x")})});
  CHECK(cycle.find("stages 'p', 'q' of phase pressure each read a field another of them writes") != std::string::npos);
  const auto shapes = error_of({stage("p", Phase::MapToGrid, {}, {node_field("velocity", 2)}),
                                stage("q", Phase::Energy, {node_field("velocity", 3)}, {})});
  CHECK(shapes.find("stage 'q' declares node field 'velocity' with 3 components, stage 'p' with 2") !=
        std::string::npos);
}

TEST_CASE("step plan: a particle field a stage creates takes the unit its writer gives, and needs one", "[step]") {
  // The unit may come with any naming of the field, here the reader's.
  const auto plan = StepPlan::resolve({stage("a.make", Phase::MapToGrid, {}, {particle_field("drag")}),
                                       stage("b.use", Phase::Energy, {particle_field("drag", 1, "kg/(m^3 s)")}, {})},
                                      {});
  REQUIRE(plan.new_particle_fields().size() == 1);
  CHECK(plan.new_particle_fields()[0].unit == "kg/(m^3 s)");
  CHECK(error_of({stage("a.make", Phase::MapToGrid, {}, {particle_field("drag")})}) ==
        "scene.yaml:3:3: at 'physics.a': stage 'a.make' writes particle field 'drag', which no physics declares in "
        "setup(), and gives no unit for it: declare it there (declare_field(name, unit, ...)) or give the handle of "
        "its writer a unit");
  CHECK(error_of({stage("a.make", Phase::MapToGrid, {}, {particle_field("drag", 1, "Pa")}),
                  stage("b.use", Phase::Energy, {particle_field("drag", 1, "m")}, {})}) ==
        "scene.yaml:3:3: at 'physics.a': stage 'b.use' declares particle field 'drag' in 'm', stage 'a.make' in 'Pa'");
  // A field the scene has keeps its declaration's unit: its handles need none.
  CHECK(error_of({stage("a.make", Phase::MapToGrid, {}, {particle_field("temperature")})}, {"temperature"}).empty());
}
