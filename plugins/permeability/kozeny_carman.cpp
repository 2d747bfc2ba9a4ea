// Kozeny–Carman absolute conductivity (paper Eq. 27, ref. 74):
//   k_a = k_0 · [(1 − φ_0)²/φ_0³] · [φ³/(1 − φ)²]
// The paper's typeset form shows (1 − φ²); the Kozeny–Carman relation it cites uses (1 − φ)²,
// which is what we implement (see docs/theory.md).
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class KozenyCarman final : public AbsolutePermeabilityModel {
 public:
  static constexpr const char* kName = "kozeny_carman";
  static constexpr const char* kDoc = "Kozeny-Carman k_a(phi) scaled to k_0 at reference porosity (paper Eq. 27)";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("k0", "m/s", "hydraulic conductivity at the reference porosity").above(0).at_most(10);
    s.real("reference_porosity", "-", "φ_0 at which k_a = k0").above(0).below(1);
    return s;
  }

  explicit KozenyCarman(const ParamSet& p) : k0_(p.real("k0")) {
    const double phi0 = p.real("reference_porosity");
    scale_ = k0_ * (1.0 - phi0) * (1.0 - phi0) / (phi0 * phi0 * phi0);
  }

  void evaluate(std::span<const double> porosity, std::span<double> k_a, std::span<double> dk_a) const override {
    for (std::size_t i = 0; i < porosity.size(); ++i) {
      const double phi = porosity[i];
      const double one_minus = 1.0 - phi;
      const double f = phi * phi * phi / (one_minus * one_minus);
      // d/dφ [φ³ (1−φ)^−2] = 3φ²/(1−φ)² + 2φ³/(1−φ)³
      const double df = 3.0 * phi * phi / (one_minus * one_minus) + 2.0 * f / one_minus;
      k_a[i] = scale_ * f;
      dk_a[i] = scale_ * df;
    }
  }

 private:
  double k0_, scale_ = 0;
};

FROSTMPM_REGISTER(AbsolutePermeabilityModel, KozenyCarman)

}  // namespace frostmpm
