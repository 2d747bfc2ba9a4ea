#include "mohr_coulomb_model.hpp"

#include "frostmpm/models/tensor3.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace frostmpm {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kMaxFriction = 80;  // degrees
/// The fixed point on the softening variable: iterations, and the change that ends them.
constexpr int kMaxIterations = 60;
constexpr double kRelativeChange = 1e-13, kAbsoluteChange = 1e-16;

}  // namespace

void MohrCoulombModel::declare(ParamSchema& s, bool ice) {
  s.real("youngs_modulus", "Pa", "Young's modulus E of the skeleton").above(0).at_most(1e13);
  // No auxetic soils: ν < 0 has no place in a Mohr–Coulomb soil, and near ν = −1 (K → 0) the
  // return's tangent loses its accuracy.
  s.real("poisson_ratio", "-", "Poisson's ratio ν (0 ≤ ν < 0.5)").at_least(0).below(0.5);
  s.real("cohesion", "Pa", "peak cohesion c′_p of the unfrozen soil").at_least(0).at_most(1e10);
  // Below 80°: no soil comes near, and as φ → 90° the cone degenerates (1 − sin φ → 0) and the
  // return loses its accuracy.
  s.real("friction_angle", "degree", "peak friction angle φ′_p of the unfrozen soil").at_least(0).below(kMaxFriction);
  s.real("dilation_angle", "degree", "peak dilation angle ψ′_p (at most φ′_p; 0: plastic flow keeps the volume)")
      .defaults_to(0.0)
      .at_least(0)
      .below(90);
  s.real("residual_cohesion", "Pa", "residual cohesion c′_res reached as the plastic deviatoric strain grows (Eq. 35)")
      .at_least(0)
      .at_most(1e10)
      .optional("the peak cohesion");
  s.real("residual_friction_angle", "degree", "residual friction angle φ′_res (Eq. 35)")
      .at_least(0)
      .below(kMaxFriction)
      .optional("the peak friction angle");
  s.real("residual_dilation_angle", "degree", "residual dilation angle ψ′_res (Eq. 35)")
      .at_least(0)
      .below(90)
      .optional("the peak dilation angle");
  s.real("softening_rate", "-",
         "η_s of Eq. 35: strength falls from peak to residual as exp(−η_s ε_p^d); 0: no softening")
      .defaults_to(0.0)
      .at_least(0)
      .at_most(1e4);
  s.real("tensile_strength", "Pa",
         "tension cut-off σ_t on the largest principal effective stress, capped at c cot φ of the point's current "
         "strength")
      .at_least(0)
      .at_most(1e10)
      .optional("c cot φ, the apex of the cone");
  if (!ice) return;
  s.real("max_ice_cohesion", "Pa", "Δc_max of Eq. 36: the cohesion ice bonding adds at most").at_least(0).at_most(1e10);
  s.real("max_ice_friction_angle", "degree", "Δφ_max of Eq. 36: the friction angle ice bonding adds at most")
      .defaults_to(0.0)
      .at_least(0)
      .below(kMaxFriction);
  s.real("max_ice_dilation_angle", "degree", "Δψ_max: the dilation angle ice bonding adds at most (at most Δφ_max)")
      .defaults_to(0.0)
      .at_least(0)
      .below(90);
  s.real("ice_bonding_rate", "-", "η_c of Eq. 36: Ψ_s = ΔΨ_max [1 − exp(−η_c s_c)]").above(0).at_most(1e4);
  s.real("lambda", "-", "λ of s_c = (S_l^(−1/λ) − 1)^(1−λ) (Eq. 37), the van Genuchten constant of the freezing curve")
      .above(0)
      .below(1)
      .optional("the lambda of the material's sfcc model");
}

