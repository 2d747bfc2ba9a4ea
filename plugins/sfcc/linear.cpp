// Linear SFCC: ice content linear in T between T_m and T_f (Lunardini's mushy zone,
// INTERFROST T1): S_l = 1 above T_f, S_res below T_m, linear in between.
#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class LinearSfcc final : public SfccModel {
 public:
  static constexpr const char* kName = "linear";
  static constexpr const char* kDoc = "ice content linear between T_m and T_f (Lunardini mushy zone)";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("freezing_point", "degC", "T_f: fully thawed at and above").defaults_to(0.0).at_least(-273.15).at_most(100);
    s.real("mushy_end", "degC", "T_m (< T_f): residual saturation reached at and below").at_least(-273.15).at_most(100);
    s.real("residual_saturation", "-", "S_res below T_m").at_least(0).below(1);
    return s;
  }

  explicit LinearSfcc(const ParamSet& p)
      : freezing_point_(p.real("freezing_point")),
        mushy_end_(p.real("mushy_end")),
        residual_(p.real("residual_saturation")) {
    if (mushy_end_ >= freezing_point_)
      throw p.error("mushy_end", "mushy_end must be below freezing_point (" +
                                     std::to_string(freezing_point_) + ")");
    slope_ = (1.0 - residual_) / (freezing_point_ - mushy_end_);
  }

  void evaluate(std::span<const double> T, std::span<const double>, const SfccResult& out) const override {
    for (std::size_t i = 0; i < T.size(); ++i) {
      out.dS_l_dp[i] = 0.0;
      if (T[i] >= freezing_point_) {
        out.S_l[i] = 1.0;
        out.dS_l_dT[i] = 0.0;
      } else if (T[i] <= mushy_end_) {
        out.S_l[i] = residual_;
        out.dS_l_dT[i] = 0.0;
      } else {
        out.S_l[i] = residual_ + slope_ * (T[i] - mushy_end_);
        out.dS_l_dT[i] = slope_;
      }
    }
  }

  double freezing_point() const override { return freezing_point_; }

 private:
  double freezing_point_, mushy_end_, residual_, slope_ = 0;
};

FROSTMPM_REGISTER(SfccModel, LinearSfcc)

}  // namespace frostmpm
