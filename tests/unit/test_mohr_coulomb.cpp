// mohr_coulomb and mohr_coulomb_ice (paper Sec. 3.3, Eqs. 30–37) against closed forms: the
// main-plane return of de Souza Neto et al. (2008, Box 8.5, its multiplier a = 4G(1 + sinφ sinψ/3)
// + 4K sinφ sinψ), the apex, Tresca in pure shear, the tension cut-off, the ice strength of
// Eqs. 36–37 against the cryo-suction of the freezing curve (Clausius–Clapeyron, Eq. 25), and
// softening (Eq. 35). The contract (yield surface, tangent, objectivity) runs for every
// parameter set in test_mechanical_models.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "frostmpm/config/input_error.hpp"
#include "mechanical_model_testing.hpp"

namespace {

using frostmpm::test::integrate;
using frostmpm::test::make_model;
using frostmpm::test::Voigt;

constexpr double kDegree = std::numbers::pi / 180;
// State order of both models.
enum { kPlasticDeviatoric, kPlasticVolumetric, kYielded, kCohesion, kFriction, kDilation };

const std::string kSoil = "youngs_modulus: 1.0e7, poisson_ratio: 0.3";
constexpr double kE = 1.0e7, kNu = 0.3;
constexpr double kG = kE / (2 * (1 + kNu)), kK = kE / (3 * (1 - 2 * kNu)), kLambda = kK - 2 * kG / 3;

/// Q diag(d) Qᵀ in Voigt order, Q a rotation by 30° about z then 40° about x.
Voigt rotated(const std::array<double, 3>& d) {
  const double a = 30 * kDegree, b = 40 * kDegree;
  const double Rz[3][3] = {{std::cos(a), -std::sin(a), 0}, {std::sin(a), std::cos(a), 0}, {0, 0, 1}};
  const double Rx[3][3] = {{1, 0, 0}, {0, std::cos(b), -std::sin(b)}, {0, std::sin(b), std::cos(b)}};
  double Q[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) Q[i][j] += Rx[i][k] * Rz[k][j];
  double m[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) m[i][j] += Q[i][k] * d[std::size_t(k)] * Q[j][k];
  return {m[0][0], m[1][1], m[2][2], m[1][2], m[0][2], m[0][1]};
}

void check_voigt(const Voigt& got, const Voigt& expected, double tolerance) {
  for (int k = 0; k < 6; ++k) {
    INFO("component " << k << ": " << got[std::size_t(k)] << " vs " << expected[std::size_t(k)]);
    CHECK(std::abs(got[std::size_t(k)] - expected[std::size_t(k)]) <= tolerance);
  }
}

}  // namespace

TEST_CASE("mohr_coulomb: a return to the main plane matches de Souza Neto's closed form, in any frame",
          "[mechanical][mohr_coulomb]") {
  const double c = 1.0e4, phi = 30 * kDegree, psi = 10 * kDegree;
  const auto model = make_model("mohr_coulomb", kSoil + ", cohesion: 1.0e4, friction_angle: 30, dilation_angle: 10");
  // Shear from zero stress: trial principal (2G e, 0, −2G e), past the surface but short of the apex.
  const double e = 4e-3;
  const double trial[3] = {2 * kG * e, 0, -2 * kG * e};
  const double sf = std::sin(phi), sp = std::sin(psi);
  const double f = trial[0] * (1 + sf) - trial[2] * (1 - sf) - 2 * c * std::cos(phi);
  const double a = 4 * kG * (1 + sf * sp / 3) + 4 * kK * sf * sp;
  const double gamma = f / a;
  const double g[3] = {1 + sp, 0, -(1 - sp)};
  std::array<double, 3> expected{};
  for (int i = 0; i < 3; ++i) expected[std::size_t(i)] = trial[i] - gamma * (kLambda * 2 * sp + 2 * kG * g[i]);
  REQUIRE(expected[0] > expected[1]);  // the main plane is the answer: the order is kept
  REQUIRE(expected[1] > expected[2]);
  const auto u = integrate(*model, rotated({e, 0, -e}), {}, -1);
  REQUIRE(!u.failed);
  check_voigt(u.stress, rotated(expected), 1e-9 * c);
  // On the surface: (σ1 − σ3) + (σ1 + σ3) sin φ = 2c cos φ.
  CHECK((expected[0] - expected[2]) + (expected[0] + expected[2]) * sf == Approx(2 * c * std::cos(phi)));
  CHECK(u.state[kYielded] == 1);
  // Δε^p = Δγ g: deviatoric part √(2/3 |dev g|²) Δγ, volumetric 2 sin ψ Δγ.
  const double mean_g = (g[0] + g[1] + g[2]) / 3;
  double dev2 = 0;
  for (double gi : g) dev2 += (gi - mean_g) * (gi - mean_g);
  CHECK(u.state[kPlasticDeviatoric] == Approx(std::sqrt(2.0 / 3.0 * dev2) * gamma).epsilon(1e-9));
  CHECK(u.state[kPlasticVolumetric] == Approx(2 * sp * gamma).epsilon(1e-9));
}

