// Constitutive models of the skeleton (kind mechanical_model, paper Sec. 3.3): linear_elastic's
// closed-form increments and moduli, and the contract `frostmpm test-model` checks — kept by
// every shipped model, broken by the fixture models on purpose. Every model is built through
// the registry as a scene builds it (YAML model section -> read_model_section -> create).
//
// Every registered mechanical model must have an entry in mechanical_cases() below; a newly
// registered model without one fails "every registered mechanical model has a test case".
#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/models/mechanical_model.hpp"
#include "frostmpm/models/model_contract.hpp"
#include "frostmpm/plugin/plugin_loader.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "mechanical_model_testing.hpp"
#include "test_support.hpp"

namespace {

using frostmpm::MechanicalModel;
using frostmpm::test::Voigt;

using frostmpm::test::integrate;
using frostmpm::test::make_model;
using Update = frostmpm::test::StressUpdate;

/// Lamé constants of (E, ν).
struct Elastic {
  double E, nu;
  double G() const { return E / (2 * (1 + nu)); }
  double lambda() const { return E * nu / ((1 + nu) * (1 - 2 * nu)); }
  double oedometric() const { return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)); }
};

const std::map<std::string, std::vector<std::string>>& mechanical_cases() {
  static const std::map<std::string, std::vector<std::string>> cases = {
      {"linear_elastic",
       {"youngs_modulus: 1.0e6, poisson_ratio: 0.3",                                  // the self-weight column
        "youngs_modulus: 5.0e7, poisson_ratio: 0.0, frozen_youngs_modulus: 5.0e8",    // frozen 10× stiffer
        "youngs_modulus: 2.0e8, poisson_ratio: 0.49, frozen_youngs_modulus: 1.0e9",   // nearly incompressible
        "youngs_modulus: 1.0e5, poisson_ratio: -0.5",                                  // auxetic, soft
        "youngs_modulus: 1.0e10, poisson_ratio: 0.25, frozen_youngs_modulus: 1.0e3",    // ice softens
        "youngs_modulus: 1.0e6, poisson_ratio: 0.0, frozen_youngs_modulus: 2.0e7, modulus_change: elastic_strain"}},
      {"mohr_coulomb",
       {"youngs_modulus: 1.0e7, poisson_ratio: 0.3, cohesion: 1.0e4, friction_angle: 30, dilation_angle: 10",
        "youngs_modulus: 1.0e7, poisson_ratio: 0.3, cohesion: 0, friction_angle: 35",           // cohesionless sand
        "youngs_modulus: 1.0e8, poisson_ratio: 0.49, cohesion: 5.0e4, friction_angle: 0",       // Tresca, undrained
        "youngs_modulus: 1.0e7, poisson_ratio: 0.25, cohesion: 2.0e4, residual_cohesion: 1.0e4, friction_angle: 30, "
        "residual_friction_angle: 25, dilation_angle: 5, residual_dilation_angle: 0, softening_rate: 50",
        "youngs_modulus: 1.0e7, poisson_ratio: 0.3, cohesion: 5.0e4, friction_angle: 30, tensile_strength: 1.0e4"}},
      {"mohr_coulomb_ice",
       {// the paper's strip footing (Sec. 5.3.2) and thaw slump (Sec. 5.3.1)
        "youngs_modulus: 1.0e8, poisson_ratio: 0.3, cohesion: 2.0e4, residual_cohesion: 1.0e4, friction_angle: 30, "
        "softening_rate: 5, max_ice_cohesion: 2.0e5, ice_bonding_rate: 0.05, lambda: 0.4",
        "youngs_modulus: 2.0e7, poisson_ratio: 0.3, cohesion: 2.0e3, friction_angle: 20, max_ice_cohesion: 2.0e5, "
        "max_ice_friction_angle: 15, max_ice_dilation_angle: 5, ice_bonding_rate: 0.05, lambda: 0.4"}}};
  return cases;
}

const Voigt kStart = {-1.0e5, -2.0e5, -1.2e5, 4.0e3, -3.0e3, 5.0e3};

/// The fixture library whose models break their contract on purpose, in its own registry.
const frostmpm::Registry& broken_registry() {
  static frostmpm::Registry registry = [] {
    frostmpm::Registry r;
    frostmpm::PluginLoader loader(r);
    const std::string library = frostmpm::test::binary_dir() + "/test-fixtures/libfixture_broken_models.so";
    if (!loader.load_file(library)) throw std::runtime_error("cannot load " + library);
    return r;
  }();
  return registry;
}

