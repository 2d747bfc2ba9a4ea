// Soil freezing characteristic curves (paper Sec. 3.1, Eq. 25 and Appendix B, Eq. B1).
// Every model is built through the registry exactly as a scene builds it: a YAML model section
// parsed by read_model_section and created with section.create<SfccModel>(registry).
//
// Every registered SFCC model must have at least one parameter set in sfcc_cases() below; a
// newly registered model without one fails "every registered SFCC model has a test case".
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/models/model_contract.hpp"
#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "numerics.hpp"
#include "test_support.hpp"

namespace {

using frostmpm::test::derivative_matches;
using frostmpm::test::linspace;
using frostmpm::test::richardson;

using frostmpm::SfccModel;

/// Builds a model of `kind` from the YAML body of its section, as a scene would:
/// `material: {sfcc: {model: NAME, ...}}` -> read_model_section -> create.
std::shared_ptr<SfccModel> make_sfcc(const std::string& name, const std::string& params) {
  const auto& registry = frostmpm::test::builtin_registry();
  const std::string text = "material:\n  sfcc: {model: " + name + (params.empty() ? "" : ", " + params) + "}\n";
  const auto root = frostmpm::ConfigNode::load_string(text, "sfcc-test.yaml");
  const auto section = frostmpm::read_model_section(registry, SfccModel::kKind, root.child("material").child("sfcc"));
  return section.create<SfccModel>(registry);
}

struct SfccPoint {
  double S = 0, dT = 0, dp = 0;
};

SfccPoint eval(const SfccModel& model, double T, double p = 0.0) {
  double t[1] = {T}, pl[1] = {p}, s[1] = {-1}, dT[1] = {-1}, dp[1] = {-1};
  model.evaluate(t, pl, {s, dT, dp});
  return {s[0], dT[0], dp[0]};
}

// ---- the parameter table -----------------------------------------------------------------------

/// 0 °C in kelvin; Eq. 25 uses (T + 273.15)/273.15.
constexpr double kZeroCelsius = 273.15;

/// Freezing point of Eq. 25 at liquid pressure p: the cryo-suction s vanishes where
/// ln(K/273.15) = −(1 − ρ_c/ρ_l) p / (ρ_c L_f), independent of λ and p_0 (default densities/L_f).
double vgcc_freezing_point(double p) {
  return kZeroCelsius * std::exp(-(1.0 - 917.0 / 1000.0) * p / (917.0 * 3.34e5)) - kZeroCelsius;
}

struct SfccCase {
  std::string params;     ///< YAML flow-map entries after "model: NAME"
  double residual = 0;    ///< S_res reached far below freezing
  /// Temperatures (at liquid pressure p) where the curve is not smooth: excluded from the
  /// finite-difference checks.
  std::function<std::vector<double>(double p)> kinks;
};

const std::map<std::string, std::vector<SfccCase>>& sfcc_cases() {
  static const std::map<std::string, std::vector<SfccCase>> cases = {
      {"exponential",
       {// INTERFROST TH2/TH3 (Eq. B1): W = 0.5 °C, S_res = 0.05, T_0 = 0.
        {"width: 0.5, residual_saturation: 0.05", 0.05, [](double) { return std::vector<double>{0.0}; }},
        {"width: 1.5, residual_saturation: 0.0, freezing_point: -0.3", 0.0,
         [](double) { return std::vector<double>{-0.3}; }}}},
      {"linear",
       {{"freezing_point: 0.0, mushy_end: -1.0, residual_saturation: 0.05", 0.05,
         [](double) { return std::vector<double>{0.0, -1.0}; }},
        {"freezing_point: -0.2, mushy_end: -3.5, residual_saturation: 0.0", 0.0,
         [](double) { return std::vector<double>{-0.2, -3.5}; }}}},
      {"power_law",
       {// Starts at T_f − T_ref = −0.1; floored where (d/T_ref)^−b = S_res:
        // d = 0.1 · 0.02^(−1/0.6) = 0.1 · 50^1.6667 = 67.86 °C.
        {"exponent: 0.6, reference_depression: 0.1, residual_saturation: 0.02", 0.02,
         [](double) { return std::vector<double>{-0.1, -0.1 * std::pow(0.02, -1.0 / 0.6)}; }},
        // No floor (S_res = 0), T_f = −0.5, start at −0.5 − 0.25 = −0.75; at −200 °C
        // S = (199.5/0.25)^−1.2 = 3.3e-4.
        {"exponent: 1.2, reference_depression: 0.25, freezing_point: -0.5", 0.0,
         [](double) { return std::vector<double>{-0.75}; }}}},
      {"van_genuchten_cc",
       {// The paper's rock-freezing set (Sec. 5.1): λ = 0.5, p_0 = 100 kPa, residual 0 (default).
        {"lambda: 0.5, p0: 1.0e5", 0.0, [](double p) { return std::vector<double>{vgcc_freezing_point(p)}; }},
        // Non-integer exponent 1/(1 − λ) = 3.33 and a residual.
        {"lambda: 0.7, p0: 2.0e5, residual_saturation: 0.05", 0.05,
         [](double p) { return std::vector<double>{vgcc_freezing_point(p)}; }}}},
      {"table",
       {// A measured-looking curve: C1 inside (not C2: finite differences skip the points),
        // kinks at its first and last points.
        {"temperatures: [-5, -2, -1, -0.5, 0], saturations: [0.05, 0.1, 0.2, 0.5, 1]", 0.05,
         [](double) { return std::vector<double>{-5.0, -2.0, -1.0, -0.5, 0.0}; }},
        // A plateau (equal saturations) then a steep rise that a cubic spline would overshoot.
        {"temperatures: [-8, -3, -1, -0.2], saturations: [0.02, 0.02, 0.03, 1]", 0.02,
         [](double) { return std::vector<double>{-8.0, -3.0, -1.0, -0.2}; }}}},
  };
  return cases;
}


}  // namespace

