#pragma once
// The elastoplastic Mohr–Coulomb skeleton of the paper (Sec. 3.3, Eqs. 30–37), registered twice
// (end of mohr_coulomb_model.cpp): `mohr_coulomb` without the ice terms, `mohr_coulomb_ice` with them.
//
// Strength Ψ ∈ {c, φ, ψ} at a point (Eqs. 34–37):
//   Ψ = Ψ′ + Ψ_s,  Ψ′ = Ψ′_res + (Ψ′_p − Ψ′_res) exp(−η_s ε_p^d)          (softening, Eq. 35)
//   Ψ_s = ΔΨ_max [1 − exp(−η_c s_c)],  s_c = (S_l^{−1/λ} − 1)^{1−λ}, S_l = 1 − S_c  (ice, Eqs. 36–37)
// s_c is the normalised cryo-suction of the van Genuchten freezing curve read backwards, so the
// ice strength follows the ice saturation of this step, from the first step on, whether or not
// the point has yielded. ε_p^d = Σ √(2/3 Δe^p:Δe^p) accumulates the deviatoric plastic strain.
// The paper applies Eq. 35 to c and φ; ψ softens and grows with ice the same way here, so ψ ≤ φ
// holds at every strain and ice saturation when it holds for the peak, residual and ice values.
//
// The strength is implicit in the softening variable: the return is repeated with the strength
// at the step's end value of ε_p^d until that value no longer changes (a fixed point; it
// converges when the softening modulus is small against the shear modulus, which a point that
// does not snap back needs). So a returned stress lies on the surface its own internal variables
// describe, and a zero strain increment leaves it there.
#include <vector>

#include "frostmpm/models/mechanical_model.hpp"
#include "mohr_coulomb_return.hpp"

namespace frostmpm {

class MohrCoulombModel : public MechanicalModel {
 public:
  /// The parameters of both models; `ice` adds those of the ice terms.
  static void declare(ParamSchema& s, bool ice);
  MohrCoulombModel(const ParamSet& p, bool ice);

  std::vector<InternalVariable> internal_variables() const override;
  std::vector<double> initial_state() const override;
  void integrate(const StressUpdateInput& in, const StressUpdateOutput& out) const override;
  bool yield_function(std::span<const double> stress, std::span<const double> state,
                      std::span<double> value) const override;
  double max_p_wave_modulus() const override;

 private:
  /// c, φ, ψ after plastic deviatoric strain `plastic` at ice saturation S_c (< 0: none given).
  mohr_coulomb::Strength strength(double plastic, double ice_saturation) const;
  /// s_c of Eq. 37 at liquid saturation S_l (0 when thawed, +∞ when no liquid is left).
  double normalised_suction(double liquid_saturation) const;

  /// A strength that softens from its peak to its residual value (Eq. 35) and grows with ice (Eq. 36).
  struct Parameter {
    double peak = 0, residual = 0, ice = 0;
    double at(double softening, double bonding) const { return residual + (peak - residual) * softening + ice * bonding; }
  };
  enum Variable : std::size_t { kPlasticDeviatoric, kPlasticVolumetric, kYielded, kCohesion, kFriction, kDilation, kCount };
  mohr_coulomb::ReturnResult update_point(const double* trial, double plastic_start, double ice_saturation,
                                          double* stress, double* tangent, mohr_coulomb::Strength& used,
                                          bool& converged) const;
  void add_softening_tangent(const double* trial, double plastic_end, double ice_saturation, const double* stress,
                             const mohr_coulomb::ReturnResult& result, double* tangent) const;

  bool softens() const;

  mohr_coulomb::Elasticity elastic_;
  mohr_coulomb::Strength unbonded_;  ///< the peak strength without ice
  Parameter cohesion_, friction_, dilation_;  // angles in radians
  double softening_rate_ = 0, tension_ = 0;
  bool ice_ = false;
  double bonding_rate_ = 0, lambda_ = 0;
};

}  // namespace frostmpm
