#pragma once
// The sparsity graph of a nodal operator assembled from particles (Σ_p V_p f_p ∇S_ip·∇S_jp
// and the like): node i couples to node j when some particle's stencil holds both. Built
// once per stencil topology and kept while particles stand still, so an implicit physics
// reassembles values into a fixed CSR pattern (and SparseSystem keeps its graph and
// preconditioner structure).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/shape/stencil_cache.hpp"

namespace frostmpm {

struct StencilGraph {
  std::vector<std::size_t> offsets;  ///< CSR row offsets (nodes + 1)
  std::vector<int> columns;          ///< sorted column indices of each row
  std::vector<int> scatter;          ///< CSR position of (particle p, stencil slot a, slot b)
  std::vector<std::size_t> diagonal; ///< CSR position of (i, i); every node has one
  std::vector<std::size_t> transpose; ///< CSR position of (j, i) for the entry (i, j) (the pattern is symmetric)
  /// The transfer topology it was built for (Transfer::topology_version(); the caller sets it).
  std::uint64_t topology_version = ~std::uint64_t{0};

  /// Builds the graph of `nodes` nodes from the stencil's particles. `squared`: the pattern of
  /// a product of two such operators (node i couples to k when some node j couples to both,
  /// e.g. Q M⁻¹ Qᵀ of a divergence Q and a lumped mass M), which holds the plain one.
  /// `cliques`: sets of nodes that all couple with one another besides (bodies whose nodes move
  /// as one, e.g. a rigid plate).
  template <int Dim>
  void build(const StencilCache<Dim>& stencil, std::size_t nodes, bool squared = false,
             const std::vector<std::vector<std::size_t>>& cliques = {});
  /// The pattern of every node with all nodes within `radius` lattice steps along each axis,
  /// plus `cliques`: independent of where particles are, so a physics whose particles move keeps
  /// one matrix (and its preconditioner's structure) for the whole run and only refreshes the
  /// particle-to-entry map (build_scatter) when the stencil topology changes.
  template <int Dim>
  void build_lattice(const UniformGrid<Dim>& grid, int radius, const std::vector<std::vector<std::size_t>>& cliques = {});
  /// scatter for the stencil's particles in this pattern (which must hold every pair).
  template <int Dim>
  void build_scatter(const StencilCache<Dim>& stencil);
  std::size_t rows() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t nonzeros() const { return columns.size(); }
  /// Fills `transpose` (after the pattern is built).
  void fill_transpose();
  /// CSR position of (row, col), which must be in the pattern.
  std::size_t position(std::size_t row, int col) const;
};

}  // namespace frostmpm