TEST_CASE("every registered SFCC model has a test case and builds from the registry", "[sfcc]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto entries = registry.entries(SfccModel::kKind);
  REQUIRE(entries.size() >= 4);  // exponential, linear, power_law, van_genuchten_cc
  for (const auto* entry : entries) {
    INFO("registered SFCC model '" << entry->name << "' (from " << entry->library
                                   << ") needs an entry in sfcc_cases() of " << __FILE__);
    REQUIRE(sfcc_cases().count(entry->name) == 1);
    REQUIRE_FALSE(sfcc_cases().at(entry->name).empty());
    for (const auto& c : sfcc_cases().at(entry->name)) {
      INFO("params: " << c.params);
      std::shared_ptr<SfccModel> model;
      REQUIRE_NOTHROW(model = make_sfcc(entry->name, c.params));
      REQUIRE(model != nullptr);
    }
  }
  // The table must not go stale either: every entry names a registered model.
  for (const auto& [name, cases] : sfcc_cases()) {
    INFO(name);
    CHECK(registry.find(SfccModel::kKind, name) != nullptr);
  }
}

TEST_CASE("SFCC analytic derivatives match finite differences", "[sfcc]") {
  const auto& registry = frostmpm::test::builtin_registry();
  // Dense near freezing, sparser far below; irregular spacing so no sample hits a kink exactly.
  std::vector<double> temperatures = linspace(-3.0, 1.0, 401);
  for (double T : linspace(-150.0, -3.0, 300)) temperatures.push_back(T + 0.0137);
  const std::vector<double> pressures = {0.0, -3.0e4, 2.0e5, 1.5e6};
  const double h_T = 1e-3;      // °C; all curves here vary on scales ≥ 0.1 °C
  const double exclude = 0.02;  // °C around each kink (≫ h_T, the widest stencil point)
  const double h_p = 1e2;       // Pa; Eq. 25 varies on the scale p_0/(1 − ρ_c/ρ_l) ≈ 1e6 Pa
  const double tiny_dT = 1e-4;  // 1/°C: below this, compare absolutely to 1e-10
  const double tiny_dp = 1e-11; // 1/Pa

  int checked = 0;
  for (const auto* entry : registry.entries(SfccModel::kKind)) {
    REQUIRE(sfcc_cases().count(entry->name) == 1);
    for (const auto& c : sfcc_cases().at(entry->name)) {
      const auto model = make_sfcc(entry->name, c.params);
      for (double p : pressures) {
        const auto kinks = c.kinks(p);
        for (double T : temperatures) {
          const bool near_kink = std::any_of(kinks.begin(), kinks.end(),
                                             [&](double k) { return std::abs(T - k) < exclude; });
          if (near_kink) continue;
          const SfccPoint at = eval(*model, T, p);
          const double fd_T = richardson([&](double x) { return eval(*model, x, p).S; }, T, h_T);
          const double fd_p = richardson([&](double x) { return eval(*model, T, x).S; }, p, h_p);
          INFO(entry->name << " {" << c.params << "} at T = " << T << " °C, p_l = " << p
                           << " Pa: S_l = " << at.S);
          INFO("dS/dT analytic " << at.dT << " vs fd " << fd_T);
          CHECK(derivative_matches(at.dT, fd_T, tiny_dT));
          INFO("dS/dp analytic " << at.dp << " vs fd " << fd_p);
          CHECK(derivative_matches(at.dp, fd_p, tiny_dp));
          ++checked;
        }
      }
    }
  }
  CHECK(checked > 5000);
}

