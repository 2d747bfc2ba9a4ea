#pragma once
// Per-step cache of every particle's shape-function weights and gradients on its support
// nodes, computed once and reused by every stage (P2G, gradients, assembly, G2P). Layout is
// flat: particle p owns entries [p*K, (p+1)*K) with K = width^Dim.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/shape/shape_function.hpp"

namespace frostmpm {

template <int Dim>
class StencilCache {
 public:
  void configure(ShapeKind kind) {
    kind_ = kind;
    width_ = support_width(kind);
    per_particle_ = 1;
    for (int d = 0; d < Dim; ++d) per_particle_ *= width_;
  }

  /// Recomputes the stencil of every particle. `positions` holds Dim values per particle and
  /// `half_sizes` the GIMP half-widths (Dim per particle, in metres). Returns the index of the
  /// first particle outside the grid, or -1.
  long update(const UniformGrid<Dim>& grid, std::span<const double> positions,
              std::span<const double> half_sizes);

  ShapeKind kind() const { return kind_; }
  int per_particle() const { return per_particle_; }
  std::size_t particles() const { return particles_; }
  /// Incremented on every update: stages that cache graphs compare it.
  std::uint64_t version() const { return version_; }
  /// True when the last update changed the set of (particle, node) pairs (or first update).
  bool topology_changed() const { return topology_changed_; }

  const std::uint32_t* nodes(std::size_t p) const { return node_.data() + p * per_particle_; }
  const double* weights(std::size_t p) const { return weight_.data() + p * per_particle_; }
  const double* gradients(std::size_t p) const { return gradient_.data() + p * per_particle_ * Dim; }

 private:
  ShapeKind kind_ = ShapeKind::Linear;
  int width_ = 2;
  int per_particle_ = 1 << Dim;
  std::size_t particles_ = 0;
  std::uint64_t version_ = 0;
  bool topology_changed_ = true;
  std::vector<std::uint32_t> node_;
  std::vector<double> weight_;
  std::vector<double> gradient_;
};

}  // namespace frostmpm