/// J2 plasticity with linear isotropic hardening by radial return and its consistent tangent:
/// an elastoplastic model must keep the contract too (start states on the yield surface, kinks
/// in the stress-strain path). `tangent_error` spoils the tangent's plastic part.
class RadialReturn final : public MechanicalModel {
 public:
  RadialReturn(double yield_stress, double tangent_error = 0) : yield_(yield_stress), error_(tangent_error) {}
  std::vector<frostmpm::InternalVariable> internal_variables() const override { return {{"plastic_strain", "1"}}; }
  void integrate(const frostmpm::StressUpdateInput& in, const frostmpm::StressUpdateOutput& out) const override {
    const double G = E_ / (2 * (1 + nu_)), K = E_ / (3 * (1 - 2 * nu_));
    for (std::size_t p = 0; p < in.stress_start.size() / 6; ++p) {
      const double* de = &in.strain_increment[6 * p];
      const double trace = de[0] + de[1] + de[2];
      double trial[6], dev[6];
      for (int i = 0; i < 6; ++i)
        trial[i] = in.stress_start[6 * p + i] + 2 * G * de[i] + (i < 3 ? (K - 2 * G / 3) * trace : 0);
      const double mean = (trial[0] + trial[1] + trial[2]) / 3;
      double norm2 = 0;
      for (int i = 0; i < 6; ++i) {
        dev[i] = trial[i] - (i < 3 ? mean : 0);
        norm2 += (i < 3 ? 1 : 2) * dev[i] * dev[i];
      }
      const double q = std::sqrt(1.5 * norm2), yield = yield_ + H_ * in.state_start[p];
      const double dg = q > yield ? (q - yield) / (3 * G + H_) : 0, shrink = dg > 0 ? 1 - 3 * G * dg / q : 1;
      for (int i = 0; i < 6; ++i) out.stress[6 * p + i] = (i < 3 ? mean : 0) + shrink * dev[i];
      out.state[p] = in.state_start[p] + dg;
      if (!out.tangent.empty()) {
        double* D = &out.tangent[36 * p];
        const double c = dg > 0 ? 6 * G * G * (dg / q - 1 / (3 * G + H_)) * (1 + error_) / norm2 : 0;
        for (int a = 0; a < 6; ++a)
          for (int b = 0; b < 6; ++b) {
            const double deviatoric = (a == b ? 1 : 0) - (a < 3 && b < 3 ? 1.0 / 3 : 0);
            // n ⊗ n with n = dev/|dev|; a shear strain component stands for two tensor entries.
            D[6 * a + b] =
                (a < 3 && b < 3 ? K : 0) + 2 * G * shrink * deviatoric + c * dev[a] * dev[b] * (b < 3 ? 1 : 2);
          }
      }
      if (!out.p_wave_modulus.empty()) out.p_wave_modulus[p] = K + 4 * G / 3;
      if (!out.shear_modulus.empty()) out.shear_modulus[p] = G;
    }
  }
  double max_p_wave_modulus() const override { return E_ * (1 - nu_) / ((1 + nu_) * (1 - 2 * nu_)); }

 private:
  double E_ = 1e8, nu_ = 0.3, H_ = 1e6, yield_, error_;
};

/// Throws where it should flag the point as failed.
class Throwing final : public MechanicalModel {
 public:
  void integrate(const frostmpm::StressUpdateInput&, const frostmpm::StressUpdateOutput&) const override {
    throw std::runtime_error("no convergence");
  }
  double max_p_wave_modulus() const override { return 1e8; }
};