TEST_CASE("SFCC models are fully thawed at and above the freezing point", "[sfcc]") {
  const auto& registry = frostmpm::test::builtin_registry();
  for (const auto* entry : registry.entries(SfccModel::kKind)) {
    REQUIRE(sfcc_cases().count(entry->name) == 1);
    for (const auto& c : sfcc_cases().at(entry->name)) {
      const auto model = make_sfcc(entry->name, c.params);
      const double Tf = model->freezing_point();
      for (double T : {Tf, Tf + 1e-12, Tf + 1e-6, Tf + 0.01, Tf + 0.3, Tf + 1.0, Tf + 25.0, 100.0}) {
        if (T < Tf) continue;
        INFO(entry->name << " {" << c.params << "} T_f = " << Tf << ", T = " << T);
        const SfccPoint at = eval(*model, T, 0.0);
        CHECK(at.S == 1.0);
        CHECK(at.dT == 0.0);
        CHECK(at.dp == 0.0);
      }
      // Just below the freezing point the soil has started to freeze (or, for the power law,
      // is still at 1 until T_f − T_ref); never above 1.
      const SfccPoint below = eval(*model, Tf - 5.0, 0.0);
      INFO(entry->name << " {" << c.params << "}");
      CHECK(below.S < 1.0);
    }
  }
}

TEST_CASE("SFCC models tend to the residual saturation far below freezing", "[sfcc]") {
  const auto& registry = frostmpm::test::builtin_registry();
  for (const auto* entry : registry.entries(SfccModel::kKind)) {
    REQUIRE(sfcc_cases().count(entry->name) == 1);
    for (const auto& c : sfcc_cases().at(entry->name)) {
      const auto model = make_sfcc(entry->name, c.params);
      INFO(entry->name << " {" << c.params << "}");
      const double S = eval(*model, -200.0, 0.0).S;
      CHECK(S >= c.residual);
      CHECK(S - c.residual <= 1e-3);
    }
  }
  // Eq. 25 has no residual: S_l only decays like 1/s, so check a milder statement at −50 °C
  // (s = 3062.78 · ln(273.15/223.15) = 619.2, S_l = (1 + s²)^−1/2 ≈ 1.615e-3).
  const auto vgcc = make_sfcc("van_genuchten_cc", "lambda: 0.5, p0: 1.0e5");
  CHECK(eval(*vgcc, -50.0, 0.0).S < 0.01);
  CHECK(eval(*vgcc, -50.0, 0.0).S > 0.0);
}