TEST_CASE("mohr_coulomb: a trial past the apex returns to c cot(phi) in one step, without NaN",
          "[mechanical][mohr_coulomb]") {
  const auto model = make_model("mohr_coulomb", kSoil + ", cohesion: 1.0e4, friction_angle: 30");
  const double apex = 1.0e4 / std::tan(30 * kDegree);  // 17320.5 Pa
  for (const auto& strain : {Voigt{1e-2, 1e-2, 1e-2, 0, 0, 0}, Voigt{2e-2, 1e-2, 1.5e-2, 1e-3, 0, -2e-3}}) {
    const auto u = integrate(*model, strain, {}, -1);
    REQUIRE(!u.failed);
    check_voigt(u.stress, {apex, apex, apex, 0, 0, 0}, 1e-9 * apex);
    const double trial_mean = kK * (strain[0] + strain[1] + strain[2]);
    CHECK(u.state[kPlasticVolumetric] == Approx((trial_mean - apex) / kK).epsilon(1e-12));
  }
  // A hydrostatic trial exactly at the apex stays there: equal eigenvalues, no Lode angle.
  const auto at = integrate(*model, {}, {apex * 1.5, apex * 1.5, apex * 1.5, 0, 0, 0}, -1);
  for (double s : at.stress) CHECK(std::isfinite(s));
  check_voigt(at.stress, {apex, apex, apex, 0, 0, 0}, 1e-9 * apex);
}

TEST_CASE("mohr_coulomb: Tresca (phi = 0) in pure shear returns to tau = c", "[mechanical][mohr_coulomb]") {
  const auto model = make_model("mohr_coulomb", kSoil + ", cohesion: 1.0e4, friction_angle: 0");
  const auto u = integrate(*model, {0, 0, 0, 0, 0, 5e-3}, {}, -1);  // trial τ = 2G · 5e-3 = 38462 Pa
  REQUIRE(!u.failed);
  check_voigt(u.stress, {0, 0, 0, 0, 0, 1.0e4}, 1e-9 * 1.0e4);
  CHECK(u.state[kPlasticVolumetric] == Approx(0).margin(1e-15));  // ψ = 0: isochoric flow
}