bool any_has(const std::vector<std::string>& lines, const std::string& part) {
  for (const auto& line : lines)
    if (line.find(part) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("every registered mechanical model has a test case and builds", "[mechanical]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto entries = registry.entries(MechanicalModel::kKind);
  REQUIRE(!entries.empty());
  for (const auto* entry : entries) {
    INFO("mechanical model '" << entry->name << "' needs an entry in mechanical_cases() of " << __FILE__);
    REQUIRE(mechanical_cases().count(entry->name) == 1);
    for (const auto& params : mechanical_cases().at(entry->name)) {
      INFO(params);
      REQUIRE_NOTHROW(make_model(entry->name, params));
    }
  }
  for (const auto& [name, _] : mechanical_cases()) CHECK(registry.find(MechanicalModel::kKind, name));
}

TEST_CASE("every mechanical parameter set keeps the contract `frostmpm test-model` checks", "[mechanical][contract]") {
  const auto& registry = frostmpm::test::builtin_registry();
  int checked = 0;
  for (const auto* entry : registry.entries(MechanicalModel::kKind))
    for (const auto& params : mechanical_cases().at(entry->name)) {
      const auto violations = frostmpm::check_mechanical_model_contract(*make_model(entry->name, params));
      INFO(entry->name << " {" << params << "}: " << frostmpm::join(violations, "\n"));
      CHECK(violations.empty());
      ++checked;
    }
  CHECK(checked >= 5);
}

TEST_CASE("linear_elastic: a uniaxial strain increment gives E_oed and lambda times it", "[mechanical]") {
  const Elastic e{1.0e7, 0.3};
  const auto model = make_model("linear_elastic", "youngs_modulus: 1.0e7, poisson_ratio: 0.3");
  // Hand values: λ = 3e6 / (1.3 · 0.4) = 5.769231e6 Pa, E_oed = 7e6 / 0.52 = 1.346154e7 Pa.
  CHECK(e.lambda() == Approx(5.769231e6).epsilon(1e-6));
  CHECK(e.oedometric() == Approx(1.346154e7).epsilon(1e-6));
  const Update u = integrate(*model, {0, 1e-4, 0, 0, 0, 0}, kStart, -1);
  REQUIRE(!u.failed);
  CHECK(u.stress[1] - kStart[1] == Approx(e.oedometric() * 1e-4).epsilon(1e-12));
  CHECK(u.stress[0] - kStart[0] == Approx(e.lambda() * 1e-4).epsilon(1e-12));
  CHECK(u.stress[2] - kStart[2] == Approx(e.lambda() * 1e-4).epsilon(1e-12));
  for (int k = 3; k < 6; ++k) CHECK(u.stress[k] == kStart[k]);  // no shear from a normal strain
  // Compression shortens: the same increment negated gives the negated change.
  const Update c = integrate(*model, {0, -1e-4, 0, 0, 0, 0}, kStart, -1);
  CHECK(c.stress[1] - kStart[1] == Approx(-e.oedometric() * 1e-4).epsilon(1e-12));
}

TEST_CASE("linear_elastic: a tensor shear strain increment gives 2G times it", "[mechanical]") {
  const Elastic e{1.0e7, 0.3};
  const auto model = make_model("linear_elastic", "youngs_modulus: 1.0e7, poisson_ratio: 0.3");
  for (int k = 3; k < 6; ++k) {
    INFO("shear component " << k);
    Voigt strain{};
    strain[k] = 1e-4;
    const Update u = integrate(*model, strain, kStart, -1);
    // G = 1e7 / 2.6 = 3.846154e6 Pa: σ_xy = 2G ε_xy with the tensor (not engineering) strain.
    CHECK(u.stress[k] - kStart[k] == Approx(2 * 3.846154e6 * 1e-4).epsilon(1e-6));
    CHECK(u.stress[k] - kStart[k] == Approx(2 * e.G() * 1e-4).epsilon(1e-12));
    for (int j = 0; j < 6; ++j)
      if (j != k) CHECK(u.stress[j] == kStart[j]);
    CHECK(u.tangent[6 * k + k] == Approx(2 * e.G()).epsilon(1e-14));
  }
}

TEST_CASE("linear_elastic: tangent, P-wave and shear modulus outputs, and the bound", "[mechanical]") {
  const Elastic e{2.0e8, 0.25};
  const auto model = make_model("linear_elastic", "youngs_modulus: 2.0e8, poisson_ratio: 0.25");
  const Update u = integrate(*model, {1e-4, -2e-4, 3e-5, 1e-5, 0, -4e-5}, kStart, -1);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double expected = i < 3 && j < 3 ? e.lambda() + (i == j ? 2 * e.G() : 0.0) : (i == j ? 2 * e.G() : 0.0);
      INFO("D[" << i << "][" << j << "]");
      CHECK(u.tangent[6 * i + j] == Approx(expected).epsilon(1e-14).margin(0.0));
    }
  CHECK(u.p_wave == Approx(e.oedometric()).epsilon(1e-14));  // K + 4G/3 = λ + 2G
  CHECK(u.p_wave == Approx(e.E / (3 * (1 - 2 * e.nu)) + 4.0 / 3.0 * e.G()).epsilon(1e-14));
  CHECK(u.shear == Approx(8.0e7).epsilon(1e-14));
  CHECK(model->max_p_wave_modulus() == Approx(e.oedometric()).epsilon(1e-14));
  CHECK(model->internal_variables().empty());
  CHECK(model->initial_state().empty());
}

TEST_CASE("linear_elastic: Young's modulus E + (E_frozen - E) S_c at S_c = 0, 0.5, 1", "[mechanical]") {
  const auto model =
      make_model("linear_elastic", "youngs_modulus: 1.0e7, poisson_ratio: 0.2, frozen_youngs_modulus: 1.0e9");
  const Voigt shear{0, 0, 0, 0, 0, 1e-4};
  for (const auto& [S_c, E] : std::vector<std::pair<double, double>>{{0.0, 1.0e7}, {0.5, 5.05e8}, {1.0, 1.0e9}}) {
    INFO("S_c = " << S_c);
    const Elastic e{E, 0.2};
    const Update u = integrate(*model, shear, kStart, S_c);
    CHECK(u.stress[5] - kStart[5] == Approx(2 * e.G() * 1e-4).epsilon(1e-12));
    CHECK(u.shear == Approx(e.G()).epsilon(1e-14));
    CHECK(u.p_wave == Approx(e.oedometric()).epsilon(1e-14));
  }
  // No ice saturation given (no thermal physics): the unfrozen modulus.
  CHECK(integrate(*model, shear, kStart, -1).shear == Approx(Elastic{1.0e7, 0.2}.G()).epsilon(1e-14));
  // The bound is the frozen P-wave modulus; without frozen_youngs_modulus ice changes nothing.
  CHECK(model->max_p_wave_modulus() == Approx(Elastic{1.0e9, 0.2}.oedometric()).epsilon(1e-14));
  const auto plain = make_model("linear_elastic", "youngs_modulus: 1.0e7, poisson_ratio: 0.2");
  CHECK(integrate(*plain, shear, kStart, 1.0).shear == Approx(Elastic{1.0e7, 0.2}.G()).epsilon(1e-14));
  // In rate form a stiffness change alone changes no stress: ice melting at zero strain.
  const Update melted = integrate(*model, {}, kStart, 0.0);
  for (int k = 0; k < 6; ++k) CHECK(melted.stress[k] == kStart[k]);
}

TEST_CASE("the mechanical contract flags the deliberately broken fixture models", "[mechanical][contract]") {
  const auto& registry = broken_registry();
  // Anisotropic (stiffer along x), engineering-strain shear tangent, P-wave modulus above its bound.
  const auto broken_elastic = make_model(registry, "broken_elastic", "youngs_modulus: 1.0e7");
  auto lines = frostmpm::check_mechanical_model_contract(*broken_elastic, 200);
  INFO(frostmpm::join(lines, "\n"));
  CHECK(lines.size() == 4);
  CHECK(any_has(lines, "tangent dstress_yz/dstrain_yz = 5e+06 but finite differences give 1e+07 (central)"));
  CHECK(any_has(lines, "not objective: the rotated input gives stress"));
  CHECK(any_has(lines, "stress_xx and stress_yy do not swap"));
  CHECK(any_has(lines, "p_wave_modulus = 2e+07 is outside (0, max_p_wave_modulus() = 1e+07]"));
  CHECK(any_has(lines, "(and 199 more samples)"));  // every sample breaks the tangent rule

  // Relaxes at zero strain, declares one internal variable but starts two, writes no state,
  // fails below -10 degC, writes no shear modulus without a temperature.
  lines = frostmpm::check_mechanical_model_contract(*make_model(registry, "broken_creep", ""), 200);
  INFO(frostmpm::join(lines, "\n"));
  CHECK(lines.size() == 5);
  CHECK(any_has(lines, "initial_state() has 2 entries but internal_variables() names 1 (creep_strain)"));
  CHECK(any_has(lines, "a zero strain increment changes the stress"));
  CHECK(any_has(lines, "state 'creep_strain' = nan is not finite (not written?) (strain increment"));
  CHECK(any_has(lines, "shear_modulus = nan is not finite (not written?) (strain increment"));
  CHECK(any_has(lines, "p_l given) (and 199 more samples)"));  // the shear modulus line: no T, S_c or p_l given
  CHECK(any_has(lines, "the integration fails (strain increment"));

  // Parameter sets are named in the lines; one line per rule across the sets.
  const auto soft = make_model(registry, "broken_elastic", "youngs_modulus: 1.0e5");
  const auto stiff = make_model(registry, "broken_elastic", "youngs_modulus: 1.0e9");
  lines = frostmpm::check_mechanical_model_contract(
      {{soft.get(), "youngs_modulus=1e5"}, {stiff.get(), "youngs_modulus=1e9"}}, 50);
  INFO(frostmpm::join(lines, "\n"));
  CHECK(lines.size() == 4);
  CHECK(any_has(lines, ", with youngs_modulus=1e5) (and 99 more samples)"));
}

TEST_CASE("an elastoplastic model keeps the contract, a wrong plastic tangent or a throw does not",
          "[mechanical][contract]") {
  // Yield stresses from far below to above the sampled deviators: most points plastic to none.
  for (const double yield : {1e2, 1e4, 1e5, 1e7}) {
    const auto lines = frostmpm::check_mechanical_model_contract(RadialReturn(yield), 500);
    INFO("yield stress " << yield << ": " << frostmpm::join(lines, "\n"));
    CHECK(lines.empty());
  }
  // A 1e-4 error in the plastic part of the tangent only.
  auto lines = frostmpm::check_mechanical_model_contract(RadialReturn(1e4, 1e-4), 500);
  INFO(frostmpm::join(lines, "\n"));
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].rfind("tangent dstress_", 0) == 0);
  lines = frostmpm::check_mechanical_model_contract(Throwing(), 10);
  REQUIRE(lines.size() == 1);
  CHECK(lines[0] == "integrate() throws instead of setting the failure flag: no convergence");
}

