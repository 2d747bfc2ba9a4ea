// Hydraulic conductivity k = k_a(φ) k_r(S_l, φ): relative models (paper Eq. 26, van
// Genuchten–Mualem; Eq. B2, impedance) and absolute models (Eq. 27, Kozeny–Carman; constant
// conductivity; constant intrinsic permeability). Every model is built through the registry
// as a scene builds it (YAML model section -> read_model_section -> create).
//
// Every registered relative/absolute permeability model must have an entry in the tables
// below; a newly registered model without one fails the "has a test case" tests.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/models/model_contract.hpp"
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "numerics.hpp"
#include "test_support.hpp"

namespace {

using frostmpm::test::derivative_matches;
using frostmpm::test::linspace;
using frostmpm::test::richardson;

using frostmpm::AbsolutePermeabilityModel;
using frostmpm::RelativePermeabilityModel;

/// `material: {<kind>: {model: NAME, params}}` -> read_model_section -> create, as in a scene.
template <class Interface>
std::shared_ptr<Interface> make_model(const std::string& name, const std::string& params) {
  const auto& registry = frostmpm::test::builtin_registry();
  const std::string kind = Interface::kKind;
  const std::string text =
      "material:\n  " + kind + ": {model: " + name + (params.empty() ? "" : ", " + params) + "}\n";
  const auto root = frostmpm::ConfigNode::load_string(text, "permeability-test.yaml");
  const auto section = frostmpm::read_model_section(registry, kind, root.child("material").child(kind));
  return section.create<Interface>(registry);
}

std::shared_ptr<RelativePermeabilityModel> make_relative(const std::string& name, const std::string& params) {
  return make_model<RelativePermeabilityModel>(name, params);
}
std::shared_ptr<AbsolutePermeabilityModel> make_absolute(const std::string& name, const std::string& params) {
  return make_model<AbsolutePermeabilityModel>(name, params);
}

struct Value {
  double k = 0, dk = 0;
};

Value relative(const RelativePermeabilityModel& model, double S, double phi) {
  double s[1] = {S}, p[1] = {phi}, k[1] = {-1}, dk[1] = {-1};
  model.evaluate(s, p, k, dk);
  return {k[0], dk[0]};
}

Value absolute(const AbsolutePermeabilityModel& model, double phi) {
  double p[1] = {phi}, k[1] = {-1}, dk[1] = {-1};
  model.evaluate(p, k, dk);
  return {k[0], dk[0]};
}

struct RelativeCase {
  std::string params;
  double floor = 0;  ///< k_r floor of this parameter set
  double S_max = 1;  ///< finite differences only below this (van Genuchten–Mualem: slope → ∞ at 1)
};

const std::map<std::string, std::vector<RelativeCase>>& relative_cases() {
  static const std::map<std::string, std::vector<RelativeCase>> cases = {
      {"impedance",
       {// INTERFROST TH2/TH3 (Eq. B2): Ω = 50, floor 1e-6 (default).
        {"omega: 50", 1e-6, 0.999},
        {"omega: 80, floor: 1.0e-9", 1e-9, 0.999}}},
      {"van_genuchten_mualem",
       {{"m: 0.5", 1e-12, 0.99},  // default floor 1e-12
        {"m: 0.8, floor: 1.0e-8", 1e-8, 0.99}}},
  };
  return cases;
}

struct AbsoluteCase {
  std::string params;
};

const std::map<std::string, std::vector<AbsoluteCase>>& absolute_cases() {
  static const std::map<std::string, std::vector<AbsoluteCase>> cases = {
      {"constant", {{"k0: 1.0e-5"}}},
      {"intrinsic", {{"permeability: 1.3e-10"}, {"permeability: 2.0e-12, fluid_viscosity: 1.0e-3"}}},
      {"kozeny_carman", {{"k0: 1.0e-6, reference_porosity: 0.37"}, {"k0: 2.0e-9, reference_porosity: 0.1"}}},
  };
  return cases;
}


const std::vector<double> kPorosities = {0.2, 0.37, 0.6};

}  // namespace

