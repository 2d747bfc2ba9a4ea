// The objective stress rate and the two-phase corrector, against their closed forms.
#include <catch2/catch.hpp>

#include <cmath>

#include "frostmpm/models/tensor3.hpp"
#include "frostmpm/models/two_phase.hpp"

using namespace frostmpm;

TEST_CASE("Jaumann rate: diag(1, 0) turned rigidly by 45° counter-clockwise by forward Euler", "[unit][mechanics]") {
  // v = ω × x, ω = 1: (∇v)_ij = ∂v_i/∂x_j = [[0, −1], [1, 0]], W = ½(∇v − ∇vᵀ) = ∇v. The exact
  // rotation gives [[½, ½], [½, ½]]; forward Euler with σ ← σ + Δt(Wσ − σW) gives σ_xy =
  // 0.50621 / 0.50062 / 0.50006 in 100 / 1000 / 10 000 steps (the deviator grows by
  // √(1 + (2Δt)²) a step; the trace is kept exactly). The opposite sign turns it clockwise.
  tensor3::Mat W{};
  W[0][1] = -1.0;
  W[1][0] = 1.0;
  const double angle = std::acos(-1.0) / 4;
  const double expected[] = {0.50621, 0.50062, 0.50006};
  int k = 0;
  for (int steps : {100, 1000, 10000}) {
    double s[6] = {1, 0, 0, 0, 0, 0};
    for (int i = 0; i < steps; ++i) tensor3::jaumann_rotate(W, angle / steps, s);
    CHECK(s[5] == Approx(expected[k++]).margin(5e-6));
    CHECK(s[0] + s[1] == Approx(1.0).epsilon(1e-12));  // trace kept
    CHECK(s[0] == Approx(0.5).margin(0.01));
    CHECK(s[1] == Approx(0.5).margin(0.01));
    CHECK(s[2] == 0.0);
    CHECK(s[3] == 0.0);
    CHECK(s[4] == 0.0);
  }
}

TEST_CASE("two-phase corrector: the corrected ξ_s, ξ_l and their drained and undrained limits", "[unit][hydraulic]") {
  const double m_s = 0.6 * 2650, n_l = 0.4, m_l = n_l * 1000, rho_m = m_s + m_l;
  const double dt = 1e-3;
  SECTION("no drag: each phase on its own (ξ_s = ξ_l = 1)") {
    const auto f = two_phase::corrector_factors(m_s, m_l, n_l, 0.0, dt);
    CHECK(f.xi_s == Approx(1.0).epsilon(1e-15));
    CHECK(f.xi_l == Approx(1.0).epsilon(1e-15));
    const auto m = two_phase::corrector_mobility(m_s, m_l, n_l, 0.0, dt);
    CHECK(m.solid == Approx((1 - n_l) / m_s).epsilon(1e-14));  // a_s = −n_sc ∇Δp / m_s
    CHECK(m.liquid == Approx(1.0 / 1000).epsilon(1e-14));      // a_l = −∇Δp / ρ_l
  }
  SECTION("Δt C_d → ∞ (undrained): equal accelerations −∇Δp/ρ_m") {
    const auto m = two_phase::corrector_mobility(m_s, m_l, n_l, 1e30, dt);
    CHECK(m.solid == Approx(1.0 / rho_m).epsilon(1e-12));
    CHECK(m.liquid == Approx(1.0 / rho_m).epsilon(1e-12));
    const auto r = two_phase::liquid_response(m_l, 1e30, dt);
    CHECK(r.xi == Approx(0.0).margin(1e-20));
    CHECK(r.drag_stiffness == Approx(m_l / dt).epsilon(1e-12));  // the water moves with the skeleton
  }
  SECTION("the closed forms solve the phase-wise corrector") {
    for (double drag : {1e2, 1e6, 1e10}) {
      // m_s a_s = −n_sc g + D (a_l − a_s), m_l a_l = −n_l g − D (a_l − a_s) with g = ∇Δp = 1.
      const auto m = two_phase::corrector_mobility(m_s, m_l, n_l, drag, dt);
      const double a_s = -m.solid, a_l = -m.liquid, D = dt * drag;
      CHECK(m_s * a_s == Approx(-(1 - n_l) + D * (a_l - a_s)).epsilon(1e-10));
      CHECK(m_l * a_l == Approx(-n_l - D * (a_l - a_s)).epsilon(1e-10));
      const auto f = two_phase::corrector_factors(m_s, m_l, n_l, drag, dt);
      CHECK(f.xi_s * (1 - n_l) / m_s == Approx(m.solid).epsilon(1e-12));
      CHECK(f.xi_l * n_l / m_l == Approx(m.liquid).epsilon(1e-12));
      // The skeleton's share through the drag: λ_s = (1 − n_l ξ)/(m_s + Δt k).
      const auto r = two_phase::liquid_response(m_l, drag, dt);
      CHECK((1 - n_l * r.xi) / (m_s + dt * r.drag_stiffness) == Approx(m.solid).epsilon(1e-12));
    }
  }
  SECTION("a dry point (no liquid, so no drag): ξ = 0 and k = 0, the corrector's liquid mobility 0") {
    const auto r = two_phase::liquid_response(0.0, 0.0, dt);
    CHECK(r.xi == 0.0);
    CHECK(r.drag_stiffness == 0.0);
    CHECK(two_phase::corrector_mobility(INFINITY, 0.0, 0.0, 0.0, dt).liquid == 0.0);
    const auto wet = two_phase::liquid_response(m_l, 0.0, dt);  // no drag: the liquid keeps its own
    CHECK(wet.xi == 1.0);
    CHECK(wet.drag_stiffness == 0.0);
  }
  SECTION("a rigid skeleton (m_s → ∞): the liquid alone, ξ = m_l/(m_l + Δt C_d)") {
    const double drag = 5e5;
    const auto m = two_phase::corrector_mobility(INFINITY, m_l, n_l, drag, dt);
    CHECK(m.solid == 0.0);
    CHECK(m.liquid == Approx(n_l / (m_l + dt * drag)).epsilon(1e-14));
  }
}