TEST_CASE("linear_elastic with modulus_change elastic_strain: melting ice scales the stress by E(S_c)/E of the "
          "last step, a strain increment acts with the new modulus",
          "[mechanical]") {
  const auto model = make_model("linear_elastic", "youngs_modulus: 1.0e7, poisson_ratio: 0.2, frozen_youngs_modulus: "
                                                  "1.0e9, modulus_change: elastic_strain");
  REQUIRE(model->internal_variables() == std::vector<frostmpm::InternalVariable>{{"modulus_of_last_step", "Pa"}});
  auto step = [&](const Voigt& strain, const Voigt& start, double S_c, double state_in, double& state_out) {
    Voigt stress{};
    const double ice[1] = {S_c};
    std::uint8_t failed[1] = {0};
    frostmpm::StressUpdateInput in;
    in.strain_increment = strain;
    in.stress_start = start;
    in.state_start = {&state_in, 1};
    in.ice_saturation = ice;
    frostmpm::StressUpdateOutput out;
    out.stress = stress;
    out.state = {&state_out, 1};
    out.failed = failed;
    model->integrate(in, out);
    return stress;
  };
  // The first step (state 0: no modulus yet) is the rate form, and records E.
  double E = 0;
  const Voigt shear{0, 0, 0, 0, 0, 1e-4};
  Voigt sigma = step(shear, kStart, 1.0, 0.0, E);
  CHECK(E == 1.0e9);
  CHECK(sigma[5] - kStart[5] == Approx(2 * Elastic{1.0e9, 0.2}.G() * 1e-4).epsilon(1e-12));
  // Half the ice melts at no strain: every component scales by E(0.5)/E(1) = 5.05e8/1e9.
  double E_half = 0;
  const Voigt melted = step({}, sigma, 0.5, E, E_half);
  CHECK(E_half == Approx(5.05e8).epsilon(1e-14));
  for (int k = 0; k < 6; ++k) CHECK(melted[k] == Approx(sigma[k] * 0.505).epsilon(1e-14));
  // Refreezing at no strain scales it back.
  double E_back = 0;
  const Voigt frozen = step({}, melted, 1.0, E_half, E_back);
  for (int k = 0; k < 6; ++k) CHECK(frozen[k] == Approx(sigma[k]).epsilon(1e-13));
}