TEST_CASE("SFCC models are monotone in temperature and bounded by S_res and 1", "[sfcc]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto sweep = linspace(-250.0, 5.0, 25501);  // 0.01 °C steps
  for (const auto* entry : registry.entries(SfccModel::kKind)) {
    REQUIRE(sfcc_cases().count(entry->name) == 1);
    for (const auto& c : sfcc_cases().at(entry->name)) {
      const auto model = make_sfcc(entry->name, c.params);
      // One batch for the whole sweep, with an empty pressure span (taken as p_l = 0).
      std::vector<double> S(sweep.size()), dT(sweep.size()), dp(sweep.size());
      model->evaluate(sweep, {}, {S, dT, dp});
      int violations = 0, out_of_bounds = 0, negative_slopes = 0;
      for (std::size_t i = 0; i < sweep.size(); ++i) {
        if (i > 0 && S[i] < S[i - 1]) ++violations;
        if (S[i] < c.residual || S[i] > 1.0) ++out_of_bounds;
        if (dT[i] < 0.0) ++negative_slopes;
      }
      INFO(entry->name << " {" << c.params << "}");
      CHECK(violations == 0);
      CHECK(out_of_bounds == 0);
      CHECK(negative_slopes == 0);
      CHECK(S.front() < S.back());
    }
  }
}

TEST_CASE("SFCC batch evaluation equals pointwise evaluation, empty pressure means zero", "[sfcc]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const std::vector<double> T = {-40.0, -7.5, -2.0, -0.6, -0.05, 0.0, 0.4, 3.0};
  const std::vector<double> zeros(T.size(), 0.0);
  for (const auto* entry : registry.entries(SfccModel::kKind)) {
    REQUIRE(sfcc_cases().count(entry->name) == 1);
    const auto model = make_sfcc(entry->name, sfcc_cases().at(entry->name).front().params);
    std::vector<double> S(T.size()), dT(T.size()), dp(T.size());
    std::vector<double> S0(T.size()), dT0(T.size()), dp0(T.size());
    model->evaluate(T, {}, {S, dT, dp});
    model->evaluate(T, zeros, {S0, dT0, dp0});
    for (std::size_t i = 0; i < T.size(); ++i) {
      INFO(entry->name << " at T = " << T[i]);
      const SfccPoint single = eval(*model, T[i], 0.0);
      CHECK(S[i] == single.S);
      CHECK(dT[i] == single.dT);
      CHECK(dp[i] == single.dp);
      CHECK(S0[i] == S[i]);
      CHECK(dT0[i] == dT[i]);
      CHECK(dp0[i] == dp[i]);
    }
  }
}

TEST_CASE("exponential SFCC is cut to 1 above the freezing point (not symmetric)", "[sfcc]") {
  // The Gaussian of Eq. B1 is symmetric about T_0; without the cut, thawed soil at +0.3 °C
  // would have the same S_l as frozen soil at −0.3 °C.
  const auto model = make_sfcc("exponential", "width: 0.5, residual_saturation: 0.05");
  const SfccPoint warm = eval(*model, 0.3, 0.0);
  const SfccPoint cold = eval(*model, -0.3, 0.0);
  CHECK(warm.S == 1.0);
  CHECK(warm.dT == 0.0);
  // S_l(−0.3) = 0.05 + 0.95 · exp(−(−0.3/0.5)²) = 0.05 + 0.95 · exp(−0.36)
  //           = 0.05 + 0.95 · 0.697676 = 0.712793
  CHECK(cold.S < 1.0);
  CHECK(cold.S == Approx(0.05 + 0.95 * 0.6976763261).epsilon(1e-9));
  CHECK(cold.dT > 0.0);
}

TEST_CASE("linear SFCC: hand values and cross-parameter validation", "[sfcc]") {
  const auto model = make_sfcc("linear", "freezing_point: 0.0, mushy_end: -1.0, residual_saturation: 0.05");
  // Slope (1 − 0.05)/(0 − (−1)) = 0.95 per °C; at −0.25 °C: 0.05 + 0.95 · 0.75 = 0.7625.
  const SfccPoint mid = eval(*model, -0.25, 0.0);
  CHECK(mid.S == Approx(0.7625).epsilon(1e-14));
  CHECK(mid.dT == Approx(0.95).epsilon(1e-14));
  CHECK(eval(*model, -1.0, 0.0).S == 0.05);
  CHECK(eval(*model, -3.0, 0.0).S == 0.05);
  CHECK(eval(*model, -3.0, 0.0).dT == 0.0);

  // mushy_end at or above freezing_point is rejected, pointing at mushy_end.
  try {
    make_sfcc("linear", "freezing_point: 0.0, mushy_end: 0.5, residual_saturation: 0.05");
    FAIL("expected an InputError for mushy_end >= freezing_point");
  } catch (const frostmpm::InputError& e) {
    const std::string message = e.what();
    INFO(message);
    CHECK(message.find("material.sfcc.mushy_end") != std::string::npos);
    CHECK(message.find("sfcc-test.yaml:2") != std::string::npos);
    CHECK(message.find("below freezing_point") != std::string::npos);
  }
}

