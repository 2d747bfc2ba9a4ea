// A third-party constitutive model of the soil skeleton: isotropic hypoelasticity whose
// Young's modulus grows as the ground cools below freezing,
//   Δσ′ = λ(T) tr(Δε) I + 2G(T) Δε,
//   E(T) = E_t                                   for T ≥ T_f,
//        = E_t + (E_f − E_t) min((T_f − T)/ΔT, 1) below,  ν fixed,
// and one internal variable, the accumulated deviatoric strain Σ √(2/3 Δe:Δe) (Δe the
// deviatoric part of Δε), to show how a model carries state.
//
// Conventions of every mechanical_model (<frostmpm/models/mechanical_model.hpp>): effective
// stress, tension positive; 6 Voigt components xx, yy, zz, yz, xz, xy with tensor (not
// engineering) shear strains, so σ_xy = 2G ε_xy; the tangent is ∂σ′/∂Δε in that order,
// 6×6 row-major. The mechanics hands over the step-start stress already rotated (Jaumann), so
// a model only adds the increment.
#include <algorithm>
#include <cmath>

#include <frostmpm/models/mechanical_model.hpp>
#include <frostmpm/plugin/plugin_api.hpp>

namespace my_lab {

class TemperatureElastic final : public frostmpm::MechanicalModel {
 public:
  static constexpr const char* kName = "temperature_elastic";
  static constexpr const char* kDoc = "isotropic hypoelasticity, Young's modulus rising linearly below freezing";

  // Bounded ranges matter: `frostmpm test-model` checks the contract at 1 % and 99 % of each one.
  static frostmpm::ParamSchema schema() {
    frostmpm::ParamSchema s;
    s.real("thawed_youngs_modulus", "Pa", "E_t: Young's modulus at and above the freezing point")
        .above(0)
        .at_most(1e11);
    s.real("frozen_youngs_modulus", "Pa", "E_f: Young's modulus at T_f - dT and colder").above(0).at_most(1e11);
    s.real("poisson_ratio", "-", "Poisson's ratio").above(-1).below(0.5);
    s.real("freezing_point", "degC", "T_f: the modulus starts to rise below it")
        .defaults_to(0.0)
        .at_least(-10)
        .at_most(10);
    s.real("stiffening_range", "K", "dT: the modulus reaches E_f at T_f - dT")
        .defaults_to(10.0)
        .above(0)
        .at_most(100);
    return s;
  }

  explicit TemperatureElastic(const frostmpm::ParamSet& p)
      : thawed_(p.real("thawed_youngs_modulus")),
        frozen_(p.real("frozen_youngs_modulus")),
        nu_(p.real("poisson_ratio")),
        freezing_point_(p.real("freezing_point")),
        range_(p.real("stiffening_range")) {}

  // One scalar per particle each, written to fields.h5 under this name with this unit.
  std::vector<frostmpm::InternalVariable> internal_variables() const override {
    return {{"accumulated_shear_strain", "1"}};
  }
  std::vector<double> initial_state() const override { return {0.0}; }

  // One call per batch of particles of one material; spans hold n points (× 6 for tensors,
  // × 1 for our one internal variable). The temperature is empty when the scene has no
  // thermal physics: then the ground counts as thawed.
  void integrate(const frostmpm::StressUpdateInput& in, const frostmpm::StressUpdateOutput& out) const override {
    const std::size_t n = in.stress_start.size() / 6;
    for (std::size_t p = 0; p < n; ++p) {
      const double E = modulus(in.temperature.empty() ? freezing_point_ : in.temperature[p]);
      const double G = E / (2 * (1 + nu_)), lambda = E * nu_ / ((1 + nu_) * (1 - 2 * nu_));
      const double* de = in.strain_increment.data() + 6 * p;
      const double* s0 = in.stress_start.data() + 6 * p;
      double* s = out.stress.data() + 6 * p;
      const double trace = de[0] + de[1] + de[2];
      for (int i = 0; i < 3; ++i) s[i] = s0[i] + lambda * trace + 2 * G * de[i];
      for (int i = 3; i < 6; ++i) s[i] = s0[i] + 2 * G * de[i];

      // Δe:Δe counts each shear component twice (the tensor is symmetric).
      double dev2 = 0;
      for (int i = 0; i < 3; ++i) dev2 += (de[i] - trace / 3) * (de[i] - trace / 3);
      for (int i = 3; i < 6; ++i) dev2 += 2 * de[i] * de[i];
      out.state[p] = in.state_start[p] + std::sqrt(2.0 / 3.0 * dev2);

      // Optional outputs: fill each one the caller asked for (a non-empty span).
      if (!out.tangent.empty()) {
        double* D = out.tangent.data() + 36 * p;
        std::fill(D, D + 36, 0.0);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) D[6 * i + j] = lambda;
        for (int i = 0; i < 6; ++i) D[6 * i + i] += 2 * G;
      }
      if (!out.p_wave_modulus.empty()) out.p_wave_modulus[p] = lambda + 2 * G;  // K + 4G/3: the stable step
      if (!out.shear_modulus.empty()) out.shear_modulus[p] = G;
      // A point that cannot be integrated (a return mapping that does not converge, say) sets
      // out.failed[p] = 1 instead of throwing: the mechanics then stops naming the particle.
    }
  }

  // Bounds the stable step before the first update: the stiffer of the two moduli.
  double max_p_wave_modulus() const override {
    const double E = std::max(thawed_, frozen_);
    return E * (1 - nu_) / ((1 + nu_) * (1 - 2 * nu_));
  }

 private:
  double modulus(double T) const {
    const double frozen_fraction = std::clamp((freezing_point_ - T) / range_, 0.0, 1.0);
    return thawed_ + (frozen_ - thawed_) * frozen_fraction;
  }

  double thawed_, frozen_, nu_, freezing_point_, range_;
};

FROSTMPM_REGISTER(frostmpm::MechanicalModel, TemperatureElastic)

}  // namespace my_lab

FROSTMPM_PLUGIN("my-lab-constitutive", "1.0.0")
