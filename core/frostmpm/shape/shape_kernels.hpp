#pragma once
// The 1-D shape functions themselves, inline: shape_1d() (shape_function.hpp) calls them, and
// StencilCache::update inlines them with the kind known at compile time (one branch-free call
// per axis instead of an out-of-line call and a switch per particle). Same code, same bits.
#include <algorithm>
#include <cmath>
#include <limits>

#include "frostmpm/shape/shape_function.hpp"

namespace frostmpm::shape_kernels {

// uGIMP (Bardenhagen & Kober 2004; paper Eq. 58 with a linear grid basis and a hat-shaped
// particle characteristic function): r = distance to node in cell units, lp = half-width.
// A node within round-off `tol` of the support's edge gets exactly zero: otherwise a particle
// whose support ends on the grid's last node would hold a ~1e-27 weight on a node past the grid.
inline void gimp(double r, double lp, double tol, double& s, double& ds) {
  const double a = std::abs(r);
  const double sign = r < 0 ? -1.0 : 1.0;
  if (a >= 1.0 + lp - tol) {
    s = ds = 0.0;
  } else if (a > 1.0 - lp) {
    const double t = 1.0 + lp - a;
    s = t * t / (4.0 * lp);
    ds = -sign * t / (2.0 * lp);
  } else if (a > lp) {
    s = 1.0 - a;
    ds = -sign;
  } else {
    s = 1.0 - (r * r + lp * lp) / (2.0 * lp);
    ds = -r / lp;
  }
}

/// uGIMP gradients of a domain [lo, hi] (cell units) from the hat at its two ends,
/// dS_k/dx = (N(hi − k) − N(lo − k)) / ((hi − lo) h), for the nodes base, base + 1, base + 2.
/// Analytically gimp()'s ds; used for a domain clipped at the grid's edge, whose width can shrink
/// to ~1e-11 cells as it leaves: there gimp()'s −r/lp, with r = xi − node rounded to eps·|xi|, put a
/// 1e-4 error in Σ_k dS_k (a rigidly moving particle strained as it left), while here the edge's
/// two nodes take the same rounded hat value with opposite signs and Σ_k dS_k stays at round-off.
inline void gimp_gradients_of_ends(double lo, double hi, int base, double inv_h, double* gradient) {
  const auto hat = [](double r) { return std::max(0.0, 1.0 - std::abs(r)); };
  const double scale = inv_h / (hi - lo);
  for (int k = 0; k < 3; ++k) gradient[k] = (hat(hi - (base + k)) - hat(lo - (base + k))) * scale;
}

inline void bspline(double r, double tol, double& s, double& ds) {
  const double a = std::abs(r);
  const double sign = r < 0 ? -1.0 : 1.0;
  if (a >= 2.0 - tol) {
    s = ds = 0.0;
  } else if (a >= 1.0) {
    const double t = 2.0 - a;
    s = t * t * t / 6.0;
    ds = -sign * 0.5 * t * t;
  } else {
    s = 2.0 / 3.0 - a * a + 0.5 * a * a * a;
    ds = sign * (-2.0 * a + 1.5 * a * a);
  }
}

/// The round-off of xi (a position minus the origin, over h) and of xi − node.
inline double tolerance(double xi) { return 16.0 * std::numeric_limits<double>::epsilon() * (std::abs(xi) + 2.0); }

/// shape_1d() for a kind known at compile time.
template <ShapeKind Kind>
inline int shape_1d(double xi, double h, double half_size, double* weight, double* gradient) {
  const double inv_h = 1.0 / h;
  const double tol = tolerance(xi);
  if constexpr (Kind == ShapeKind::Linear) {
    const int base = static_cast<int>(std::floor(xi));
    const double f = xi - base;
    weight[0] = 1.0 - f;
    weight[1] = f;
    gradient[0] = -inv_h;
    gradient[1] = inv_h;
    (void)tol;
    (void)half_size;
    return base;
  } else if constexpr (Kind == ShapeKind::Gimp) {
    // Support of width 3 centred on the nearest node.
    const int base = static_cast<int>(std::floor(xi + 0.5)) - 1;
    for (int k = 0; k < 3; ++k) {
      double s, ds;
      gimp(xi - (base + k), half_size, tol, s, ds);
      weight[k] = s;
      gradient[k] = ds * inv_h;
    }
    return base;
  } else {
    const int base = static_cast<int>(std::floor(xi)) - 1;
    for (int k = 0; k < 4; ++k) {
      double s, ds;
      bspline(xi - (base + k), tol, s, ds);
      weight[k] = s;
      gradient[k] = ds * inv_h;
    }
    (void)half_size;
    return base;
  }
}

}  // namespace frostmpm::shape_kernels
