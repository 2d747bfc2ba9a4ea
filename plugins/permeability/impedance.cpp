// Impedance relative conductivity, paper Eq. (B2) / INTERFROST:
//   k_r = max(10^(−Ω φ (1 − S_l)), floor). The porosity stays in the exponent.
#include <cmath>

#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class ImpedancePermeability final : public RelativePermeabilityModel {
 public:
  static constexpr const char* kName = "impedance";
  static constexpr const char* kDoc = "impedance k_r = max(10^(-Omega*phi*(1-S_l)), floor) (paper Eq. B2)";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("omega", "-", "impedance factor Ω (INTERFROST: 50)").above(0);
    s.real("floor", "-", "lower bound of k_r (INTERFROST: 1e-6)").defaults_to(1e-6).above(0).at_most(1);
    return s;
  }

  explicit ImpedancePermeability(const ParamSet& p) : omega_(p.real("omega")), floor_(p.real("floor")) {}

  void evaluate(std::span<const double> S_l, std::span<const double> porosity, std::span<double> k_r,
                std::span<double> dk_r) const override {
    const double ln10 = std::log(10.0);
    for (std::size_t i = 0; i < S_l.size(); ++i) {
      if (S_l[i] > 1.0) {  // round-off above full saturation: thawed, k_r stays at 1
        k_r[i] = 1.0;
        dk_r[i] = 0.0;
        continue;
      }
      const double rate = omega_ * porosity[i];
      const double value = std::pow(10.0, -rate * (1.0 - S_l[i]));
      if (value <= floor_) {
        k_r[i] = floor_;
        dk_r[i] = 0.0;
      } else {
        k_r[i] = value;
        dk_r[i] = value * ln10 * rate;
      }
    }
  }

 private:
  double omega_, floor_;
};

FROSTMPM_REGISTER(RelativePermeabilityModel, ImpedancePermeability)

}  // namespace frostmpm
