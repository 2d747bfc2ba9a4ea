// A third-party plasticity model of the soil skeleton: Drucker–Prager with perfect plasticity,
// built outside FrostMPM against the installed SDK only.
//
//   elasticity   Δσ′ = K tr(Δε) I + 2G dev(Δε)            (isotropic, rate form)
//   yield        F = √J2 + α σ_m − k ≤ 0,                  σ_m = tr σ′/3, s = σ′ − σ_m I, J2 = ½ s:s
//   flow         Δε^p = Δγ ∂Q/∂σ′,  Q = √J2 + β σ_m        (β = α: associated)
//
// Stress is tension positive in FrostMPM, so σ_m < 0 in compression and the cone widens with
// confinement: F = √J2 − α p − k with the pressure p = −σ_m. Its apex lies in tension, at
// σ_m = k/α.
//
// The parameters are those of Mohr–Coulomb (c, φ, ψ), matched in PLANE STRAIN:
//   α = 3 tan φ / √(9 + 12 tan²φ),  k = 3c / √(9 + 12 tan²φ),  β = 3 tan ψ / √(9 + 12 tan²ψ).
// Why: in plane strain ε_zz^p = 0, i.e. ∂Q/∂σ_zz = 0, which fixes s_zz = −(2β/3)√J2; then
// √J2 = t/√(1 − β²/3) and σ_m = σ_c − (β/3)√J2, with t = √(((σ_xx − σ_yy)/2)² + σ_xy²) the
// radius and σ_c = (σ_xx + σ_yy)/2 the centre of the in-plane Mohr circle. F = 0 becomes
//   t + σ_c · α√(1 − β²/3)/(1 − αβ/3) = k√(1 − β²/3)/(1 − αβ/3),
// Mohr–Coulomb's t + σ_c sin φ = c cos φ when β = α and the α, k above (then
// α/√(1 − α²/3) = sin φ and k/√(1 − α²/3) = c cos φ). With β ≠ α (ψ < φ) the plane-strain
// strength is lower than Mohr–Coulomb's: sin φ_ps = α√(1 − β²/3)/(1 − αβ/3) < sin φ.
//
// Conventions of every mechanical_model (<frostmpm/models/mechanical_model.hpp>): effective
// stress, tension positive; 6 Voigt components xx, yy, zz, yz, xz, xy with tensor (not
// engineering) shear strains; the tangent is ∂σ′/∂Δε in that order, 6×6 row-major. The
// mechanics hands over the step-start stress already rotated (Jaumann).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <frostmpm/models/mechanical_model.hpp>
#include <frostmpm/plugin/plugin_api.hpp>

namespace my_lab {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
// A double contraction A:B of symmetric tensors in Voigt order counts each shear component twice.
constexpr double kWeight[6] = {1, 1, 1, 2, 2, 2};

/// The plane-strain Drucker–Prager slope of a Mohr–Coulomb angle (α of φ, β of ψ).
double plane_strain_slope(double angle) {
  const double t = std::tan(angle);
  return 3 * t / std::sqrt(9 + 12 * t * t);
}

}  // namespace

class DruckerPrager final : public frostmpm::MechanicalModel {
 public:
  static constexpr const char* kName = "drucker_prager";
  static constexpr const char* kDoc =
      "Drucker–Prager perfect plasticity with Mohr–Coulomb c, φ, ψ matched in plane strain; closed-form radial return";

  // Bounded ranges matter: `frostmpm test-model` checks the contract at 1 % and 99 % of each one.
  static frostmpm::ParamSchema schema() {
    frostmpm::ParamSchema s;
    s.real("youngs_modulus", "Pa", "Young's modulus E").above(0).at_most(1e11);
    s.real("poisson_ratio", "-", "Poisson's ratio ν (0 ≤ ν < 0.5)").at_least(0).below(0.5);
    s.real("cohesion", "Pa", "Mohr–Coulomb cohesion c (frozen soil: up to a few MPa)").at_least(0).at_most(1e7);
    // Below 80°: the cone stays well shaped (α < 0.86).
    s.real("friction_angle", "degree", "Mohr–Coulomb friction angle φ").at_least(0).below(80);
    s.real("dilation_angle", "degree", "Mohr–Coulomb dilation angle ψ ≤ φ (ψ = φ: associated flow; 0: no plastic volume change)")
        .defaults_to(0.0)
        .at_least(0)
        .below(80);
    return s;
  }