TEST_CASE("every registered permeability model has a test case and builds", "[permeability]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto rel = registry.entries(RelativePermeabilityModel::kKind);
  const auto abs = registry.entries(AbsolutePermeabilityModel::kKind);
  REQUIRE(rel.size() >= 2);
  REQUIRE(abs.size() >= 3);
  for (const auto* entry : rel) {
    INFO("relative permeability model '" << entry->name << "' needs an entry in relative_cases() of " << __FILE__);
    REQUIRE(relative_cases().count(entry->name) == 1);
    for (const auto& c : relative_cases().at(entry->name)) {
      INFO(c.params);
      REQUIRE_NOTHROW(make_relative(entry->name, c.params));
    }
  }
  for (const auto* entry : abs) {
    INFO("absolute permeability model '" << entry->name << "' needs an entry in absolute_cases() of " << __FILE__);
    REQUIRE(absolute_cases().count(entry->name) == 1);
    for (const auto& c : absolute_cases().at(entry->name)) {
      INFO(c.params);
      REQUIRE_NOTHROW(make_absolute(entry->name, c.params));
    }
  }
  for (const auto& [name, _] : relative_cases()) CHECK(registry.find(RelativePermeabilityModel::kKind, name));
  for (const auto& [name, _] : absolute_cases()) CHECK(registry.find(AbsolutePermeabilityModel::kKind, name));
}

TEST_CASE("relative permeability dk_r/dS_l matches finite differences", "[permeability]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const double h = 1e-4;        // in S_l
  const double exclude = 2e-3;  // around the floor kink (≫ h)
  int checked = 0, floored = 0;
  for (const auto* entry : registry.entries(RelativePermeabilityModel::kKind)) {
    REQUIRE(relative_cases().count(entry->name) == 1);
    for (const auto& c : relative_cases().at(entry->name)) {
      const auto model = make_relative(entry->name, c.params);
      for (double phi : kPorosities) {
        for (double S : linspace(0.003, c.S_max, 997)) {
          // Skip the neighbourhood of the floor kink: k_r is monotone, so the kink lies
          // within ±exclude exactly when one side is on the floor and the other is not.
          const bool below_on_floor = relative(*model, S - exclude, phi).k <= c.floor;
          const bool above_on_floor = relative(*model, S + exclude, phi).k <= c.floor;
          if (below_on_floor != above_on_floor) continue;
          const Value at = relative(*model, S, phi);
          const double fd = richardson([&](double x) { return relative(*model, x, phi).k; }, S, h);
          INFO(entry->name << " {" << c.params << "} S_l = " << S << ", φ = " << phi << ": k_r = " << at.k
                           << ", dk_r/dS analytic " << at.dk << " vs fd " << fd);
          CHECK(derivative_matches(at.dk, fd, 1e-4));
          ++checked;
          if (below_on_floor) ++floored;
        }
      }
    }
  }
  CHECK(checked > 5000);
  CHECK(floored > 0);  // the floored range was sampled too (there the slope must be 0)
}

TEST_CASE("absolute permeability dk_a/dphi matches finite differences", "[permeability]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const double h = 1e-4;  // in φ
  int checked = 0;
  for (const auto* entry : registry.entries(AbsolutePermeabilityModel::kKind)) {
    REQUIRE(absolute_cases().count(entry->name) == 1);
    for (const auto& c : absolute_cases().at(entry->name)) {
      const auto model = make_absolute(entry->name, c.params);
      const double scale = absolute(*model, 0.37).k;  // compare absolutely below 1e-3 of this
      for (double phi : linspace(0.02, 0.9, 881)) {
        const Value at = absolute(*model, phi);
        const double fd = richardson([&](double x) { return absolute(*model, x).k; }, phi, h);
        INFO(entry->name << " {" << c.params << "} φ = " << phi << ": k_a = " << at.k << ", dk_a/dφ analytic "
                         << at.dk << " vs fd " << fd);
        CHECK(at.k > 0.0);
        CHECK(derivative_matches(at.dk, fd, 1e-3 * scale));
        ++checked;
      }
    }
  }
  CHECK(checked > 3000);
}

