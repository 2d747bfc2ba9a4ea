// van Genuchten–Clausius–Clapeyron SFCC, paper Eq. (25):
//   s   = −(1 − ρ_c/ρ_l) p_l/p_0 − (ρ_c L_f/p_0) ln((T + 273.15)/273.15)   (cryo-suction / p_0)
//   S_l = S_res + (1 − S_res) [1 + s^(1/(1−λ))]^(−λ)   for s > 0, else 1.
// The Clausius–Clapeyron suction makes the freezing point depend on p_l.
#include <cmath>

#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class VanGenuchtenClausiusClapeyron final : public SfccModel {
 public:
  static constexpr const char* kName = "van_genuchten_cc";
  static constexpr const char* kDoc =
      "van Genuchten curve driven by Clausius-Clapeyron cryo-suction (paper Eq. 25)";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("lambda", "-", "shape constant λ; larger is steeper").above(0).below(1);
    s.real("p0", "Pa", "air-entry-like pressure scale p_0").above(0).at_most(1e10);
    s.real("ice_density", "kg/m^3", "intrinsic ice density ρ_c").defaults_to(917.0).above(0).at_most(3e4);
    s.real("water_density", "kg/m^3", "intrinsic liquid density ρ_l").defaults_to(1000.0).above(0).at_most(3e4);
    s.real("latent_heat", "J/kg", "latent heat of fusion L_f").defaults_to(3.34e5).above(0).at_most(1e8);
    s.real("residual_saturation", "-", "S_res, liquid saturation far below freezing")
        .defaults_to(0.0).at_least(0).below(1);
    return s;
  }

  explicit VanGenuchtenClausiusClapeyron(const ParamSet& p)
      : lambda_(p.real("lambda")),
        exponent_(1.0 / (1.0 - lambda_)),
        suction_per_kelvin_log_(p.real("ice_density") * p.real("latent_heat") / p.real("p0")),
        suction_per_pressure_((1.0 - p.real("ice_density") / p.real("water_density")) / p.real("p0")),
        residual_(p.real("residual_saturation")) {}

  void evaluate(std::span<const double> T, std::span<const double> p_l,
                const SfccResult& out) const override {
    const bool has_pressure = !p_l.empty();
    for (std::size_t i = 0; i < T.size(); ++i) {
      const double pressure = has_pressure ? p_l[i] : 0.0;
      const double kelvin = T[i] + 273.15;
      const double s = -suction_per_pressure_ * pressure -
                       suction_per_kelvin_log_ * std::log(kelvin / 273.15);
      if (s <= 0.0) {
        out.S_l[i] = 1.0;
        out.dS_l_dT[i] = 0.0;
        out.dS_l_dp[i] = 0.0;
        continue;
      }
      const double s_pow = std::pow(s, exponent_);
      const double base = 1.0 + s_pow;
      const double vg = std::pow(base, -lambda_);
      // d vg/ds = −λ a s^(a−1) (1 + s^a)^(−λ−1), with a = 1/(1−λ)
      const double dvg_ds = -lambda_ * exponent_ * (s_pow / s) * vg / base;
      const double scale = 1.0 - residual_;
      out.S_l[i] = residual_ + scale * vg;
      out.dS_l_dT[i] = scale * dvg_ds * (-suction_per_kelvin_log_ / kelvin);
      out.dS_l_dp[i] = scale * dvg_ds * (-suction_per_pressure_);
    }
  }

  double freezing_point() const override { return 0.0; }

 private:
  double lambda_, exponent_, suction_per_kelvin_log_, suction_per_pressure_, residual_;
};

FROSTMPM_REGISTER(SfccModel, VanGenuchtenClausiusClapeyron)

}  // namespace frostmpm