TEST_CASE("mohr_coulomb: the tension cut-off holds the largest principal stress at its strength",
          "[mechanical][mohr_coulomb]") {
  const auto model = make_model("mohr_coulomb", kSoil + ", cohesion: 5.0e4, friction_angle: 30, tensile_strength: 1.0e4");
  // Uniaxial strain in tension: trial (λ + 2G, λ, λ) 1e-2; the cut-off plane alone: σ1 = T and
  // the lateral stresses drop by λ Δγ with Δγ = (σ1_tr − T)/(λ + 2G).
  const double T = 1.0e4, e = 1e-2;
  const double gamma = ((kLambda + 2 * kG) * e - T) / (kLambda + 2 * kG);
  const double lateral = kLambda * e - kLambda * gamma;
  const auto u = integrate(*model, {e, 0, 0, 0, 0, 0}, {}, -1);
  REQUIRE(!u.failed);
  check_voigt(u.stress, {T, lateral, lateral, 0, 0, 0}, 1e-9 * T);
  // A cut-off above the apex changes nothing: the cone's apex is the tensile strength.
  const auto high = make_model("mohr_coulomb", kSoil + ", cohesion: 1.0e4, friction_angle: 30, tensile_strength: 1.0e6");
  const auto plain = make_model("mohr_coulomb", kSoil + ", cohesion: 1.0e4, friction_angle: 30");
  check_voigt(integrate(*high, {e, 0, 0, 0, 0, 0}, {}, -1).stress, integrate(*plain, {e, 0, 0, 0, 0, 0}, {}, -1).stress,
              1e-9 * 1.0e4);
}

TEST_CASE("mohr_coulomb_ice: the ice strength at -0.1, -1 and -5 degC matches Eqs. 36-37 with the cryo-suction "
          "of the freezing curve, from the first step",
          "[mechanical][mohr_coulomb]") {
  // The thaw slump's soil (Sec. 5.3.1): c' = 2 kPa, φ' = 20°, Δc_max = 200 kPa, Δφ_max = 15°,
  // η_c = 0.05, λ = 0.4, p0 = 100 kPa.
  const auto model = make_model("mohr_coulomb_ice", kSoil +
                                                        ", cohesion: 2.0e3, friction_angle: 20, max_ice_cohesion: 2.0e5, "
                                                        "max_ice_friction_angle: 15, ice_bonding_rate: 0.05, lambda: 0.4");
  const double lambda = 0.4, p0 = 1.0e5, rho_c = 917, L_f = 3.34e5;
  double previous = 0;
  for (const double T : {-0.1, -1.0, -5.0}) {
    INFO("T = " << T << " degC");
    // Eq. 25 at p_l = 0: s/p0 = −(ρ_c L_f / p0) ln(T_K / 273.15), S_l = [1 + (s/p0)^(1/(1−λ))]^(−λ).
    const double suction = -(rho_c * L_f / p0) * std::log((T + 273.15) / 273.15);
    const double S_l = std::pow(1 + std::pow(suction, 1 / (1 - lambda)), -lambda);
    const double bonding = 1 - std::exp(-0.05 * suction);
    // A small elastic step: the strength is already the frozen one, before any plastic strain.
    const auto u = integrate(*model, {-1e-6, 0, 0, 0, 0, 0}, {-1e3, -1e3, -1e3, 0, 0, 0}, 1 - S_l);
    REQUIRE(!u.failed);
    CHECK(u.state[kPlasticDeviatoric] == 0);
    CHECK(u.state[kCohesion] == Approx(2.0e3 + 2.0e5 * bonding).epsilon(1e-9));
    CHECK(u.state[kFriction] == Approx(20 + 15 * bonding).epsilon(1e-9));
    CHECK(u.state[kCohesion] > previous);  // colder is stronger
    previous = u.state[kCohesion];
  }
  // By hand at −1 °C: s/p0 = 3062.78 · 0.0036677 = 11.2334, 1 − e^(−0.56167) = 0.42973.
  const double S_l = std::pow(1 + std::pow(11.2334, 1 / 0.6), -0.4);
  CHECK(integrate(*model, {}, {}, 1 - S_l).state[kCohesion] == Approx(2.0e3 + 2.0e5 * 0.42973).epsilon(1e-4));
  // Thawed, or no thermal physics: the unfrozen strength.
  CHECK(integrate(*model, {}, {}, 0.0).state[kCohesion] == 2.0e3);
  CHECK(integrate(*model, {}, {}, -1).state[kCohesion] == 2.0e3);
  // All ice: the whole Δc_max, finite.
  CHECK(integrate(*model, {}, {}, 1.0).state[kCohesion] == Approx(2.02e5));
}