TEST_CASE("relative permeability is monotone in S_l, floored, and 1 when thawed", "[permeability]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto sweep = linspace(0.0, 1.0, 10001);
  for (const auto* entry : registry.entries(RelativePermeabilityModel::kKind)) {
    REQUIRE(relative_cases().count(entry->name) == 1);
    for (const auto& c : relative_cases().at(entry->name)) {
      const auto model = make_relative(entry->name, c.params);
      for (double phi : kPorosities) {
        INFO(entry->name << " {" << c.params << "} φ = " << phi);
        // One batch for the whole sweep.
        const std::vector<double> porosity(sweep.size(), phi);
        std::vector<double> k(sweep.size()), dk(sweep.size());
        model->evaluate(sweep, porosity, k, dk);
        int decreasing = 0, below_floor = 0, above_one = 0, negative_slope = 0;
        for (std::size_t i = 0; i < sweep.size(); ++i) {
          if (i > 0 && k[i] < k[i - 1]) ++decreasing;
          if (k[i] < c.floor) ++below_floor;
          if (k[i] > 1.0) ++above_one;
          if (dk[i] < 0.0) ++negative_slope;
        }
        CHECK(decreasing == 0);
        CHECK(below_floor == 0);
        CHECK(above_one == 0);
        CHECK(negative_slope == 0);
        // Thawed: k_r(1) = 1. Deep in the frozen range: exactly the floor, zero slope.
        CHECK(relative(*model, 1.0, phi).k == Approx(1.0).epsilon(1e-12));
        CHECK(relative(*model, 0.0, phi).k == c.floor);
        CHECK(relative(*model, 0.0, phi).dk == 0.0);
        CHECK(relative(*model, 0.002, phi).k == c.floor);
        // S_l a little above 1 (round-off from a solver or an interpolation) stays thawed: k_r
        // never exceeds 1 (impedance used to return 10^(Ω φ (S_l − 1)) > 1 there).
        for (double S : {1.0 + 1e-12, 1.0 + 1e-6, 1.01, 1.5}) {
          INFO("S_l = " << S);
          CHECK(relative(*model, S, phi).k == 1.0);
          CHECK(relative(*model, S, phi).dk == 0.0);
        }
      }
    }
  }
}

TEST_CASE("impedance k_r keeps porosity in the exponent (Eq. B2)", "[permeability]") {
  // INTERFROST: Ω = 50, φ = 0.37, floor 1e-6.
  const auto interfrost = make_relative("impedance", "omega: 50, floor: 1.0e-6");
  const auto unfloored = make_relative("impedance", "omega: 50, floor: 1.0e-12");
  // S_l = 0.5: exponent −Ω φ (1 − S_l) = −50 · 0.37 · 0.5 = −9.25, 10^−9.25 = 5.62341e-10,
  // below the 1e-6 floor, so INTERFROST's k_r is the floor.
  CHECK(relative(*interfrost, 0.5, 0.37).k == 1e-6);
  CHECK(relative(*interfrost, 0.5, 0.37).dk == 0.0);
  // With a 1e-12 floor the unfloored value shows: 5.62341e-10, and
  // dk_r/dS = ln(10) Ω φ k_r = 2.302585 · 18.5 · 5.62341e-10 = 2.39545e-8.
  CHECK(relative(*unfloored, 0.5, 0.37).k == Approx(5.62341e-10).epsilon(1e-5));
  CHECK(relative(*unfloored, 0.5, 0.37).dk == Approx(2.39545e-8).epsilon(1e-5));
  // S_l = 0.9: 10^(−50 · 0.37 · 0.1) = 10^−1.85 = 0.0141254; with φ = 0.2: 10^(−50 · 0.2 · 0.1)
  // = 10^−1 = 0.1. Changing φ changes k_r.
  CHECK(relative(*interfrost, 0.9, 0.37).k == Approx(0.0141254).epsilon(1e-5));
  CHECK(relative(*interfrost, 0.9, 0.2).k == Approx(0.1).epsilon(1e-12));
  CHECK(relative(*interfrost, 0.9, 0.2).k != relative(*interfrost, 0.9, 0.37).k);
  // Thawed soil does not depend on φ.
  CHECK(relative(*interfrost, 1.0, 0.2).k == 1.0);
  CHECK(relative(*interfrost, 1.0, 0.37).k == 1.0);
  // The batch path reads each particle's own porosity.
  const std::vector<double> S = {0.9, 0.9}, phi = {0.37, 0.2};
  std::vector<double> k(2), dk(2);
  interfrost->evaluate(S, phi, k, dk);
  CHECK(k[0] == Approx(0.0141254).epsilon(1e-5));
  CHECK(k[1] == Approx(0.1).epsilon(1e-12));
}

