#pragma once
// Race-free, thread-count-independent particle-to-grid scatter.
//
// Particles are grouped into blocks by the lowest node of their stencil (blocks of `width`
// node columns per axis, `width` = the shape function's support, and longer along the first
// axis, for runs of consecutive particles: coloured_blocks.cpp), and the blocks are
// coloured like a 2^Dim checkerboard. Two blocks of one colour are at least `width` node
// columns apart, so their particles never touch a common node: the blocks of a colour can
// scatter in parallel without atomics. Colours run one after another, and inside a block the
// particles run in index order. Every node therefore receives its contributions in the same
// order whatever the thread count, and P2G sums are bitwise reproducible on 1, 2 or 64
// threads — the property the issue tracker asks of every result.
//
// On a periodic axis a stencil that wraps across the seam touches both ends of the lattice; such
// particles (a column of them per periodic axis) form one more group, scattered serially after
// the colours.
//
// Gather loops (G2P) need none of this: a plain `omp parallel for` over particles is exact.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/shape/stencil_cache.hpp"

namespace frostmpm {

template <int Dim>
class ColouredBlocks {
 public:
  static constexpr int kColours = 1 << Dim;
  /// The colours, then the serial group of stencils that wrap across a periodic seam.
  static constexpr int kGroups = kColours + 1;

  /// Groups the stencil's particles into coloured blocks. Call again whenever the stencil
  /// topology changes (StencilCache::topology_changed()); when no particle changed block, the
  /// grouping (the same one) is kept without being redone.
  void build(const UniformGrid<Dim>& grid, const StencilCache<Dim>& stencil, int width);

  /// Runs f(p) for every particle: colour by colour, the blocks of a colour in parallel, the
  /// particles of a block in index order. f may scatter into any node of p's stencil.
  template <class F>
  void for_each(F&& f) const {
    const bool parallel = order_.size() >= kParallelMinimum;  // see parallel.hpp
    for (int c = 0; c < kGroups; ++c) {
      const std::uint32_t first = colour_begin_[c], last = colour_begin_[c + 1];
#pragma omp parallel for schedule(dynamic, 1) if (parallel && c < kColours)
      for (std::uint32_t b = first; b < last; ++b)
        for (std::uint32_t k = block_begin_[b]; k < block_begin_[b + 1]; ++k) f(std::size_t{order_[k]});
    }
  }

  std::size_t particles() const { return order_.size(); }
  /// Blocks of colour (or group) c are [first_block(c), first_block(c + 1)).
  std::uint32_t first_block(int c) const { return colour_begin_[c]; }
  /// Particles of block b, in the order for_each visits them.
  std::span<const std::uint32_t> block(std::uint32_t b) const {
    return {order_.data() + block_begin_[b], block_begin_[b + 1] - block_begin_[b]};
  }
  std::size_t blocks() const { return block_begin_.empty() ? 0 : block_begin_.size() - 1; }
  /// The stencil version the blocks were built for.
  std::uint64_t stencil_version() const { return version_; }

 private:
  std::vector<std::uint32_t> order_;        ///< particle indices, block by block
  std::vector<std::uint32_t> block_begin_;  ///< blocks sorted by colour; block b = order_[begin[b], begin[b+1])
  std::array<std::uint32_t, kGroups + 1> colour_begin_{};  ///< blocks of colour c: [begin[c], begin[c+1])
  std::uint64_t version_ = 0;
  // What the last build grouped: each particle's block, for the grid and width it was made for.
  std::vector<std::uint32_t> block_of_;
  int width_ = 0;
  std::array<int, Dim> nodes_along_{};
};

}  // namespace frostmpm
