#pragma once
// The two-phase momentum balance of the fractional step (paper Sec. 4.1, Eqs. 43–49), per unit
// volume at a material point, in one place. The hydraulic physics takes the liquid's
// coefficients from here (liquid_response: ξ and the drag stiffness k it hands the mechanical
// physics as particle fields; corrector_mobility of a rigid skeleton: the liquid's own response
// n_l/(m_l + Δt C_d)); the mechanical physics only reads those fields, so neither repeats the
// other's formulas. With a moving skeleton the skeleton's response to Δp enters the pressure
// matrix at the nodes (HydraulicPhysics::assemble_skeleton) rather than through the per-point
// λ_s below, whose closed forms and limits the unit tests state. Inputs are inertias per unit
// volume — the skeleton's m_s = n_s ρ_s + n_c ρ_c and the liquid's m_l = n_l ρ_l, both times any
// mass scaling — the drag coefficient C_d = n_l² ρ_l g / (K k_r) (Eq. 9) and the step Δt;
// D = Δt C_d.
//
// Predictor (Eq. 43). With the drag implicit, the liquid's own predictor is
//   v_l* = ξ ṽ_l + (1 − ξ) v_s*,  ξ = m_l / (m_l + D),  ṽ_l = v_l + Δt f_l / m_l,
// f_l = −n_l ∇p + m_l b; so the skeleton feels the drag k (ṽ_l − v_s*) with the stiffness
// k = C_d ξ. Undrained (D → ∞): k → m_l/Δt, the water moves with the skeleton.
//
// Corrector (Eqs. 44–47). The phase-wise corrector, solid m_s a_s = −n_sc ∇Δp + D (a_l − a_s),
// liquid m_l a_l = −n_l ∇Δp − D (a_l − a_s), solved for the accelerations gives
//   a_s = −λ_s ∇Δp,  λ_s = (n_sc m_l + D) / (m_s m_l + D ρ_m) = ξ_s n_sc / m_s,
//   a_l = −λ_l ∇Δp,  λ_l = (n_l m_s + D) / (m_s m_l + D ρ_m) = ξ_l n_l / m_l,
// with ρ_m = m_s + m_l, n_sc = 1 − n_l and
//   ξ_s = [m_l m_s + D m_s/n_sc] / [m_l m_s + D ρ_m],  ξ_l = [m_l m_s + D m_l/n_l] / [m_l m_s + D ρ_m].
// The paper's Eq. 46 prints these with the volume fractions multiplying where they divide;
// this is the form that solves its own Eq. 44 (and the form of the authors' public code).
// Limits: D → 0: a_s = −n_sc ∇Δp/m_s, a_l = −∇Δp/ρ_l; D → ∞: a_s = a_l = −∇Δp/ρ_m;
// m_s → ∞ (a rigid skeleton): λ_s → 0, λ_l → n_l/(m_l + D). Also λ_s = (1 − n_l ξ)/(m_s + Δt k):
// the skeleton, dragging k, takes the share 1 − n_l ξ of the pressure gradient.
//
// The paper's compact pressure coefficient (Eq. 49, η = n_l λ_l + (n_sc − ζ n_c) λ_s) is not used:
// the pressure matrix is assembled from the liquid's mobility and, at the nodes, the skeleton's
// (HydraulicPhysics::assemble, assemble_skeleton), with the skeleton's volume term of Eq. 6.
#include <cmath>

namespace frostmpm::two_phase {

/// The liquid's implicit response to the drag in the predictor.
struct LiquidResponse {
  double xi = 0;              ///< ξ = m_l / (m_l + Δt C_d): the liquid's own share of its momentum
  double drag_stiffness = 0;  ///< k = C_d ξ [kg/m³/s]: the drag on the skeleton per unit velocity difference
};

inline LiquidResponse liquid_response(double m_l, double drag, double dt) {
  // No liquid: no momentum of its own (ξ = 0, it moves with the skeleton) and no drag.
  if (!(m_l > 0)) return {0.0, 0.0};
  const double xi = m_l / (m_l + dt * drag);
  return {xi, drag * xi};
}

/// Velocity change per unit pressure-increment gradient and per unit Δt, of each phase.
struct Mobility {
  double liquid = 0;  ///< λ_l = ξ_l n_l / m_l [m³/kg]
  double solid = 0;   ///< λ_s = ξ_s n_sc / m_s [m³/kg]
};

/// The corrector of a skeleton of inertia m_s (m_s ≤ 0 or infinite: rigid, λ_s = 0).
inline Mobility corrector_mobility(double m_s, double m_l, double n_l, double drag, double dt) {
  const double D = dt * drag;
  if (!(m_s > 0) || std::isinf(m_s)) {
    const double denominator = m_l + D;
    return {denominator > 0 ? n_l / denominator : 0.0, 0.0};
  }
  const double denominator = m_s * m_l + D * (m_s + m_l);
  if (denominator <= 0) return {0.0, (1.0 - n_l) / m_s};  // no liquid, no drag: a dry skeleton
  return {(n_l * m_s + D) / denominator, ((1.0 - n_l) * m_l + D) / denominator};
}

/// ξ_s and ξ_l themselves (Eq. 46 corrected), for tests and output.
struct CorrectorFactors {
  double xi_s = 1, xi_l = 1;
};
inline CorrectorFactors corrector_factors(double m_s, double m_l, double n_l, double drag, double dt) {
  const double D = dt * drag, denominator = m_l * m_s + D * (m_s + m_l);
  if (denominator <= 0) return {};
  return {(m_l * m_s + D * m_s / (1.0 - n_l)) / denominator, (m_l * m_s + D * m_l / n_l) / denominator};
}

}  // namespace frostmpm::two_phase
