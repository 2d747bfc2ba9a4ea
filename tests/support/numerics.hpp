#pragma once
// Numerical helpers shared by the model tests: finite differences and sampling.
#include <algorithm>
#include <cmath>
#include <vector>

namespace frostmpm::test {

/// Richardson-extrapolated central difference (4 D(h/2) − D(h))/3, error O(h⁴). With h a small
/// fraction of the curve's length scale this is far below a 1e-6 tolerance, while round-off
/// (≈ ε·|f|/h) stays ≈ 1e-12 for h = 1e-3.
template <class F>
double richardson(const F& f, double x, double h) {
  const auto central = [&](double step) { return (f(x + step) - f(x - step)) / (2.0 * step); };
  return (4.0 * central(0.5 * h) - central(h)) / 3.0;
}

/// |analytic − fd| ≤ 1e-6 · max(|analytic|, tiny_abs).
inline bool derivative_matches(double analytic, double fd, double tiny_abs) {
  return std::abs(analytic - fd) <= 1e-6 * std::max(std::abs(analytic), tiny_abs);
}

inline std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> out(n);
  for (int i = 0; i < n; ++i) out[i] = a + (b - a) * i / (n - 1);
  return out;
}

}  // namespace frostmpm::test