  explicit DruckerPrager(const frostmpm::ParamSet& p) {
    const double E = p.real("youngs_modulus"), nu = p.real("poisson_ratio");
    K_ = E / (3 * (1 - 2 * nu));
    G_ = E / (2 * (1 + nu));
    const double phi = p.real("friction_angle") * kDegree, psi = p.real("dilation_angle") * kDegree;
    // A cross-parameter check: throw the parameter's own error, so the scene names the line.
    if (psi > phi)
      throw p.error("dilation_angle", "dilation_angle = " + frostmpm::number_text(p.real("dilation_angle")) +
                                          " is above friction_angle = " +
                                          frostmpm::number_text(p.real("friction_angle")) +
                                          ": plastic flow would create energy; use ψ ≤ φ");
    alpha_ = plane_strain_slope(phi);
    beta_ = plane_strain_slope(psi);
    const double t = std::tan(phi);
    k_ = 3 * p.real("cohesion") / std::sqrt(9 + 12 * t * t);
  }

  // One scalar per particle each, written to fields.h5 under this name with this unit.
  std::vector<frostmpm::InternalVariable> internal_variables() const override {
    return {{"plastic_shear_strain", "1"}, {"plastic_volumetric_strain", "1"}, {"yielded", "1"}};
  }

  void integrate(const frostmpm::StressUpdateInput& in, const frostmpm::StressUpdateOutput& out) const override {
    const std::size_t n = in.stress_start.size() / 6;
    const double lambda = K_ - 2 * G_ / 3;
    for (std::size_t p = 0; p < n; ++p) {
      const double* de = in.strain_increment.data() + 6 * p;
      const double* s0 = in.stress_start.data() + 6 * p;
      const double* state0 = in.state_start.data() + kCount * p;
      double* s = out.stress.data() + 6 * p;
      double* state = out.state.data() + kCount * p;

      // 1. Elastic trial stress, split into mean stress and deviator.
      double trial[6], dev[6];
      const double volumetric = de[0] + de[1] + de[2];
      for (int i = 0; i < 6; ++i) trial[i] = s0[i] + (i < 3 ? lambda * volumetric : 0.0) + 2 * G_ * de[i];
      const double mean = (trial[0] + trial[1] + trial[2]) / 3;
      double J2 = 0;
      for (int i = 0; i < 6; ++i) {
        dev[i] = trial[i] - (i < 3 ? mean : 0.0);
        J2 += 0.5 * kWeight[i] * dev[i] * dev[i];
      }
      const double J = std::sqrt(J2), F = J + alpha_ * mean - k_;
      if (!std::isfinite(F)) out.failed[p] = 1;  // a broken input: let the mechanics name the particle

      // 2. Return mapping. The flow direction ∂Q/∂σ′ = s/(2√J2) + β/3 I keeps the deviator's
      // direction, so √J2 = √J2_tr − GΔγ and σ_m = σ_m,tr − KβΔγ, and F = 0 is linear in Δγ:
      //   Δγ = F_tr / (G + αβK).
      enum class Branch { elastic, cone, apex } branch = Branch::elastic;
      double gamma = 0, shear_strain = 0, volume_strain = 0;
      if (F > 0) {
        gamma = F / (G_ + alpha_ * beta_ * K_);
        // A cone return that would carry √J2 past zero (the deviator reverses) has overshot the
        // apex: the stress goes to the apex itself. Only a cone with α > 0 has one; with α = 0
        // (von Mises) J > k ≥ 0, so the cone return is always valid.
        branch = alpha_ > 0 && J - G_ * gamma < 0 ? Branch::apex : Branch::cone;
      }
      const double factor = branch == Branch::cone ? 1 - G_ * gamma / J : 0.0;  // J > 0 on the cone
      switch (branch) {
        case Branch::elastic:
          std::copy(trial, trial + 6, s);
          break;
        case Branch::cone:
          for (int i = 0; i < 6; ++i) s[i] = factor * dev[i] + (i < 3 ? mean - K_ * beta_ * gamma : 0.0);
          // Δe^p = Δγ s/(2√J2) has √(2/3 Δe^p:Δe^p) = Δγ/√3; Δε_v^p = βΔγ (> 0: dilation).
          shear_strain = gamma / std::sqrt(3.0);
          volume_strain = beta_ * gamma;
          break;
        case Branch::apex:
          for (int i = 0; i < 6; ++i) s[i] = i < 3 ? k_ / alpha_ : 0.0;
          // The whole trial deviator is plastic, and whatever volume change the apex's mean
          // stress does not take up elastically.
          shear_strain = J / (std::sqrt(3.0) * G_);
          volume_strain = (mean - k_ / alpha_) / K_;
          break;
      }
      state[kPlasticShear] = state0[kPlasticShear] + shear_strain;
      state[kPlasticVolumetric] = state0[kPlasticVolumetric] + volume_strain;
      state[kYielded] = branch == Branch::elastic ? 0.0 : 1.0;

      // 3. The consistent tangent ∂σ′/∂Δε of this return (an implicit solver's Newton converges
      // quadratically with it). Optional: fill it only when the caller asks.
      if (!out.tangent.empty()) {
        double* D = out.tangent.data() + 36 * p;
        std::fill(D, D + 36, 0.0);
        if (branch == Branch::elastic) {
          for (int a = 0; a < 6; ++a)
            for (int j = 0; j < 6; ++j) D[6 * a + j] = (a < 3 && j < 3 ? lambda : 0.0) + (a == j ? 2 * G_ : 0.0);
        } else if (branch == Branch::cone) {
          // With n = s_tr/|s_tr| (unit), I_d the deviatoric projector and H = G + αβK:
          //   D = 2G f (I_d − n⊗n) + 2G n⊗n + K I⊗I − (√2G n + Kβ I) ⊗ (√2G n + Kα I) / H,
          // f = 1 − GΔγ/√J2_tr: the deviator's length follows Δγ, its direction turns with the
          // trial deviator. Symmetric for associated flow. A column j multiplies Δε_j, so terms
          // ⊗ n pick up the shear weight (n:Δε counts shear twice).
          const double norm = std::sqrt(2.0) * J, H = G_ + alpha_ * beta_ * K_;
          double unit[6];
          for (int i = 0; i < 6; ++i) unit[i] = dev[i] / norm;
          for (int a = 0; a < 6; ++a)
            for (int j = 0; j < 6; ++j) {
              const double deviatoric = (a == j ? 1.0 : 0.0) - (a < 3 && j < 3 ? 1.0 / 3 : 0.0);
              const double nn = unit[a] * unit[j] * kWeight[j];
              const double left = std::sqrt(2.0) * G_ * unit[a] + (a < 3 ? K_ * beta_ : 0.0);
              const double right = (std::sqrt(2.0) * G_ * unit[j] + (j < 3 ? K_ * alpha_ : 0.0)) * (j < 3 ? 1.0 : 2.0);
              D[6 * a + j] = 2 * G_ * factor * (deviatoric - nn) + 2 * G_ * nn + (a < 3 && j < 3 ? K_ : 0.0) -
                             left * right / H;
            }
        }
        // At the apex the stress is fixed whatever the strain: D = 0 (perfect plasticity).
      }
      // The stable step and the pressure stabilization use the elastic moduli (the plastic tangent is softer).
      if (!out.p_wave_modulus.empty()) out.p_wave_modulus[p] = K_ + 4 * G_ / 3;
      if (!out.shear_modulus.empty()) out.shear_modulus[p] = G_;
    }
  }

