// Out-of-line virtual destructors: one vtable per interface, owned by the core library.
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/physics/physics.hpp"

namespace frostmpm {
SfccModel::~SfccModel() = default;
Physics::~Physics() = default;
RelativePermeabilityModel::~RelativePermeabilityModel() = default;
AbsolutePermeabilityModel::~AbsolutePermeabilityModel() = default;
}  // namespace frostmpm
