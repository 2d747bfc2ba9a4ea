#pragma once
// Constitutive models of the soil skeleton (solid grains and ice, paper Sec. 3.3) as a plugin
// kind, `mechanical_model`, chosen per material like the SFCC:
//   materials: {soil: {mechanical_model: {model: linear_elastic, youngs_modulus: 1e6, ...}}}
//
// Conventions (the whole code): stress is the effective stress σ′ of the skeleton, tension
// positive; total stress σ = σ′ − p_l I (paper Eq. 10 with the ice carried by the skeleton).
// Tensors are 3×3 whatever the dimension (plane strain keeps σ_zz), stored as 6 values in
// Voigt order xx, yy, zz, yz, xz, xy with tensor (not engineering) shear strains, so
// σ_xy = 2G ε_xy for an isotropic elastic model.
//
// Contract (as OGS's MechanicsBase::integrateStress): the model takes a strain increment and
// the step-start stress (already rotated by the objective rate) and internal variables, and
// returns the new stress and internal variables — or a failure flag per point instead of
// throwing, so the mechanics can stop with the particle, region, time and model named. Models
// are evaluated in batches (one virtual call per material range), never per particle.
// `frostmpm test-model mechanical_model/NAME` checks a model against this contract
// (models/model_contract.hpp).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// One batch of stress updates; every span holds n points (times 6 for tensors, times
/// internal_variables().size() for the state). Optional inputs are empty when the scene has no
/// physics providing them.
struct StressUpdateInput {
  std::span<const double> strain_increment;  ///< Δε, n × 6 (the part that makes stress: thermal strain removed)
  std::span<const double> stress_start;      ///< σ′ at the step's start, rotated, n × 6 [Pa]
  std::span<const double> state_start;       ///< internal variables at the step's start
  std::span<const double> temperature;       ///< T [°C] (optional)
  std::span<const double> ice_saturation;    ///< S_c = 1 − S_l [-] (optional)
  std::span<const double> pore_pressure;     ///< p_l [Pa] (optional)
  double dt = 0;                             ///< the step [s]
};

struct StressUpdateOutput {
  std::span<double> stress;                 ///< σ′ at the step's end, n × 6
  std::span<double> state;                  ///< internal variables at the step's end
  std::span<std::uint8_t> failed;           ///< 1 where the integration failed (the rest stay 0)
  std::span<double> tangent;                ///< ∂σ′/∂Δε, n × 36 row-major (optional: empty = not wanted)
  std::span<double> p_wave_modulus;         ///< K + 4G/3 now [Pa], for the stable step (optional)
  std::span<double> shear_modulus;          ///< G now [Pa], for the pressure stabilization (optional)
};

/// An internal variable of a model: a scalar per particle, a particle field of the scene (its
/// values written to fields.h5 with `unit` when the scene's output lists it).
struct InternalVariable {
  std::string name;
  std::string unit;  ///< UDUNITS-2 text: "1" when dimensionless, "Pa", "degree" (frostmpm/config/units.hpp)
  bool operator==(const InternalVariable&) const = default;
};

class MechanicalModel {
 public:
  static constexpr const char* kKind = "mechanical_model";
  virtual ~MechanicalModel();

  /// The internal variables, each with its unit.
  virtual std::vector<InternalVariable> internal_variables() const { return {}; }
  /// Their values before the first step.
  virtual std::vector<double> initial_state() const { return std::vector<double>(internal_variables().size(), 0.0); }
  virtual void integrate(const StressUpdateInput& in, const StressUpdateOutput& out) const = 0;
  /// A plasticity model's yield function F(σ′, internal variables) for n points [Pa], ≤ 0 where
  /// the stress is admissible: `frostmpm test-model` checks that every returned stress lies on or
  /// inside the surface its internal variables describe, and a scene using a model with one is
  /// warned of volumetric locking (called with empty spans for that). false: no yield surface.
  virtual bool yield_function(std::span<const double> /*stress*/, std::span<const double> /*state*/,
                              std::span<double> /*value*/) const {
    return false;
  }
  /// The largest P-wave modulus K + 4G/3 the model can reach [Pa] (over every ice saturation):
  /// bounds the stable step before the first update.
  virtual double max_p_wave_modulus() const = 0;
};

}  // namespace frostmpm