MohrCoulombModel::MohrCoulombModel(const ParamSet& p, bool ice) : ice_(ice) {
  const double E = p.real("youngs_modulus"), nu = p.real("poisson_ratio");
  elastic_ = {E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))};
  const auto read = [&](const char* peak, const char* residual, double unit) {
    Parameter out;
    out.peak = p.real(peak) * unit;
    out.residual = p.has(residual) ? p.real(residual) * unit : out.peak;
    if (out.residual > out.peak)
      throw p.error(residual, std::string(residual) + " = " + number_text(p.real(residual)) + " is above the peak " +
                                  peak + " = " + number_text(p.real(peak)) + ": softening lowers the strength");
    return out;
  };
  cohesion_ = read("cohesion", "residual_cohesion", 1.0);
  friction_ = read("friction_angle", "residual_friction_angle", kDegree);
  dilation_ = read("dilation_angle", "residual_dilation_angle", kDegree);
  softening_rate_ = p.real("softening_rate");
  tension_ = p.has("tensile_strength") ? p.real("tensile_strength") : std::numeric_limits<double>::infinity();
  unbonded_ = mohr_coulomb::Strength::make(cohesion_.peak, friction_.peak, dilation_.peak, tension_);
  if (dilation_.peak > friction_.peak)
    throw p.error("dilation_angle", "dilation_angle = " + number_text(p.real("dilation_angle")) +
                                        " is above friction_angle = " + number_text(p.real("friction_angle")) +
                                        ": plastic flow would create energy; use ψ ≤ φ");
  if (dilation_.residual > friction_.residual)
    throw p.error(p.has("residual_dilation_angle") ? "residual_dilation_angle" : "residual_friction_angle",
                  "the residual dilation angle " + number_text(dilation_.residual / kDegree) +
                      " is above the residual friction angle " + number_text(friction_.residual / kDegree) +
                      ": use ψ ≤ φ");
  if (!ice) return;
  cohesion_.ice = p.real("max_ice_cohesion");
  friction_.ice = p.real("max_ice_friction_angle") * kDegree;
  dilation_.ice = p.real("max_ice_dilation_angle") * kDegree;
  bonding_rate_ = p.real("ice_bonding_rate");
  if (dilation_.ice > friction_.ice)
    throw p.error("max_ice_dilation_angle", "max_ice_dilation_angle = " +
                                                number_text(p.real("max_ice_dilation_angle")) +
                                                " is above max_ice_friction_angle = " +
                                                number_text(p.real("max_ice_friction_angle")) + ": use ψ ≤ φ");
  if (friction_.peak + friction_.ice >= kMaxFriction * kDegree)
    throw p.error("max_ice_friction_angle", "friction_angle + max_ice_friction_angle = " +
                                                number_text((friction_.peak + friction_.ice) / kDegree) +
                                                " degrees: the frozen friction angle must stay below " +
                                                number_text(kMaxFriction));
  if (!p.has("lambda"))
    throw p.section_error(
        "mohr_coulomb_ice needs λ for s_c (Eq. 37): give lambda here, or use a freezing curve with a lambda "
        "(sfcc: {model: van_genuchten_cc, ...}), which the model then reads");
  lambda_ = p.real("lambda");
}

std::vector<InternalVariable> MohrCoulombModel::internal_variables() const {
  return {{"plastic_deviatoric_strain", "1"}, {"plastic_volumetric_strain", "1"}, {"yielded", "1"},
          {"cohesion", "Pa"},
          {"friction_angle", "degree"},
          {"dilation_angle", "degree"}};
}

std::vector<double> MohrCoulombModel::initial_state() const {
  return {0.0, 0.0, 0.0, cohesion_.peak, friction_.peak / kDegree, dilation_.peak / kDegree};
}

double MohrCoulombModel::max_p_wave_modulus() const { return elastic_.K + 4.0 * elastic_.G / 3.0; }

double MohrCoulombModel::normalised_suction(double liquid_saturation) const {
  const double S_l = std::clamp(liquid_saturation, 0.0, 1.0);
  if (S_l >= 1) return 0;
  if (S_l <= 0) return std::numeric_limits<double>::infinity();
  return std::pow(std::pow(S_l, -1.0 / lambda_) - 1.0, 1.0 - lambda_);
}

