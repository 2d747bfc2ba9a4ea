// Out-of-line virtual destructors: one vtable per interface, owned by the core library.
#include "frostmpm/config/input_error.hpp"
#include "frostmpm/models/mechanical_model.hpp"
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/physics/physics.hpp"

namespace frostmpm {
SfccModel::~SfccModel() = default;
Physics::~Physics() = default;
MechanicalModel::~MechanicalModel() = default;
void Physics::setup(Kernel<2>&) { throw InputError("this physics does not run in 2-D"); }
void Physics::setup(Kernel<3>&) { throw InputError("this physics does not run in 3-D yet"); }
RelativePermeabilityModel::~RelativePermeabilityModel() = default;
AbsolutePermeabilityModel::~AbsolutePermeabilityModel() = default;
}  // namespace frostmpm