TEST_CASE("van Genuchten-Mualem k_r hand value (Eq. 26)", "[permeability]") {
  const auto model = make_relative("van_genuchten_mualem", "m: 0.5");
  // S_l = 0.5, m = 0.5: S^(1/m) = 0.25; 1 − 0.25 = 0.75; 0.75^0.5 = 0.866025;
  // 1 − 0.866025 = 0.133975; squared 0.0179492; times √0.5 = 0.707107 -> k_r = 0.0126920.
  const Value at = relative(*model, 0.5, 0.37);
  CHECK(at.k == Approx(0.0126920).epsilon(1e-5));
  // dk_r/dS = g²/(2√S) + 2√S g w^(m−1) S^(1/m−1), g = 0.133975, w = 0.75:
  //         = 0.0179492/1.414214 + 2 · 0.707107 · 0.133975 · 1.154701 · 0.5
  //         = 0.0126920 + 0.109390 = 0.122082
  CHECK(at.dk == Approx(0.122082).epsilon(1e-5));
  // Porosity does not enter Eq. 26.
  CHECK(relative(*model, 0.5, 0.1).k == at.k);
  // S_l above 1 (round-off from a solver) is treated as thawed.
  CHECK(relative(*model, 1.0 + 1e-12, 0.37).k == 1.0);
}

TEST_CASE("Kozeny-Carman returns k0 at the reference porosity and grows with porosity", "[permeability]") {
  const auto model = make_absolute("kozeny_carman", "k0: 1.0e-6, reference_porosity: 0.37");
  CHECK(absolute(*model, 0.37).k == Approx(1.0e-6).epsilon(1e-13));
  // Implemented form k_a = k0 (1 − φ0)²/φ0³ · φ³/(1 − φ)² (Kozeny–Carman; the paper's Eq. 27
  // typesets (1 − φ²), see the plugin's header). At φ = 0.5:
  //   (1 − 0.37)²/0.37³ = 0.3969/0.050653 = 7.835666;  0.5³/0.5² = 0.5;  k_a = 3.917833e-6.
  CHECK(absolute(*model, 0.5).k == Approx(3.917833e-6).epsilon(1e-6));
  double previous = 0.0;
  for (double phi : linspace(0.01, 0.95, 200)) {
    const Value at = absolute(*model, phi);
    CHECK(at.k > previous);
    CHECK(at.dk > 0.0);
    previous = at.k;
  }
}

TEST_CASE("constant and intrinsic absolute permeability", "[permeability]") {
  const auto constant = make_absolute("constant", "k0: 1.0e-5");
  for (double phi : {0.1, 0.37, 0.8}) {
    CHECK(absolute(*constant, phi).k == 1.0e-5);
    CHECK(absolute(*constant, phi).dk == 0.0);
  }
  // INTERFROST's 1.3e-10 is an intrinsic permeability [m²]. K = k ρ g / μ:
  //   1.3e-10 · 1000 = 1.3e-7;  · 9.81 = 1.2753e-6;  / 1.793e-3 = 7.11266e-4 m/s.
  const auto intrinsic = make_absolute("intrinsic", "permeability: 1.3e-10");
  CHECK(absolute(*intrinsic, 0.37).k == Approx(7.1127e-4).epsilon(1e-4));
  CHECK(absolute(*intrinsic, 0.37).k == Approx(7.11266e-4).epsilon(1e-5));
  CHECK(absolute(*intrinsic, 0.37).dk == 0.0);
  // Non-default fluid: 2e-12 · 1020 · 9.8 / 1e-3 = 1.99920e-5 m/s.
  const auto other = make_absolute("intrinsic",
                                   "permeability: 2.0e-12, fluid_density: 1020, gravity: 9.8, fluid_viscosity: 1.0e-3");
  CHECK(absolute(*other, 0.3).k == Approx(1.99920e-5).epsilon(1e-5));
}

TEST_CASE("every permeability parameter set keeps the contract `frostmpm test-model` checks", "[permeability][contract]") {
  const auto& registry = frostmpm::test::builtin_registry();
  for (const auto* entry : registry.entries(RelativePermeabilityModel::kKind))
    for (const auto& c : relative_cases().at(entry->name)) {
      const auto violations = frostmpm::check_relative_permeability_contract(*make_relative(entry->name, c.params));
      INFO(entry->name << " {" << c.params << "}: " << frostmpm::join(violations, "\n"));
      CHECK(violations.empty());
    }
  for (const auto* entry : registry.entries(AbsolutePermeabilityModel::kKind))
    for (const auto& c : absolute_cases().at(entry->name)) {
      const auto violations = frostmpm::check_absolute_permeability_contract(*make_absolute(entry->name, c.params));
      INFO(entry->name << " {" << c.params << "}: " << frostmpm::join(violations, "\n"));
      CHECK(violations.empty());
    }
}