mohr_coulomb::Strength MohrCoulombModel::strength(double plastic, double ice_saturation) const {
  const bool bonded = ice_ && ice_saturation > 0;
  if (!softens() && !bonded) return unbonded_;  // the peak strength, its sines computed once
  const double softening = std::exp(-softening_rate_ * plastic);
  const double bonding = bonded ? 1.0 - std::exp(-bonding_rate_ * normalised_suction(1.0 - ice_saturation)) : 0.0;
  return mohr_coulomb::Strength::make(cohesion_.at(softening, bonding), friction_.at(softening, bonding),
                                      dilation_.at(softening, bonding), tension_);
}

bool MohrCoulombModel::softens() const {
  return softening_rate_ > 0 && (cohesion_.residual < cohesion_.peak || friction_.residual < friction_.peak ||
                                 dilation_.residual < dilation_.peak);
}

mohr_coulomb::ReturnResult MohrCoulombModel::update_point(const double* trial, double plastic_start,
                                                          double ice_saturation, double* stress, double* tangent,
                                                          mohr_coulomb::Strength& used, bool& converged) const {
  const bool softening = softens();
  double plastic = plastic_start;
  mohr_coulomb::ReturnResult r;
  converged = false;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    used = strength(plastic, ice_saturation);
    r = mohr_coulomb::return_stress(trial, used, elastic_, stress, tangent);
    const double end = plastic_start + r.plastic_deviatoric;
    if (!softening || std::abs(end - plastic) <= kRelativeChange * end + kAbsoluteChange) {
      converged = true;
      break;
    }
    plastic = end;
  }
  if (converged && softening && tangent && r.kind != mohr_coulomb::ReturnKind::elastic)
    add_softening_tangent(trial, plastic, ice_saturation, stress, r, tangent);
  return r;
}

/// The softening's own term of the tangent. With σ = R(σ_tr, ε) at the step's end value
/// ε = ε0 + h(σ_tr, ε) of the softening variable, dσ/dΔε = D_ep + R_ε ⊗ dε/dΔε, where
/// dε/dΔε = (dh/dΔε at fixed strength) / (1 − h_ε). dh/dΔε follows from D_ep, since
/// Δε^p = C_e (σ_tr − σ); R_ε and h_ε are central differences in ε.
void MohrCoulombModel::add_softening_tangent(const double* trial, double plastic_end, double ice_saturation,
                                             const double* stress, const mohr_coulomb::ReturnResult& result,
                                             double* tangent) const {
  if (!(result.plastic_deviatoric > 0)) return;
  const double G = elastic_.G, K = elastic_.K;
  // Deviatoric plastic strain (tensor components) and dΔε^p/dΔε = I − C_e D_ep.
  double drop[6], dev[6];
  for (int k = 0; k < 6; ++k) drop[k] = trial[k] - stress[k];
  const double mean = (drop[0] + drop[1] + drop[2]) / 3;
  for (int k = 0; k < 6; ++k) dev[k] = (drop[k] - (k < 3 ? mean : 0.0)) / (2 * G);
  double slope[6];  // dh/dΔε_j at fixed strength
  for (int j = 0; j < 6; ++j) {
    // C_e applied to column j of D_ep: its deviatoric part / 2G plus its mean / (3K) on the diagonal.
    const double column_mean = (tangent[j] + tangent[6 + j] + tangent[12 + j]) / 3;
    double M[6];
    for (int k = 0; k < 6; ++k) {
      const double ce = (tangent[6 * k + j] - (k < 3 ? column_mean : 0.0)) / (2 * G) + (k < 3 ? column_mean / (3 * K) : 0.0);
      M[k] = (k == j ? 1.0 : 0.0) - ce;
    }
    const double M_mean = (M[0] + M[1] + M[2]) / 3;
    double sum = 0;
    for (int k = 0; k < 6; ++k) sum += (k < 3 ? 1.0 : 2.0) * dev[k] * (M[k] - (k < 3 ? M_mean : 0.0));
    slope[j] = 2.0 / 3.0 * sum / result.plastic_deviatoric;
  }
  const double delta = 1e-5 / softening_rate_;
  double plus[6], minus[6];
  const auto hp = mohr_coulomb::return_stress(trial, strength(plastic_end + delta, ice_saturation), elastic_, plus, nullptr);
  const auto hm = mohr_coulomb::return_stress(trial, strength(plastic_end - delta, ice_saturation), elastic_, minus, nullptr);
  const double h_eps = (hp.plastic_deviatoric - hm.plastic_deviatoric) / (2 * delta);
  for (int i = 0; i < 6; ++i) {
    const double R_eps = (plus[i] - minus[i]) / (2 * delta);
    for (int j = 0; j < 6; ++j) tangent[6 * i + j] += R_eps * slope[j] / (1 - h_eps);
  }
}

