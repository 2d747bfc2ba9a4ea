#pragma once
// Work a scene asks for, estimated before it is done: a run that would not finish (too many
// steps or output rows) or not fit in memory (too many particles) is bad input, refused up
// front naming the key, instead of a hang or a bad_alloc later.
#include <cstdint>
#include <string>

#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// Default of `time.max_steps`: a bound on steps, metrics rows and field frames.
inline constexpr long kDefaultMaxSteps = 10'000'000;

/// Bytes one particle costs, all fields and its stencil together (an upper estimate).
inline constexpr double kBytesPerParticle = 2048;

/// Throws naming `key` of `params` when `count` (of `what`, e.g. "steps") exceeds `limit`;
/// `because` says where the count comes from.
void check_count(const ParamSet& params, const std::string& key, double count, long limit, const std::string& what,
                 const std::string& because);

/// Installed memory in bytes (0 when unknown).
std::uintmax_t physical_memory_bytes();

/// "3.1 GB" style text.
std::string bytes_text(double bytes);

}  // namespace frostmpm