TEST_CASE("power-law SFCC: hand values", "[sfcc]") {
  const auto model = make_sfcc("power_law", "exponent: 0.6, reference_depression: 0.1, residual_saturation: 0.02");
  // T = −0.5: depression d = 0.5, d/T_ref = 5, S = 5^−0.6 = exp(−0.6 · 1.609438) = exp(−0.965663)
  //         = 0.380731; dS/dT = b S / d = 0.6 · 0.380731 / 0.5 = 0.456877.
  const SfccPoint at = eval(*model, -0.5, 0.0);
  CHECK(at.S == Approx(std::pow(5.0, -0.6)).epsilon(1e-14));
  CHECK(at.S == Approx(0.380731).epsilon(1e-5));
  CHECK(at.dT == Approx(0.456877).epsilon(1e-5));
  // Still thawed between T_f and T_f − T_ref; floored far below.
  CHECK(eval(*model, -0.05, 0.0).S == 1.0);
  CHECK(eval(*model, -0.1, 0.0).S == 1.0);
  CHECK(eval(*model, -100.0, 0.0).S == 0.02);
  CHECK(eval(*model, -100.0, 0.0).dT == 0.0);
}

TEST_CASE("van Genuchten-Clausius-Clapeyron SFCC reproduces hand-computed Eq. 25", "[sfcc]") {
  // The paper's rock-freezing parameters: λ = 0.5, p_0 = 100 kPa, ρ_c = 917 kg/m³,
  // ρ_l = 1000 kg/m³, L_f = 3.34e5 J/kg, p_l = 0.
  const auto model = make_sfcc("van_genuchten_cc",
                               "lambda: 0.5, p0: 100000, ice_density: 917, water_density: 1000, "
                               "latent_heat: 3.34e5");
  // Common factor: ρ_c L_f / p_0 = 917 · 3.34e5 / 1e5 = 3062.78.
  // Exponent 1/(1 − λ) = 1/0.5 = 2, outer power −λ = −0.5, so S = (1 + s²)^−0.5.
  //
  // T = −1 °C:
  //   ln(272.15/273.15) = ln(0.99633900) = −0.00366771 (−3.66770996e-3)
  //   s  = 3062.78 · 0.00366771 = 11.2334 (11.23338872)
  //   s² = 126.189 (126.1890220)
  //   S  = (1 + 126.189)^−0.5 = 127.189^−0.5 = 1/11.27781 = 0.0886697 (0.08866968915)
  //   ∂S/∂T = −s (1+s²)^−1.5 · (−3062.78/272.15) = −0.00783134 · (−11.2540) = 0.0881341
  //
  // T = −5 °C:
  //   ln(268.15/273.15) = ln(0.98169504) = −0.0184746 (−1.84745694e-2)
  //   s  = 3062.78 · 0.0184746 = 56.5835 (56.58354171)
  //   s² = 3201.70 (3201.697192)
  //   S  = (1 + 3201.70)^−0.5 = 3202.70^−0.5 = 1/56.59238 = 0.0176702 (0.01767022423)
  //   ∂S/∂T = −s (1+s²)^−1.5 · (−3062.78/268.15) = −3.12188e-4 · (−11.4219) = 3.56578e-3
  const double hand_S_m1 = 1.0 / std::sqrt(1.0 + 11.23338872 * 11.23338872);
  const double hand_S_m5 = 1.0 / std::sqrt(1.0 + 56.58354171 * 56.58354171);
  CHECK(hand_S_m1 == Approx(0.0886697).epsilon(1e-6));
  CHECK(hand_S_m5 == Approx(0.0176702).epsilon(1e-5));

  const SfccPoint m1 = eval(*model, -1.0, 0.0);
  const SfccPoint m5 = eval(*model, -5.0, 0.0);
  REQUIRE(m1.S == Approx(hand_S_m1).epsilon(1e-5));
  REQUIRE(m5.S == Approx(hand_S_m5).epsilon(1e-5));
  // The values the app printed to its CSV.
  CHECK(m1.S == Approx(0.08866968915).epsilon(1e-9));
  CHECK(m5.S == Approx(0.01767022423).epsilon(1e-9));
  CHECK(m1.dT == Approx(0.0881341).epsilon(1e-5));
  CHECK(m5.dT == Approx(3.56578e-3).epsilon(1e-5));

  // ∂S/∂p at p_l = 0: −s(1+s²)^−1.5 · (−(1 − 917/1000)/p_0) = −0.00783134 · (−0.083/1e5)
  //                 = 6.50002e-9 1/Pa.
  CHECK(m1.dp == Approx(6.50002e-9).epsilon(1e-5));

  // Liquid pressure p_l = 100 kPa at T = −1 °C: s = −0.083 · 1e5/1e5 + 11.23339 = 11.15039,
  // s² = 124.3312, S = 125.3312^−0.5 = 0.0893245 — positive pressure thaws.
  const SfccPoint pressed = eval(*model, -1.0, 1.0e5);
  CHECK(pressed.S == Approx(0.0893245).epsilon(1e-5));
  CHECK(pressed.S > m1.S);
  CHECK(pressed.dp > 0.0);
  CHECK(pressed.dp == Approx(6.59598e-9).epsilon(1e-5));
  // Suction (p_l < 0) freezes more.
  CHECK(eval(*model, -1.0, -1.0e5).S < m1.S);
  // The pressure slope agrees with a difference quotient at p_l ≠ 0.
  const double fd = richardson([&](double p) { return eval(*model, -1.0, p).S; }, 1.0e5, 1.0e2);
  CHECK(derivative_matches(pressed.dp, fd, 1e-11));
  // S_l is non-decreasing in p_l over a wide range.
  double previous = 0.0;
  for (double p : linspace(-2.0e6, 2.0e6, 401)) {
    const double S = eval(*model, -1.0, p).S;
    CHECK(S >= previous);
    previous = S;
  }
}

