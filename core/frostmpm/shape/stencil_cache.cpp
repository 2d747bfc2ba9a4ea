#include "frostmpm/shape/stencil_cache.hpp"

#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/shape/shape_kernels.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <utility>

namespace frostmpm {

namespace {

using shape_kernels::tolerance;  // the round-off of a position in cell units, as shape_1d allows it

/// The stencils of particles [0, n), for a kind (and so a support width) known at compile time:
/// the 1-D weights inline and every loop over the width^Dim nodes of fixed length. Writes the
/// nodes, weights and gradients of every particle; returns the first particle outside the grid,
/// or -1, and sets `changed` when a particle's nodes differ from those `node` held.
template <int Dim, ShapeKind Kind>
long update_stencils(const UniformGrid<Dim>& grid, std::span<const double> positions,
                     std::span<const double> half_sizes, std::size_t n, std::uint32_t* node_out, double* weight_out,
                     double* gradient_out, bool& changed) {
  constexpr int width = support_width(Kind);
  constexpr std::size_t K = [] {
    std::size_t k = 1;
    for (int d = 0; d < Dim; ++d) k *= width;
    return k;
  }();
  long outside = -1;
  bool topology = false;

#pragma omp parallel for schedule(static) reduction(|| : topology) if (n >= kParallelMinimum)
  for (std::size_t p = 0; p < n; ++p) {
    std::array<std::array<double, 4>, Dim> w{}, g{};
    std::array<int, Dim> base{};
    bool inside = true;
    for (int d = 0; d < Dim; ++d) {
      const double h = grid.spacing[d];
      double xi = (positions[p * Dim + d] - grid.origin[d]) / h;
      double half = half_sizes[p * Dim + d] / h;
      std::optional<std::pair<double, double>> clipped;  // the domain's ends inside the grid
      // GIMP integrates over the particle domain inside the grid, Ω_p ∩ Ω (paper Eq. 58): a domain
      // that reaches past the grid's edge (a particle pressed against a fixed boundary) is clipped
      // to it, which keeps the partition of unity. A domain wholly outside has left the grid.
      // A periodic axis has no edge: the support wraps (below) and is never clipped.
      if (Kind == ShapeKind::Gimp && !grid.periodic[d]) {
        // Beyond round-off (shape_1d's own tolerance): a domain that ends on the edge, as every
        // lattice particle's does, keeps its weights.
        const double edge_lo = -grid.ghost_layers, edge_hi = grid.cells[d] + grid.ghost_layers;
        const double tol = tolerance(xi);
        if (xi - half < edge_lo - tol || xi + half > edge_hi + tol) {
          const double lo = std::max(xi - half, edge_lo), hi = std::min(xi + half, edge_hi);
          if (!(hi > lo)) {
            inside = false;
            break;
          }
          xi = 0.5 * (lo + hi);
          half = 0.5 * (hi - lo);
          clipped = {lo, hi};
        }
      }
      base[d] = shape_kernels::shape_1d<Kind>(xi, h, half, w[d].data(), g[d].data());
      // A clipped domain's gradients from its ends (exact cancellation however narrow it is).
      if (clipped) shape_kernels::gimp_gradients_of_ends(clipped->first, clipped->second, base[d], 1.0 / h, g[d].data());
      // A support node past the grid is harmless when its weight is zero (GIMP particles at
      // the domain edge); it is then pointed at a valid node. A domain that ends past the edge
      // by less than the round-off above was not clipped and may hold a ~1e-26 weight there
      // (a moving particle pressed against a fixed face): that is round-off, dropped.
      for (int k = 0; k < width && !grid.periodic[d]; ++k) {
        const int node = base[d] + k;
        if (node >= -grid.ghost_layers && node <= grid.cells[d] + grid.ghost_layers) continue;
        if (Kind == ShapeKind::Gimp && std::abs(node - xi) >= 1.0 + half - 2.0 * tolerance(xi)) {
          w[d][k] = g[d][k] = 0.0;
          continue;
        }
        if (w[d][k] != 0.0 || g[d][k] != 0.0) inside = false;
      }
    }
    if (!inside) {
#pragma omp critical
      outside = outside < 0 ? static_cast<long>(p) : std::min(outside, static_cast<long>(p));
      std::fill_n(weight_out + p * K, K, 0.0);
      std::fill_n(gradient_out + p * K * Dim, K * Dim, 0.0);
      std::fill_n(node_out + p * K, K, 0u);
      continue;
    }
    // Tensor product over the width^Dim support nodes (axis 0 fastest). A support wholly on the
    // grid (all but the edge particles) needs no clamping: its nodes are the first one plus
    // fixed strides.
    std::uint32_t* node_p = node_out + p * K;
    double* weight_p = weight_out + p * K;
    double* gradient_p = gradient_out + p * K * Dim;
    bool on_grid = true;
    for (int d = 0; d < Dim; ++d)
      on_grid = on_grid && (grid.periodic[d] ? base[d] >= 0 && base[d] + width <= grid.cells[d]
                                             : base[d] >= -grid.ghost_layers &&
                                                   base[d] + width - 1 <= grid.cells[d] + grid.ghost_layers);
    const std::size_t first = on_grid ? grid.node_index(base) : 0;
    std::array<std::size_t, Dim> stride{};
    for (int d = 0, s = 1; d < Dim; s *= grid.nodes_along(d), ++d) stride[d] = static_cast<std::size_t>(s);
#pragma GCC unroll 64
    for (std::size_t k = 0; k < K; ++k) {
      std::size_t rest = k;
      std::array<int, Dim> offset{}, ijk{};
      std::size_t index = first;
      for (int d = 0; d < Dim; ++d) {
        offset[d] = static_cast<int>(rest % width);
        rest /= width;
        if (on_grid)
          index += static_cast<std::size_t>(offset[d]) * stride[d];
        else if (grid.periodic[d])
          ijk[d] = grid.wrap(d, base[d] + offset[d]);
        else
          ijk[d] = std::clamp(base[d] + offset[d], -grid.ghost_layers, grid.cells[d] + grid.ghost_layers);
      }
      const std::uint32_t node = static_cast<std::uint32_t>(on_grid ? index : grid.node_index(ijk));
      if (node_p[k] != node) topology = true;
      node_p[k] = node;
      double weight = 1.0;
      for (int d = 0; d < Dim; ++d) weight *= w[d][offset[d]];
      weight_p[k] = weight;
      for (int d = 0; d < Dim; ++d) {
        double grad = g[d][offset[d]];
        for (int e = 0; e < Dim; ++e)
          if (e != d) grad *= w[e][offset[e]];
        gradient_p[k * Dim + d] = grad;
      }
    }
  }
  if (topology) changed = true;
  return outside;
}

}  // namespace

template <int Dim>
long StencilCache<Dim>::update(const UniformGrid<Dim>& grid, std::span<const double> positions,
                               std::span<const double> half_sizes) {
  const std::size_t n = positions.size() / Dim;
  const std::size_t K = static_cast<std::size_t>(per_particle_);
  topology_changed_ = n != particles_;
  particles_ = n;
  node_.resize(n * K);
  weight_.resize(n * K);
  gradient_.resize(n * K * Dim);
  bool changed = false;
  long outside = -1;
  switch (kind_) {
    case ShapeKind::Linear:
      outside = update_stencils<Dim, ShapeKind::Linear>(grid, positions, half_sizes, n, node_.data(), weight_.data(),
                                                        gradient_.data(), changed);
      break;
    case ShapeKind::Gimp:
      outside = update_stencils<Dim, ShapeKind::Gimp>(grid, positions, half_sizes, n, node_.data(), weight_.data(),
                                                      gradient_.data(), changed);
      break;
    case ShapeKind::CubicBSpline:
      outside = update_stencils<Dim, ShapeKind::CubicBSpline>(grid, positions, half_sizes, n, node_.data(),
                                                              weight_.data(), gradient_.data(), changed);
      break;
  }
  if (changed) topology_changed_ = true;
  ++version_;
  return outside;
}

template class StencilCache<2>;
template class StencilCache<3>;

}  // namespace frostmpm
