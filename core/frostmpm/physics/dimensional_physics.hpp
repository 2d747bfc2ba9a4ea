#pragma once
// A physics written once for every dimension, `template <int Dim> class Impl : public Physics`
// with `void setup(Kernel<Dim>&) override`, registered as one object: the kernel's setup call
// picks Impl<2> or Impl<3>, and every other call is forwarded to it. Schemas and model slots,
// which do not depend on the dimension, come from an Impl<2> made with the same parameters.
#include <memory>

#include "frostmpm/physics/physics.hpp"

namespace frostmpm {

template <template <int> class Impl>
class DimensionalPhysics : public Physics {
 public:
  explicit DimensionalPhysics(const ParamSet& p) : params_(p), impl_(std::make_unique<Impl<2>>(p)) {}

  ParamSchema material_schema() const override { return impl_->material_schema(); }
  std::vector<ModelSlot> material_models() const override { return impl_->material_models(); }
  std::vector<std::string> boundary_types() const override { return impl_->boundary_types(); }
  void setup(Kernel<2>& kernel) override {
    impl_ = std::make_unique<Impl<2>>(params_);
    impl_->setup(kernel);
  }
  void setup(Kernel<3>& kernel) override {
    impl_ = std::make_unique<Impl<3>>(params_);
    impl_->setup(kernel);
  }
  std::vector<Stage> stages() override { return impl_->stages(); }
  void initialize() override { impl_->initialize(); }
  double stable_time_step() const override { return impl_->stable_time_step(); }
  void begin_step(double time, double dt) override { impl_->begin_step(time, dt); }
  std::vector<PersistentArray> persistent_state() override { return impl_->persistent_state(); }
  void restored() override { impl_->restored(); }
  void checkpoint_written() override { impl_->checkpoint_written(); }
  void removing_particles(const ParticleRemoval& removal) override { impl_->removing_particles(removal); }
  std::optional<std::array<double, 3>> reaction(const BoundaryCondition& bc) const override { return impl_->reaction(bc); }
  std::optional<RigidBodyMotion> rigid_body(const BoundaryCondition& bc) const override { return impl_->rigid_body(bc); }
  std::vector<std::pair<std::string, double>> statistics() const override { return impl_->statistics(); }
  std::vector<std::pair<std::string, const std::vector<double>*>> step_series() const override {
    return impl_->step_series();
  }

 private:
  ParamSet params_;
  std::unique_ptr<Physics> impl_;
};

}  // namespace frostmpm
