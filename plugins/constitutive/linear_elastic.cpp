// Isotropic linear elasticity in rate form (hypoelastic, paper Eq. 28 with D the Hooke tensor):
//   Δσ′ = λ tr(Δε) I + 2G Δε,  G = E / (2(1 + ν)),  λ = E ν / ((1 + ν)(1 − 2ν)),
// with a Young's modulus that may grow with the ice saturation S_c (frozen soil stiff, thawed
// soil soft): E(S_c) = E + (E_frozen − E) S_c, ν fixed. How a change of the modulus acts is a
// choice (modulus_change):
//   increments     on the strain increments only (rate form, the paper's Eq. 28): ice melting
//                  at constant strain changes no stress;
//   elastic_strain σ′ = E(S_c) D̂ : ε_e, the effective stress wholly elastic (D̂ the Hooke tensor
//                  for E = 1): at constant strain a change of modulus scales the stress,
//                  Δσ′ = E⁺ D̂ Δε + (E⁺/E − 1) σ′. Ice melting then releases the stress the
//                  ice carried, and thawing soil carries only what its thawed skeleton can at
//                  its strain (Morgenstern & Nixon's thawing soil). The state is E of the last
//                  step, a scalar, so the rule is objective with the rotated stress.
#include <algorithm>
#include <cmath>

#include "frostmpm/models/mechanical_model.hpp"
#include "frostmpm/models/tensor3.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class LinearElastic final : public MechanicalModel {
 public:
  static constexpr const char* kName = "linear_elastic";
  static constexpr const char* kDoc =
      "isotropic linear elasticity (Hooke, rate form); optional Young's modulus growing with ice saturation";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("youngs_modulus", "Pa", "Young's modulus E of the (unfrozen) skeleton").above(0).at_most(1e13);
    s.real("poisson_ratio", "-", "Poisson's ratio ν (−1 < ν < 0.5)").above(-1).below(0.5);
    s.real("frozen_youngs_modulus", "Pa",
           "Young's modulus at full ice saturation S_c = 1, interpolated linearly in S_c; 0: the same as "
           "youngs_modulus (no ice dependence)")
        .defaults_to(0.0)
        .at_least(0)
        .at_most(1e13);
    s.choice("modulus_change", {"increments", "elastic_strain"},
             "how a modulus that changes with the ice acts: on the strain increments only (rate form, paper "
             "Eq. 28), or on the elastic strain since the start (melting releases the stress the ice carried)")
        .defaults_to("increments");
    return s;
  }

  explicit LinearElastic(const ParamSet& p)
      : E_(p.real("youngs_modulus")),
        nu_(p.real("poisson_ratio")),
        E_frozen_(p.real("frozen_youngs_modulus")),
        secant_(p.string("modulus_change") == "elastic_strain") {
    if (E_frozen_ == 0) E_frozen_ = E_;
  }

  std::vector<InternalVariable> internal_variables() const override {
    if (!secant_) return {};
    return {{"modulus_of_last_step", "Pa"}};
  }

  void integrate(const StressUpdateInput& in, const StressUpdateOutput& out) const override {
    const std::size_t n = in.stress_start.size() / 6;
    const bool ice = !in.ice_saturation.empty();
    for (std::size_t p = 0; p < n; ++p) {
      const double E = ice ? modulus(in.ice_saturation[p]) : E_;
      const double G = E / (2.0 * (1.0 + nu_)), lambda = E * nu_ / ((1.0 + nu_) * (1.0 - 2.0 * nu_));
      const double* de = in.strain_increment.data() + 6 * p;
      const double* s0 = in.stress_start.data() + 6 * p;
      double* s = out.stress.data() + 6 * p;
      tensor3::add_isotropic_increment(lambda, G, de, s0, s);
      if (secant_) {
        // The modulus of the last step (0 before the first: no change yet).
        const double E_last = in.state_start[p] > 0 ? in.state_start[p] : E;
        for (int i = 0; i < 6; ++i) s[i] += (E / E_last - 1.0) * s0[i];
        out.state[p] = E;
      }
      if (!out.tangent.empty()) tensor3::isotropic_tangent(lambda, G, out.tangent.data() + 36 * p);
      if (!out.p_wave_modulus.empty()) out.p_wave_modulus[p] = lambda + 2.0 * G;
      if (!out.shear_modulus.empty()) out.shear_modulus[p] = G;
    }
  }

  double max_p_wave_modulus() const override {
    const double E = std::max(E_, E_frozen_);
    return E * (1.0 - nu_) / ((1.0 + nu_) * (1.0 - 2.0 * nu_));
  }

 private:
  double modulus(double ice_saturation) const { return E_ + (E_frozen_ - E_) * std::clamp(ice_saturation, 0.0, 1.0); }

  double E_, nu_, E_frozen_;
  bool secant_;
};

FROSTMPM_REGISTER(MechanicalModel, LinearElastic)

}  // namespace frostmpm
