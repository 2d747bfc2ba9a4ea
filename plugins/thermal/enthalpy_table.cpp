#include "enthalpy_table.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frostmpm::thermal {

namespace {

/// S_l at one temperature (set-up only: one virtual call per knot candidate is cheap there).
double saturation_at(const SfccModel& sfcc, double T) {
  double S = 0, dS = 0, dp = 0;
  sfcc.evaluate(std::span<const double>(&T, 1), {}, SfccResult{std::span(&S, 1), std::span(&dS, 1), std::span(&dp, 1)});
  return S;
}

}  // namespace

EnthalpyTable::EnthalpyTable(const SfccModel& sfcc, const PhaseConstants& pc, const Options& o) : pc_(pc) {
  freezing_point_ = sfcc.freezing_point();
  const double lo = std::min(o.lo, freezing_point_ - 1), hi = std::max(o.hi, freezing_point_ + 1);
  // Start from a coarse lattice (with T_f on it), then bisect every interval on which the
  // chord misses the curve at its quarter points by more than the tolerance.
  std::vector<double> seeds;
  for (int k = 0; k <= 64; ++k) seeds.push_back(lo + (freezing_point_ - lo) * k / 64.0);
  for (int k = 1; k <= 8; ++k) seeds.push_back(freezing_point_ + (hi - freezing_point_) * k / 8.0);
  std::vector<double> knots{seeds.front()}, values{saturation_at(sfcc, seeds.front())};
  struct Pending {
    double a, b, Sa, Sb;
  };
  for (std::size_t s = 1; s < seeds.size(); ++s) {
    std::vector<Pending> stack{{seeds[s - 1], seeds[s], values.back(), saturation_at(sfcc, seeds[s])}};
    while (!stack.empty()) {
      Pending iv = stack.back();
      stack.pop_back();
      const double m = 0.5 * (iv.a + iv.b), Sm = saturation_at(sfcc, m);
      bool refine = iv.b - iv.a > 2 * o.min_spacing;
      if (refine) {
        double worst = std::abs(Sm - 0.5 * (iv.Sa + iv.Sb));
        for (double f : {0.25, 0.75}) {
          const double t = iv.a + f * (iv.b - iv.a);
          worst = std::max(worst, std::abs(saturation_at(sfcc, t) - (iv.Sa + f * (iv.Sb - iv.Sa))));
        }
        refine = worst > o.tolerance;
      }
      if (refine) {
        stack.push_back({m, iv.b, Sm, iv.Sb});  // right half after the left one
        stack.push_back({iv.a, m, iv.Sa, Sm});
      } else {
        knots.push_back(iv.b);
        values.push_back(iv.Sb);
      }
    }
    if (knots.size() > 2'000'000)
      throw std::runtime_error("thermal: the SFCC needs more than 2 million table knots; is it continuous?");
  }
  for (double S : values)
    if (!std::isfinite(S) || S < -1e-12 || S > 1 + 1e-12)
      throw std::runtime_error("thermal: the SFCC returned S_l = " + std::to_string(S) + " outside [0, 1]");

  const double Cl = pc.water_capacity, Cc = pc.ice_capacity, Lv = pc.latent_density;
  auto add = [&](double lower, double base, double S, double slope, double G) {
    lower_.push_back(lower);
    base_.push_back(base);
    S_.push_back(S);
    slope_.push_back(slope);
    G_.push_back(G);
    g1_.push_back(Cc + (Cl - Cc) * S + Lv * slope);
    g2_.push_back(0.5 * (Cl - Cc) * slope);
  };
  // Below the table S_l stays at its first value; G is referenced so that this tail is
  // G = (C_c + (C_l − C_c) S_0) T + L_v S_0.
  double G = (Cc + (Cl - Cc) * values[0]) * knots[0] + Lv * values[0];
  add(-std::numeric_limits<double>::infinity(), knots[0], values[0], 0.0, G);
  for (std::size_t k = 1; k < knots.size(); ++k) {
    const double dx = knots[k] - knots[k - 1];
    add(knots[k - 1], knots[k - 1], values[k - 1], (values[k] - values[k - 1]) / dx, G);
    G = pore_heat(knots[k], intervals() - 1);
  }
  add(knots.back(), knots.back(), values.back(), 0.0, G);
  freezing_interval_ = locate(freezing_point_, intervals() / 2);
}

double EnthalpyTable::invert(double a, double b, double H, int& hint) const {
  int i = hint;
  auto start = [&](int k) { return a * base_[k] + b * G_[k]; };  // H at the interval's lower end
  while (i > 0 && H < start(i)) --i;
  while (i + 1 < intervals() && H >= start(i + 1)) ++i;
  hint = i;
  // a T + b G = H on interval i: C x² + B x − r = 0 with r = H − H(base) ≥ 0 (except on the
  // open-ended first interval, where C = 0); the form below has no cancellation.
  const double r = H - start(i), B = a + b * g1_[i], C = b * g2_[i];
  const double disc = std::max(0.0, B * B + 4 * C * r);
  return base_[i] + 2 * r / (B + std::sqrt(disc));
}

}  // namespace frostmpm::thermal
