#pragma once
// The contract every SFCC, permeability and mechanical model must keep, checked by sampling:
// what `frostmpm test-model` runs, and what a plugin's own tests can call. Each function
// returns one line per violated rule (the first offending sample, and how many more); empty =
// clean.
#include <cstddef>
#include <string>
#include <vector>

#include "frostmpm/models/mechanical_model.hpp"
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/models/sfcc_model.hpp"

namespace frostmpm {

/// S_l finite and in [0, 1], 1 at and above freezing_point(), non-decreasing in T, continuous
/// at the freezing point, ∂S_l/∂T and ∂S_l/∂p_l equal to finite differences, an empty p_l the
/// same as p_l = 0. Samples `samples` temperatures in [T_min, T_max] °C.
std::vector<std::string> check_sfcc_contract(const SfccModel& model, double T_min, double T_max,
                                             std::size_t samples = 2001);

/// k_r finite and in [0, 1], 1 at S_l = 1, non-decreasing in S_l, dk_r/dS_l equal to finite
/// differences; S_l sampled over [0, 1] at a few porosities.
std::vector<std::string> check_relative_permeability_contract(const RelativePermeabilityModel& model,
                                                              std::size_t samples = 2001);

/// k_a positive and finite, dk_a/dφ equal to finite differences; φ sampled over (0, 1).
std::vector<std::string> check_absolute_permeability_contract(const AbsolutePermeabilityModel& model,
                                                              std::size_t samples = 2001);

/// One parameter set of a mechanical model; `parameters` names it in messages
/// ("poisson_ratio=0.485"), "" for a model checked alone.
struct MechanicalModelCase {
  const MechanicalModel* model = nullptr;
  std::string parameters;
};

/// The mechanical_model contract (models/mechanical_model.hpp) on `samples` random states (a
/// fixed seed, the same for every parameter set): strain increments up to 1e-3 in norm,
/// T in [-20, 20] degC, S_c in [0, 1] (both ends included), p_l in [0, 1e6] Pa, and start
/// stress and state the model reaches itself in one loading step from initial_state() and a
/// hydrostatic compression p up to 1 MPa (a strain worth up to 0.2 p, every other sample 3 p, at max_p_wave_modulus();
/// the first start stress zero), so an elastoplastic model starts on or inside its yield
/// surface. Rules:
///  - initial_state() has internal_variables().size() entries, all finite;
///    max_p_wave_modulus() positive and finite;
///  - stress, state, p_wave_modulus and shear_modulus finite (every entry written) and no
///    failure flag, with and without the optional inputs (T, S_c, p_l);
///  - 0 < p_wave_modulus <= max_p_wave_modulus(), shear_modulus >= 0;
///  - a zero strain increment gives the start stress back (to round-off, 1e-12 of its size);
///  - a filled tangent equals Richardson-extrapolated central (or, at a kink, second-order
///    one-sided) finite differences of the stress in each of the 6 strain components
///    (relative 1e-6, with an absolute floor of 1e-6 of the largest tangent entry plus the
///    round-off of the differences);
///  - isotropy and objectivity: integrating (Q Δε Qᵀ, Q σ0 Qᵀ) gives Q σ1 Qᵀ and the same state
///    (relative 1e-9), for a random rotation Q per sample and for 90 degrees about z (σ_xx and
///    σ_yy swap, the plane-strain case);
///  - integrate() does not throw (a point it cannot integrate sets the failure flag).
std::vector<std::string> check_mechanical_model_contract(const MechanicalModel& model, std::size_t samples = 2001);

/// The same over several parameter sets of one model, one line per rule across all of them.
std::vector<std::string> check_mechanical_model_contract(const std::vector<MechanicalModelCase>& cases,
                                                         std::size_t samples = 2001);

}  // namespace frostmpm
