// van Genuchten–Mualem relative conductivity, paper Eq. (26):
//   k_r = √S_l [1 − (1 − S_l^(1/m))^m]²,  floored at `floor`.
// The slope is unbounded as S_l → 1 (for m < 1); we evaluate it at S_l ≤ 1 − 1e-12 so the
// tangent stays finite for implicit solvers.
#include <algorithm>
#include <cmath>

#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class VanGenuchtenMualem final : public RelativePermeabilityModel {
 public:
  static constexpr const char* kName = "van_genuchten_mualem";
  static constexpr const char* kDoc = "van Genuchten-Mualem k_r(S_l) (paper Eq. 26)";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("m", "-", "van Genuchten constant m").above(0).below(1);
    s.real("floor", "-", "smallest k_r returned (keeps the drag finite in frozen soil)")
        .defaults_to(1e-12).above(0).below(1);
    return s;
  }

  explicit VanGenuchtenMualem(const ParamSet& p) : m_(p.real("m")), floor_(p.real("floor")) {}

  void evaluate(std::span<const double> S_l, std::span<const double>, std::span<double> k_r,
                std::span<double> dk_r) const override {
    for (std::size_t i = 0; i < S_l.size(); ++i) {
      const double s = std::clamp(S_l[i], 0.0, 1.0 - 1e-12);
      if (s <= 0.0) {
        k_r[i] = floor_;
        dk_r[i] = 0.0;
        continue;
      }
      const double u = std::pow(s, 1.0 / m_);
      const double w = 1.0 - u;
      const double wm = std::pow(w, m_);
      const double g = 1.0 - wm;
      const double root = std::sqrt(s);
      const double value = root * g * g;
      if (S_l[i] >= 1.0) {
        k_r[i] = 1.0;
        dk_r[i] = 0.0;
        continue;
      }
      if (value <= floor_) {
        k_r[i] = floor_;
        dk_r[i] = 0.0;
        continue;
      }
      // dg/ds = w^(m−1) s^(1/m − 1)
      const double dg = (wm / w) * (u / s);
      k_r[i] = value;
      dk_r[i] = 0.5 / root * g * g + root * 2.0 * g * dg;
    }
  }

 private:
  double m_, floor_;
};

FROSTMPM_REGISTER(RelativePermeabilityModel, VanGenuchtenMualem)

}  // namespace frostmpm
