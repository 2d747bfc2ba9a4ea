// A third-party SFCC: S_l = S_res + (1 − S_res) exp((T − T_f)/a) below T_f, 1 above.
// Everything a plugin needs: the interface, a parameter schema, one FROSTMPM_REGISTER line
// beside the class and one FROSTMPM_PLUGIN line per library.
#include <cmath>

#include <frostmpm/models/sfcc_model.hpp>
#include <frostmpm/plugin/plugin_api.hpp>

namespace my_lab {

class ExponentialDecaySfcc final : public frostmpm::SfccModel {
 public:
  static constexpr const char* kName = "exponential_decay";
  static constexpr const char* kDoc = "S_l = S_res + (1 - S_res) exp((T - T_f)/a) below T_f";

  static frostmpm::ParamSchema schema() {
    frostmpm::ParamSchema s;
    s.real("decay_scale", "K", "a: temperature scale of the decay").above(0);
    s.real("residual_saturation", "-", "S_res far below freezing").defaults_to(0.0).at_least(0).below(1);
    s.real("freezing_point", "degC", "T_f").defaults_to(0.0);
    return s;
  }

  explicit ExponentialDecaySfcc(const frostmpm::ParamSet& p)
      : scale_(p.real("decay_scale")),
        residual_(p.real("residual_saturation")),
        freezing_point_(p.real("freezing_point")) {}

  void evaluate(std::span<const double> T, std::span<const double>,
                const frostmpm::SfccResult& out) const override {
    for (std::size_t i = 0; i < T.size(); ++i) {
      out.dS_l_dp[i] = 0.0;
      if (T[i] >= freezing_point_) {
        out.S_l[i] = 1.0;
        out.dS_l_dT[i] = 0.0;
        continue;
      }
      const double e = std::exp((T[i] - freezing_point_) / scale_);
      out.S_l[i] = residual_ + (1.0 - residual_) * e;
      out.dS_l_dT[i] = (1.0 - residual_) * e / scale_;
    }
  }

  double freezing_point() const override { return freezing_point_; }

 private:
  double scale_, residual_, freezing_point_;
};

FROSTMPM_REGISTER(frostmpm::SfccModel, ExponentialDecaySfcc)

}  // namespace my_lab

FROSTMPM_PLUGIN("my-lab-sfcc", "1.0.0")
