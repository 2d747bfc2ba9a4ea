// Porosity-independent absolute conductivity, given either as a hydraulic conductivity
// (`constant`, m/s) or as an intrinsic permeability (`intrinsic`, m²). Keeping the two
// apart by name avoids the classic unit slip: INTERFROST's 1.3e-10 is m², not m/s.
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

class ConstantConductivity : public AbsolutePermeabilityModel {
 public:
  static constexpr const char* kName = "constant";
  static constexpr const char* kDoc = "constant hydraulic conductivity k0 [m/s]";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("k0", "m/s", "hydraulic conductivity").above(0).at_most(10);
    return s;
  }

  explicit ConstantConductivity(const ParamSet& p) : k_(p.real("k0")) {}
  explicit ConstantConductivity(double k) : k_(k) {}

  void evaluate(std::span<const double> porosity, std::span<double> k_a, std::span<double> dk_a) const override {
    for (std::size_t i = 0; i < porosity.size(); ++i) {
      k_a[i] = k_;
      dk_a[i] = 0.0;
    }
  }

 private:
  double k_;
};

class IntrinsicPermeability final : public ConstantConductivity {
 public:
  static constexpr const char* kName = "intrinsic";
  static constexpr const char* kDoc =
      "constant intrinsic permeability k [m^2], converted to K = k rho g / mu";

  static ParamSchema schema() {
    ParamSchema s;
    s.real("permeability", "m^2", "intrinsic permeability k").above(0).at_most(1e-3);
    s.real("fluid_density", "kg/m^3", "ρ_l").defaults_to(1000.0).above(0).at_most(3e4);
    s.real("fluid_viscosity", "Pa s", "dynamic viscosity μ (INTERFROST: 1.793e-3)").defaults_to(1.793e-3).above(0).at_most(1e3);
    s.real("gravity", "m/s^2", "g").defaults_to(9.81).above(0).at_most(1e3);
    return s;
  }

  explicit IntrinsicPermeability(const ParamSet& p)
      : ConstantConductivity(p.real("permeability") * p.real("fluid_density") * p.real("gravity") /
                             p.real("fluid_viscosity")) {}
};

FROSTMPM_REGISTER(AbsolutePermeabilityModel, ConstantConductivity)
FROSTMPM_REGISTER(AbsolutePermeabilityModel, IntrinsicPermeability)

}  // namespace frostmpm
