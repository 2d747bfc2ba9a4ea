// A third-party physics, built outside plugins/ and loaded with --plugin-path, that couples to
// another physics through the kernel's field registry alone: it never names the thermal
// plugin. Each step it interpolates a nodal field (by default the thermal physics' node field
// 'temperature') to the particles, into the particle field '<field>_sampled'. The tests check
// that the value equals what the thermal physics computes from the same nodes (its PIC
// temperature), that the kernel orders it after the writer whatever the physics' order in the
// scene, and that a field nothing writes is refused at setup.
#include <string>
#include <vector>

#include "frostmpm/physics/physics.hpp"
#include "frostmpm/plugin/plugin_api.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "frostmpm/transfer/nodal_interpolation.hpp"

namespace grid_sampler {

using namespace frostmpm;

class GridSampler final : public Physics {
 public:
  static constexpr const char* kName = "grid_sampler";
  static constexpr const char* kDoc = "test physics: interpolates a nodal field of another physics to the particles";

  static ParamSchema schema() {
    ParamSchema s;
    s.string("field", "nodal field to sample").defaults_to("temperature");
    s.choice("phase", {"map_to_grid", "energy", "map_to_particles", "update_materials"}, "phase the stage joins")
        .defaults_to("update_materials");
    return s;
  }
  explicit GridSampler(const ParamSet& p) : field_(p.string("field")), phase_(p.string("phase")) {}

  ParamSchema material_schema() const override { return {}; }
  std::vector<ModelSlot> material_models() const override { return {}; }
  std::vector<std::string> boundary_types() const override { return {}; }
  void setup(Simulation& sim) override { sim_ = &sim; }

  std::vector<Stage> stages() override {
    Phase phase = Phase::UpdateMaterials;
    for (Phase p : {Phase::MapToGrid, Phase::Energy, Phase::MapToParticles, Phase::UpdateMaterials})
      if (phase_ == phase_name(p)) phase = p;
    return {{"grid_sampler.sample", phase, {node_field(field_), particle_field("position", kDim)},
             {particle_field(field_ + "_sampled")}, [this] { sample(); }}};
  }

 private:
  std::string field_, phase_;
  Simulation* sim_ = nullptr;

  void sample() {
    const auto& stencil = sim_->stencil();
    const auto nodal = sim_->node_fields().field(field_);
    auto out = sim_->particles().field(field_ + "_sampled");
    for (std::size_t p = 0; p < out.size(); ++p) out[p] = nodal_value_at(stencil, p, nodal);
  }
};

FROSTMPM_REGISTER(Physics, GridSampler)

}  // namespace grid_sampler

FROSTMPM_PLUGIN("test-grid-sampler", "1.0.0")
