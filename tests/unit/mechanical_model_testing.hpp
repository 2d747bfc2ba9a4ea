#pragma once
// Helpers of the constitutive-model tests: a model built through the registry as a scene builds
// it (YAML model section -> read_model_section -> create), and one point's stress update.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/models/mechanical_model.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "test_support.hpp"

namespace frostmpm::test {

using Voigt = std::array<double, 6>;  // xx, yy, zz, yz, xz, xy; tensor shear strains

/// `material: {mechanical_model: {model: NAME, params}}` -> read_model_section -> create.
inline std::shared_ptr<MechanicalModel> make_model(const Registry& registry, const std::string& name,
                                                   const std::string& params) {
  const std::string text =
      "material:\n  mechanical_model: {model: " + name + (params.empty() ? "" : ", " + params) + "}\n";
  const auto root = ConfigNode::load_string(text, "mechanical-test.yaml");
  const auto section =
      read_model_section(registry, MechanicalModel::kKind, root.child("material").child("mechanical_model"));
  return section.create<MechanicalModel>(registry);
}

inline std::shared_ptr<MechanicalModel> make_model(const std::string& name, const std::string& params) {
  return make_model(builtin_registry(), name, params);
}

/// One point's update.
struct StressUpdate {
  Voigt stress{};
  std::array<double, 36> tangent{};
  std::vector<double> state;  ///< the internal variables at the step's end
  double p_wave = 0, shear = 0;
  bool failed = false;
};

/// S_c < 0 passes no ice saturation (a scene without thermal physics); an empty `state` starts
/// from the model's initial state.
inline StressUpdate integrate(const MechanicalModel& model, const Voigt& strain, const Voigt& start, double S_c,
                              std::vector<double> state = {}) {
  StressUpdate u;
  if (state.empty()) state = model.initial_state();
  u.state.assign(state.size(), 0.0);
  const double ice[1] = {S_c};
  std::uint8_t failed[1] = {0};
  StressUpdateInput in;
  in.strain_increment = strain;
  in.stress_start = start;
  in.state_start = state;
  if (S_c >= 0) in.ice_saturation = ice;
  in.dt = 1e-3;
  StressUpdateOutput out;
  out.stress = u.stress;
  out.state = u.state;
  out.failed = failed;
  out.tangent = u.tangent;
  out.p_wave_modulus = {&u.p_wave, 1};
  out.shear_modulus = {&u.shear, 1};
  model.integrate(in, out);
  u.failed = failed[0] != 0;
  return u;
}

}  // namespace frostmpm::test
