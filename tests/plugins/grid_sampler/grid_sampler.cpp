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

namespace grid_sampler {

using namespace frostmpm;

class GridSampler final : public Physics {
 public:
  static constexpr const char* kName = "grid_sampler";
  static constexpr const char* kDoc = "test physics: interpolates a nodal field of another physics to the particles";

  static ParamSchema schema() {
    ParamSchema s;
    s.string("field", "nodal field to sample").defaults_to("temperature");
    s.string("unit", "its unit, which the sampled particle field carries").defaults_to("degC");
    s.choice("phase", {"map_to_grid", "energy", "map_to_particles", "update_materials"}, "phase the stage joins")
        .defaults_to("update_materials");
    return s;
  }
  explicit GridSampler(const ParamSet& p)
      : field_(p.string("field")),
        phase_(p.string("phase")),
        nodal_(FieldHandle::node(field_)),
        sampled_(FieldHandle::particle(field_ + "_sampled", 1, FieldKind::Scalar, p.string("unit"))) {}

  ParamSchema material_schema() const override { return {}; }
  std::vector<ModelSlot> material_models() const override { return {}; }
  std::vector<std::string> boundary_types() const override { return {}; }
  void setup(Kernel<2>& kernel) override { kernel_ = &kernel; }

  std::vector<Stage> stages() override {
    Phase phase = Phase::UpdateMaterials;
    for (Phase p : {Phase::MapToGrid, Phase::Energy, Phase::MapToParticles, Phase::UpdateMaterials})
      if (phase_ == phase_name(p)) phase = p;
    return {{"grid_sampler.sample", phase, {nodal_.read(), position_.read()}, {sampled_.write()}, [this] { sample(); }}};
  }

 private:
  std::string field_, phase_;
  Kernel<2>* kernel_ = nullptr;
  FieldHandle nodal_, sampled_;
  FieldHandle position_ = FieldHandle::particle("position", 2, FieldKind::Vector);

  void sample() {
    const auto& transfer = kernel_->transfer();
    const auto nodal = nodal_.values();
    auto out = sampled_.mutable_values();
    for (std::size_t p = 0; p < out.size(); ++p) out[p] = transfer.value_at(p, nodal);
  }
};

FROSTMPM_REGISTER(Physics, GridSampler)

}  // namespace grid_sampler

FROSTMPM_PLUGIN("test-grid-sampler", "1.0.0")