void MohrCoulombModel::integrate(const StressUpdateInput& in, const StressUpdateOutput& out) const {
  const std::size_t n = in.stress_start.size() / 6;
  const bool ice_given = ice_ && !in.ice_saturation.empty();
  const double G = elastic_.G, lambda = elastic_.lambda();
  for (std::size_t p = 0; p < n; ++p) {
    const double* start = in.state_start.data() + kCount * p;
    double trial[6];
    tensor3::add_isotropic_increment(lambda, G, in.strain_increment.data() + 6 * p, in.stress_start.data() + 6 * p,
                                     trial);
    mohr_coulomb::Strength used;
    bool converged = false;
    const auto r = update_point(trial, start[kPlasticDeviatoric], ice_given ? in.ice_saturation[p] : -1.0,
                                out.stress.data() + 6 * p, out.tangent.empty() ? nullptr : out.tangent.data() + 36 * p,
                                used, converged);
    if (!converged || r.kind == mohr_coulomb::ReturnKind::failed) out.failed[p] = 1;
    double* state = out.state.data() + kCount * p;
    state[kPlasticDeviatoric] = start[kPlasticDeviatoric] + r.plastic_deviatoric;
    state[kPlasticVolumetric] = start[kPlasticVolumetric] + r.plastic_volumetric;
    state[kYielded] = r.kind == mohr_coulomb::ReturnKind::elastic ? 0.0 : 1.0;
    state[kCohesion] = used.cohesion;
    state[kFriction] = used.friction / kDegree;
    state[kDilation] = used.dilation / kDegree;
    // The stable step and the pressure stabilization use the elastic moduli (the plastic tangent is softer).
    if (!out.p_wave_modulus.empty()) out.p_wave_modulus[p] = elastic_.K + 4 * G / 3;
    if (!out.shear_modulus.empty()) out.shear_modulus[p] = G;
  }
}

bool MohrCoulombModel::yield_function(std::span<const double> stress, std::span<const double> state,
                                      std::span<double> value) const {
  for (std::size_t p = 0; p < value.size(); ++p) {
    const double* v = state.data() + kCount * p;
    const auto s = mohr_coulomb::Strength::make(v[kCohesion], v[kFriction] * kDegree, v[kDilation] * kDegree, tension_);
    value[p] = mohr_coulomb::yield_value_of_stress(stress.data() + 6 * p, s);
  }
  return true;
}

// ---- the two registered names: one model, with and without the ice terms ----------------------

namespace {

template <class Names, bool Ice>
class Registered final : public MohrCoulombModel {
 public:
  static constexpr const char* kName = Names::kName;
  static constexpr const char* kDoc = Names::kDoc;
  static ParamSchema schema() {
    ParamSchema s;
    declare(s, Ice);
    return s;
  }
  explicit Registered(const ParamSet& p) : MohrCoulombModel(p, Ice) {}
};

struct PlainNames {
  static constexpr const char* kName = "mohr_coulomb";
  static constexpr const char* kDoc =
      "Mohr–Coulomb elastoplasticity (c, φ, ψ, softening, tension cut-off), return in principal stresses";
};
struct IceNames {
  static constexpr const char* kName = "mohr_coulomb_ice";
  static constexpr const char* kDoc =
      "Mohr–Coulomb whose cohesion, friction and dilation grow with ice saturation (paper Eqs. 30–37)";
};
using MohrCoulomb = Registered<PlainNames, false>;
using MohrCoulombIce = Registered<IceNames, true>;

}  // namespace

FROSTMPM_REGISTER(MechanicalModel, MohrCoulomb)
FROSTMPM_REGISTER(MechanicalModel, MohrCoulombIce)

}  // namespace frostmpm
