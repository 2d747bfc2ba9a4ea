#pragma once
// The one particle–grid transfer service every physics shares: the stencil cache (support
// nodes, weights and gradients of every particle), the coloured blocks of the race-free P2G
// scatter, the material index of every particle, and the G2P helpers. The kernel owns it and
// updates it when particles move; physics only read it, so no physics keeps its own copy of
// stencils, blocks or material indices.
//
// Versions: version() changes whenever the stencil was recomputed (particles moved: nodal
// state derived from particles is stale); topology_version() changes only when the set of
// (particle, node) pairs changed, which is what matrix graphs and the coloured blocks depend
// on — a slowly deforming body keeps its graphs and preconditioner structure for many steps.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/particles/particle_removal.hpp"
#include "frostmpm/shape/stencil_cache.hpp"
#include "frostmpm/transfer/coloured_blocks.hpp"
#include "frostmpm/transfer/nodal_interpolation.hpp"

namespace frostmpm {

template <int Dim>
class Transfer {
 public:
  void configure(ShapeKind kind) { stencil_.configure(kind); }
  /// Material index of every particle (set once, when the particles are made).
  void set_materials(std::vector<std::uint16_t> materials) { material_ = std::move(materials); }
  /// Drops the materials of the leaving particles, in place: the storage stays where it is, so
  /// a physics' view of it stays valid (over the first remaining entries).
  void remove_particles(const ParticleRemoval& removal) { removal.compact(material_, 1); }

  /// Recomputes every stencil; rebuilds the coloured blocks when the topology changed.
  /// Returns the first particle whose support leaves the grid, or -1 (nothing rebuilt then).
  long update(const UniformGrid<Dim>& grid, std::span<const double> positions, std::span<const double> half_sizes) {
    const long outside = stencil_.update(grid, positions, half_sizes);
    if (outside >= 0) return outside;
    if (stencil_.topology_changed() || blocks_.particles() != stencil_.particles()) {
      blocks_.build(grid, stencil_, support_width(stencil_.kind()));
      ++topology_version_;
    }
    return -1;
  }

  const StencilCache<Dim>& stencil() const { return stencil_; }
  const ColouredBlocks<Dim>& blocks() const { return blocks_; }
  std::span<const std::uint16_t> materials() const { return material_; }
  std::uint16_t material(std::size_t p) const { return material_[p]; }
  std::size_t particles() const { return stencil_.particles(); }
  int per_particle() const { return stencil_.per_particle(); }
  std::uint64_t version() const { return stencil_.version(); }
  std::uint64_t topology_version() const { return topology_version_; }

  /// P2G: f(p) for every particle, coloured so that f may add into any node of p's stencil
  /// without a race, in an order independent of the thread count.
  template <class F>
  void scatter(F&& f) const {
    blocks_.for_each(std::forward<F>(f));
  }
  /// G2P and other per-particle loops that write only particle p.
  template <class F>
  void for_each_particle(F&& f) const {
    parallel_for(particles(), std::forward<F>(f));
  }

  /// Σ_i S_ip f_i.
  template <class Nodal>
  double value_at(std::size_t p, const Nodal& f) const {
    return nodal_value_at(stencil_, p, f);
  }
  /// Σ_i ∇S_ip f_i.
  template <class Nodal>
  std::array<double, Dim> gradient_at(std::size_t p, const Nodal& f) const {
    return nodal_gradient_at(stencil_, p, f);
  }
  /// Σ_i S_ip v_i of a nodal vector field stored Dim values per node.
  template <class Nodal>
  std::array<double, Dim> vector_at(std::size_t p, const Nodal& v) const {
    const auto* nodes = stencil_.nodes(p);
    const auto* w = stencil_.weights(p);
    std::array<double, Dim> out{};
    for (int k = 0; k < stencil_.per_particle(); ++k)
      for (int d = 0; d < Dim; ++d) out[d] += w[k] * v[nodes[k] * Dim + d];
    return out;
  }
  /// (∇v)_ab = Σ_i v_ia ∂S_ip/∂x_b of a nodal vector field stored Dim values per node.
  template <class Nodal>
  std::array<std::array<double, Dim>, Dim> vector_gradient_at(std::size_t p, const Nodal& v) const {
    return vector_gradient_at(p, v, stencil_.per_particle());
  }
  /// The same with the support size given, as std::integral_constant in hot loops (unrolled).
  template <class Nodal, class Support>
  std::array<std::array<double, Dim>, Dim> vector_gradient_at(std::size_t p, const Nodal& v, Support support) const {
    const auto* nodes = stencil_.nodes(p);
    const auto* g = stencil_.gradients(p);
    std::array<std::array<double, Dim>, Dim> out{};
    for (int k = 0; k < support; ++k)
      for (int a = 0; a < Dim; ++a) {
        const double va = v[nodes[k] * Dim + a];
        for (int b = 0; b < Dim; ++b) out[a][b] += va * g[k * Dim + b];
      }
    return out;
  }
  /// (∂v_a/∂x_a)_a: the diagonal of vector_gradient_at (the same sums), whose total is ∇·v.
  template <class Nodal>
  std::array<double, Dim> gradient_diagonal_at(std::size_t p, const Nodal& v) const {
    const auto* nodes = stencil_.nodes(p);
    const auto* g = stencil_.gradients(p);
    std::array<double, Dim> out{};
    for (int k = 0; k < stencil_.per_particle(); ++k)
      for (int a = 0; a < Dim; ++a) out[a] += v[nodes[k] * Dim + a] * g[k * Dim + a];
    return out;
  }

 private:
  StencilCache<Dim> stencil_;
  ColouredBlocks<Dim> blocks_;
  std::vector<std::uint16_t> material_;
  std::uint64_t topology_version_ = 0;
};

}  // namespace frostmpm
