// Power-law SFCC after Anderson & Tice (1972), θ_u ∝ |T|^(−b), written in saturation form:
//   S_l = max(S_res, ((T_f − T)/T_ref)^(−b))  for T_f − T > T_ref, and 1 above.
// T_ref is the depression below T_f where freezing starts, so S_l is continuous there.
#include <algorithm>
#include <cmath>

#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class PowerLawSfcc final : public SfccModel {
 public:
  static constexpr const char* kName = "power_law";
  static constexpr const char* kDoc = "Anderson-Tice power law S_l = ((T_f - T)/T_ref)^(-b), floored at S_res";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("exponent", "-", "power b (> 0); larger drops faster").above(0).at_most(100);
    s.real("reference_depression", "K", "T_ref: freezing starts at T_f - T_ref").above(0).at_most(273.15);
    s.real("residual_saturation", "-", "S_res lower bound").defaults_to(0.0).at_least(0).below(1);
    s.real("freezing_point", "degC", "T_f").defaults_to(0.0).at_least(-273.15).at_most(100);
    return s;
  }

  explicit PowerLawSfcc(const ParamSet& p)
      : exponent_(p.real("exponent")),
        reference_(p.real("reference_depression")),
        residual_(p.real("residual_saturation")),
        freezing_point_(p.real("freezing_point")) {}

  void evaluate(std::span<const double> T, std::span<const double>, const SfccResult& out) const override {
    for (std::size_t i = 0; i < T.size(); ++i) {
      out.dS_l_dp[i] = 0.0;
      const double depression = freezing_point_ - T[i];
      if (depression <= reference_) {
        out.S_l[i] = 1.0;
        out.dS_l_dT[i] = 0.0;
        continue;
      }
      const double value = std::pow(depression / reference_, -exponent_);
      if (value <= residual_) {
        out.S_l[i] = residual_;
        out.dS_l_dT[i] = 0.0;
        continue;
      }
      out.S_l[i] = value;
      // dS/dT = dS/d(depression) · (−1) = b S / depression
      out.dS_l_dT[i] = exponent_ * value / depression;
    }
  }

  double freezing_point() const override { return freezing_point_; }

 private:
  double exponent_, reference_, residual_, freezing_point_;
};

FROSTMPM_REGISTER(SfccModel, PowerLawSfcc)

}  // namespace frostmpm
