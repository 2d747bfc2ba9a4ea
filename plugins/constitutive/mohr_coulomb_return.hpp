#pragma once
// Mohr–Coulomb plasticity with a tension cut-off, returned in principal stresses (de Souza Neto,
// Perić & Owen 2008, Computational Methods for Plasticity, Sec. 8.2.2 and Box 8.5; Clausen,
// Damkilde & Andersen 2007, Comput. Struct. 85:1795). Tension positive; principal stresses
// ordered σ1 ≥ σ2 ≥ σ3, so σ1 is the least compressive.
//
// In the sextant σ1 ≥ σ2 ≥ σ3 the Mohr–Coulomb hexagon is the plane
//   F = (σ1 − σ3) + (σ1 + σ3) sin φ − 2c cos φ ≤ 0,
// which is the paper's Eq. 30 with Eq. 32 (R_mc q + p tan φ − c, multiplied by 2 cos φ) written
// with ordered principal stresses instead of q and the Lode angle. The flow potential has the same
// form with the dilation angle ψ. The tension cut-off is σ_i ≤ σ_t, with σ_t ≤ c cot φ (the apex).
//
// With an isotropic elastic law the return keeps the principal directions, and each yield plane
// is linear in the principal stresses. A return is therefore a small linear solve for the
// plastic multipliers of an active set of planes. The sets are tried in a fixed order: the main
// plane, the two edges, then the tension planes and their corners with the cone. The first set
// with multipliers ≥ 0 that leaves every plane ≤ 0 wins. The apex (hydrostatic at c cot φ, or at
// σ_t) is the last resort, and it is reached in one step without the Lode angle, which is
// undefined there. The Eq. 31 potential of the paper rounds the hexagon only so that a
// return in invariants has a flow direction at the edges and the apex; the principal-stress
// return has one at each exactly, so the potential here is the hexagon of ψ.
#include <array>
#include <cstdint>
#include <limits>

namespace frostmpm::mohr_coulomb {

/// The strength at one material point (make() fills the sines and cosines once).
struct Strength {
  double cohesion = 0;   ///< c [Pa]
  double friction = 0;   ///< φ [rad], 0 ≤ φ < π/2
  double dilation = 0;   ///< ψ [rad], 0 ≤ ψ ≤ φ
  double tension = std::numeric_limits<double>::infinity();  ///< cut-off σ_t [Pa]; above c cot φ it changes nothing
  double sin_friction = 0, cos_friction = 1, sin_dilation = 0;

  static Strength make(double cohesion, double friction, double dilation, double tension);

  /// c cot φ: where the cone meets the hydrostatic axis (+∞ for φ = 0, Tresca).
  double apex() const;
  /// The cut-off that acts: min(σ_t, c cot φ).
  double tension_cutoff() const;
};

/// Isotropic elasticity: bulk and shear modulus [Pa].
struct Elasticity {
  double K = 0, G = 0;
  double lambda() const { return K - 2.0 * G / 3.0; }
};

enum class ReturnKind : std::uint8_t { elastic, plane, edge, tension, cone_and_tension, apex, failed };

/// The yield function: the largest of the three Mohr–Coulomb planes of the sextant and the
/// cut-off σ1 − σ_t, for principal stresses in any order [Pa]; ≤ 0 is admissible.
double yield_value(std::array<double, 3> principal, const Strength& strength);

/// yield_value() of a stress in Voigt order (its principal values found first).
double yield_value_of_stress(const double* stress, const Strength& strength);

/// The update of one point: `trial` (Voigt xx, yy, zz, yz, xz, xy; the elastic trial stress)
/// returned onto the surface into `stress`; with `tangent` non-null, the consistent tangent
/// dσ/dε (6 × 6 row-major, tensor shear strains) of the whole update, trial included.
struct ReturnResult {
  ReturnKind kind = ReturnKind::elastic;
  double plastic_deviatoric = 0;  ///< √(2/3 Δe^p : Δe^p) of this return [-]
  double plastic_volumetric = 0;  ///< tr Δε^p [-], dilation positive
};
ReturnResult return_stress(const double* trial, const Strength& strength, const Elasticity& elastic, double* stress,
                           double* tangent);

}  // namespace frostmpm::mohr_coulomb