TEST_CASE("mohr_coulomb_ice: a thawing point loses its ice strength and yields at zero strain",
          "[mechanical][mohr_coulomb]") {
  const auto model = make_model("mohr_coulomb_ice", kSoil +
                                                        ", cohesion: 2.0e3, friction_angle: 20, max_ice_cohesion: 2.0e5, "
                                                        "ice_bonding_rate: 0.05, lambda: 0.4");
  // A shear stress the frozen soil carries (S_c = 0.9) but the thawed soil cannot.
  const Voigt start = {-1.0e4, -1.0e4, -1.0e4, 0, 0, 3.0e4};
  const auto frozen = integrate(*model, {}, start, 0.9);
  CHECK(frozen.state[kYielded] == 0);
  check_voigt(frozen.stress, start, 0);
  const auto thawed = integrate(*model, {}, start, 0.0);
  CHECK(thawed.state[kYielded] == 1);
  CHECK(thawed.stress[5] < 3.0e4);
  std::vector<double> F(1);
  REQUIRE(model->yield_function(thawed.stress, thawed.state, F));
  CHECK(std::abs(F[0]) <= 1e-6);
}

TEST_CASE("mohr_coulomb: softening follows Eq. 35 and the stress stays on the softened surface",
          "[mechanical][mohr_coulomb]") {
  const auto model = make_model("mohr_coulomb", kSoil +
                                                    ", cohesion: 2.0e4, residual_cohesion: 5.0e3, friction_angle: 30, "
                                                    "residual_friction_angle: 20, softening_rate: 20");
  Voigt stress{};
  std::vector<double> state = model->initial_state();
  for (int step = 0; step < 40; ++step) {
    const auto u = integrate(*model, {2e-3, 0, -2e-3, 0, 0, 0}, stress, -1, state);
    REQUIRE(!u.failed);
    stress = u.stress;
    state = u.state;
  }
  const double eps = state[kPlasticDeviatoric];
  REQUIRE(eps > 0.05);  // well into softening
  const double decay = std::exp(-20 * eps);
  CHECK(state[kCohesion] == Approx(5.0e3 + 1.5e4 * decay).epsilon(1e-9));
  CHECK(state[kFriction] == Approx(20 + 10 * decay).epsilon(1e-9));
  std::vector<double> F(1);
  REQUIRE(model->yield_function(stress, state, F));
  CHECK(std::abs(F[0]) <= 1e-8 * 2.0e4);
  // A zero increment now changes nothing: the strength was taken at the step's end.
  const auto still = integrate(*model, {}, stress, -1, state);
  check_voigt(still.stress, stress, 1e-12 * 2.0e4);
}

TEST_CASE("mohr_coulomb: inconsistent strengths are refused with the key named", "[mechanical][mohr_coulomb]") {
  const auto refused = [](const std::string& params, const std::string& text) {
    INFO(params);
    try {
      (void)make_model("mohr_coulomb_ice", kSoil + ", cohesion: 1.0e4, friction_angle: 30, max_ice_cohesion: 1.0e5, "
                                                   "ice_bonding_rate: 0.05, " +
                                               params);
      FAIL("accepted");
    } catch (const frostmpm::InputError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(text) != std::string::npos);
    }
  };
  refused("lambda: 0.4, dilation_angle: 35", "dilation_angle = 35 is above friction_angle = 30");
  refused("lambda: 0.4, residual_cohesion: 2.0e4", "residual_cohesion = 20000 is above the peak cohesion");
  refused("lambda: 0.4, max_ice_friction_angle: 55", "must stay below 80");
  refused("lambda: 0.4, max_ice_dilation_angle: 5", "max_ice_dilation_angle = 5 is above max_ice_friction_angle = 0");
  refused("dilation_angle: 0", "needs λ for s_c (Eq. 37)");
}