TEST_CASE("van Genuchten-Clausius-Clapeyron freezing point moves with liquid pressure", "[sfcc]") {
  const auto model = make_sfcc("van_genuchten_cc", "lambda: 0.5, p0: 1.0e5");
  // Clausius–Clapeyron: under 1 MPa of liquid pressure the freezing point drops to
  // 273.15 · exp(−0.083 · 1e6/(917 · 3.34e5)) − 273.15 = 273.15 · (exp(−2.71e-4) − 1) = −0.0740 °C.
  const double Tf = vgcc_freezing_point(1.0e6);
  CHECK(Tf == Approx(-0.0740).margin(2e-4));
  CHECK(eval(*model, Tf + 1e-4, 1.0e6).S == 1.0);
  CHECK(eval(*model, Tf - 1e-3, 1.0e6).S < 1.0);
  // Suction raises it.
  CHECK(eval(*model, 0.0, -1.0e5).S < 1.0);
}

TEST_CASE("every SFCC parameter set keeps the contract `frostmpm test-model` checks", "[sfcc][contract]") {
  const auto& registry = frostmpm::test::builtin_registry();
  for (const auto* entry : registry.entries(SfccModel::kKind))
    for (const auto& c : sfcc_cases().at(entry->name)) {
      const auto model = make_sfcc(entry->name, c.params);
      const double T_f = model->freezing_point();
      const auto violations = frostmpm::check_sfcc_contract(*model, T_f - 20.0, T_f + 5.0);
      INFO(entry->name << " {" << c.params << "}: " << frostmpm::join(violations, "\n"));
      CHECK(violations.empty());
    }
}