  // `frostmpm test-model` checks that every stress integrate() returns has F ≤ 0 (to round-off).
  bool yield_function(std::span<const double> stress, std::span<const double> /*state*/,
                      std::span<double> value) const override {
    for (std::size_t p = 0; p < value.size(); ++p) {
      const double* s = stress.data() + 6 * p;
      const double mean = (s[0] + s[1] + s[2]) / 3;
      double J2 = 0;
      for (int i = 0; i < 6; ++i) {
        const double d = s[i] - (i < 3 ? mean : 0.0);
        J2 += 0.5 * kWeight[i] * d * d;
      }
      value[p] = std::sqrt(J2) + alpha_ * mean - k_;
    }
    return true;
  }

  double max_p_wave_modulus() const override { return K_ + 4 * G_ / 3; }

 private:
  enum Variable : std::size_t { kPlasticShear, kPlasticVolumetric, kYielded, kCount };
  double K_ = 0, G_ = 0;                // bulk and shear moduli
  double alpha_ = 0, beta_ = 0, k_ = 0;  // yield slope, flow slope, yield √J2 at σ_m = 0
};

FROSTMPM_REGISTER(frostmpm::MechanicalModel, DruckerPrager)

}  // namespace my_lab

FROSTMPM_PLUGIN("my-lab-drucker-prager", "1.0.0")
