// The paper's ice-saturation-dependent Mohr–Coulomb model (Eqs. 30–37): the strength of
// mohr_coulomb plus what ice bonding adds, ΔΨ_max [1 − exp(−η_c s_c)] with the normalised
// cryo-suction s_c of the freezing curve (mohr_coulomb_model.hpp).
#include "frostmpm/plugin/plugin_api.hpp"
#include "mohr_coulomb_model.hpp"

namespace frostmpm {

struct MohrCoulombIceNames {
  static constexpr const char* kName = "mohr_coulomb_ice";
  static constexpr const char* kDoc =
      "Mohr–Coulomb whose cohesion, friction and dilation grow with ice saturation (paper Eqs. 30–37)";
};
using MohrCoulombIce = MohrCoulombRegistered<MohrCoulombIceNames, true>;

FROSTMPM_REGISTER(MechanicalModel, MohrCoulombIce)

}  // namespace frostmpm