TEST_CASE("tabulated SFCC is SciPy's PCHIP between its points and honest outside them", "[sfcc][table]") {
  const auto model = make_sfcc("table", "temperatures: [-5, -2, -1, -0.5, 0], saturations: [0.05, 0.1, 0.2, 0.5, 1]");
  CHECK(model->freezing_point() == 0.0);
  // scipy.interpolate.PchipInterpolator on the same points (value, derivative).
  const double reference[][3] = {{-4.0, 0.055755755755755754, 0.01141141141141141},
                                 {-1.5, 0.13077819198508855, 0.09534016775396087},
                                 {-0.75, 0.3147629310344828, 0.665948275862069},
                                 {-0.1, 0.8832000000000001, 1.134}};
  for (const auto& r : reference) {
    INFO("T = " << r[0]);
    CHECK(eval(*model, r[0]).S == Approx(r[1]).epsilon(1e-13));
    CHECK(eval(*model, r[0]).dT == Approx(r[2]).epsilon(1e-12));
  }
  // The points themselves, below the table (its first value) and thawed above it.
  CHECK(eval(*model, -2.0).S == Approx(0.1).epsilon(1e-15));
  CHECK(eval(*model, -30.0).S == 0.05);
  CHECK(eval(*model, -30.0).dT == 0.0);
  CHECK(eval(*model, 0.5).S == 1.0);

  // No overshoot where the data jump: a plateau stays flat (a spline would dip below it).
  const auto steep = make_sfcc("table", "temperatures: [-3, -1, 0], saturations: [0.1, 0.1, 1]");
  CHECK(eval(*steep, -2.0).S == Approx(0.1).epsilon(1e-15));  // PCHIP: 0.1
  CHECK(eval(*steep, -0.5).S == Approx(0.4).epsilon(1e-13));  // PCHIP: 0.4
  for (double T = -3.0; T <= 0.0; T += 0.01) {
    const auto point = eval(*steep, T);
    CHECK(point.S >= 0.1 - 1e-15);
    CHECK(point.S <= 1.0);
  }
}

TEST_CASE("tabulated SFCC reads a CSV file next to the scene and refuses broken tables", "[sfcc][table]") {
  frostmpm::test::TempDir dir;
  frostmpm::test::write_file(dir.file("curve.csv"), "temperature_degC,liquid_saturation\n-5, 0.05\n-2,0.1\n"
                                                   "# measured 2024\n-1,0.2\n-0.5,0.5\n0,1\n");
  const auto& registry = frostmpm::test::builtin_registry();
  const auto build = [&](const std::string& body) {
    frostmpm::test::write_file(dir.file("scene.yaml"), "material:\n  sfcc: {model: table" + (body.empty() ? "" : ", " + body) + "}\n");
    const auto root = frostmpm::ConfigNode::load_file(dir.file("scene.yaml"));
    return frostmpm::read_model_section(registry, SfccModel::kKind, root.child("material").child("sfcc"))
        .create<SfccModel>(registry);
  };
  const auto from_file = build("file: curve.csv");  // relative to the scene's folder
  const auto inline_table =
      make_sfcc("table", "temperatures: [-5, -2, -1, -0.5, 0], saturations: [0.05, 0.1, 0.2, 0.5, 1]");
  for (const double T : {-4.0, -1.5, -0.75, -0.1}) CHECK(eval(*from_file, T).S == eval(*inline_table, T).S);

  const auto refused = [&](const std::string& body, const std::string& text) {
    INFO(body);
    try {
      build(body);
      FAIL("accepted");
    } catch (const frostmpm::InputError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(text) != std::string::npos);
      CHECK(std::string(e.what()).find("material.sfcc") != std::string::npos);
    }
  };
  refused("temperatures: [-1, 0], saturations: [0.5, 1], file: curve.csv", "not both");
  refused("", "not neither");
  refused("temperatures: [-1, 0, 1], saturations: [0.5, 1]", "3 temperatures but 2 saturations");
  refused("temperatures: [0, -1], saturations: [0.5, 1]", "increase strictly");
  refused("temperatures: [-2, -1, 0], saturations: [0.5, 0.3, 1]", "decreases on warming");
  refused("temperatures: [-1, 0], saturations: [0.5, 0.9]", "must reach 1");
  refused("temperatures: [-1, 0], saturations: [-0.5, 1]", "outside [0, 1]");
  refused("temperatures: [0], saturations: [1]", "at least 2 points");
  refused("file: missing.csv", "cannot read");
  frostmpm::test::write_file(dir.file("bad.csv"), "T,S\n-1,0.5\n0,one\n");
  refused("file: bad.csv", "bad.csv:3");
}
