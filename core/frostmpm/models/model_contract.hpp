#pragma once
// The contract every SFCC and permeability model must keep, checked by sampling: what
// `frostmpm test-model` runs, and what a plugin's own tests can call. Each function returns
// one line per violated rule (the first offending sample, and how many more); empty = clean.
#include <cstddef>
#include <string>
#include <vector>

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

}  // namespace frostmpm
