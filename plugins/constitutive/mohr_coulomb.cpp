// Mohr–Coulomb plasticity of the unfrozen skeleton (paper Eqs. 30–35 without the ice terms):
// cohesion, friction and dilation angle with optional exponential softening and a tension
// cut-off, returned in principal stresses (mohr_coulomb_model.hpp, mohr_coulomb_return.hpp).
#include "frostmpm/plugin/plugin_api.hpp"
#include "mohr_coulomb_model.hpp"

namespace frostmpm {

struct MohrCoulombNames {
  static constexpr const char* kName = "mohr_coulomb";
  static constexpr const char* kDoc =
      "Mohr–Coulomb elastoplasticity (c, φ, ψ, softening, tension cut-off), return in principal stresses";
};
using MohrCoulomb = MohrCoulombRegistered<MohrCoulombNames, false>;

FROSTMPM_REGISTER(MechanicalModel, MohrCoulomb)

}  // namespace frostmpm
