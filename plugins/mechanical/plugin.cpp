// The mechanical physics plugin: one registered physics that runs MechanicalPhysics<2> or <3>
// according to the kernel that sets it up.
#include "frostmpm/physics/dimensional_physics.hpp"
#include "frostmpm/plugin/plugin_api.hpp"
#include "mechanical_physics.hpp"

namespace frostmpm::mechanical {

class Mechanical final : public DimensionalPhysics<MechanicalPhysics> {
 public:
  static constexpr const char* kName = "mechanical";
  static constexpr const char* kDoc =
      "the solid skeleton: momentum with gravity and tractions, effective stress with a constitutive model per "
      "material, Jaumann rate, moving material points (with hydraulic: the two-phase fractional step)";
  static ParamSchema schema() { return MechanicalPhysics<2>::schema(); }
  static std::vector<BoundaryType> boundary_type_docs() { return mechanical_boundary_types(); }
  using DimensionalPhysics::DimensionalPhysics;
};

FROSTMPM_REGISTER(Physics, Mechanical)
FROSTMPM_REGISTER_BOUNDARY_TYPES(Mechanical)

}  // namespace frostmpm::mechanical

FROSTMPM_PLUGIN("frostmpm-mechanical", "0.1.0")
