// Exponential (Gaussian) SFCC, paper Eq. (B1), as used by INTERFROST TH2/TH3:
//   S_l = S_res + (1 − S_res) exp(−((T − T_f)/W)²)  below T_f, and 1 at and above T_f.
// The Gaussian is symmetric in T, so the branch above T_f must be cut to 1, or thawed soil
// would "refreeze" as it warms.
#include <cmath>

#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class ExponentialSfcc final : public SfccModel {
 public:
  static constexpr const char* kName = "exponential";
  static constexpr const char* kDoc = "Gaussian-exponential curve of INTERFROST (paper Eq. B1)";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("width", "K", "width W (the paper's M) of the freezing interval").above(0).at_most(100);
    s.real("residual_saturation", "-", "S_res, liquid saturation far below freezing").at_least(0).below(1);
    s.real("freezing_point", "degC", "T_f, fully thawed at and above").defaults_to(0.0).at_least(-273.15).at_most(100);
    return s;
  }

  explicit ExponentialSfcc(const ParamSet& p)
      : width_(p.real("width")), residual_(p.real("residual_saturation")), freezing_point_(p.real("freezing_point")) {}

  void evaluate(std::span<const double> T, std::span<const double>, const SfccResult& out) const override {
    for (std::size_t i = 0; i < T.size(); ++i) {
      out.dS_l_dp[i] = 0.0;
      if (T[i] >= freezing_point_) {
        out.S_l[i] = 1.0;
        out.dS_l_dT[i] = 0.0;
        continue;
      }
      const double z = (T[i] - freezing_point_) / width_;
      const double g = std::exp(-z * z);
      out.S_l[i] = residual_ + (1.0 - residual_) * g;
      out.dS_l_dT[i] = (1.0 - residual_) * g * (-2.0 * z / width_);
    }
  }

  double freezing_point() const override { return freezing_point_; }

 private:
  double width_, residual_, freezing_point_;
};

FROSTMPM_REGISTER(SfccModel, ExponentialSfcc)

}  // namespace frostmpm
