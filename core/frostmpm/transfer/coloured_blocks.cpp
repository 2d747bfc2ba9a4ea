#include "frostmpm/transfer/coloured_blocks.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace frostmpm {

template <int Dim>
void ColouredBlocks<Dim>::build(const UniformGrid<Dim>& grid, const StencilCache<Dim>& stencil, int width) {
  if (width < 1) throw std::invalid_argument("ColouredBlocks: width must be positive");
  const std::size_t n = stencil.particles();
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("ColouredBlocks: more than 2^32 particles");
  const int K = stencil.per_particle();
  // Block lattice: node columns -ghost .. cells+ghost, `width` per block along every axis but
  // the first, where a block is kRunNodes long: particles are made (and mostly stay) in rows
  // along that axis, so a block's particles lie in runs of consecutive indices as long as the
  // block. With 3-node-wide blocks a run was 6 particles (2 per cell), too short for the
  // hardware prefetcher: the P2G loops stalled on every run's first load of each particle array
  // (120k particles: 135 ns a particle-step for the mass and momentum scatter alone). The shape
  // depends on the grid only, so the order of every node's sum stays independent of threads.
  constexpr int kRunNodes = 32;
  std::array<int, Dim> size{};
  size.fill(width);
  size[0] = std::max(width, kRunNodes);
  std::array<int, Dim> blocks_along{};
  for (int d = 0; d < Dim; ++d) blocks_along[d] = (grid.nodes_along(d) + size[d] - 1) / size[d];
  std::size_t block_count = 1;
  for (int d = 0; d < Dim; ++d) block_count *= static_cast<std::size_t>(blocks_along[d]);

  // Block of every particle: from the lowest lattice node of its stencil (every node it
  // writes lies within `width` columns of it along each axis). A stencil is a tensor product of
  // one run of nodes per axis and a node's index grows with each of its lattice coordinates, so
  // the lowest node along every axis is the stencil's lowest index.
  // A stencil wrapped across a periodic seam spans (almost) the whole axis between its lowest
  // and highest node; it goes to the serial block `block_count` (a periodic axis has more cells
  // than the support is wide, so an unwrapped stencil never spans that far).
  const std::size_t wrapped_block = block_count;
  // A particle whose stencil changed mostly stays in its block (32 × 3 nodes): when none left
  // its block, the order, blocks and colours below would come out as they are, and are kept.
  std::array<int, Dim> nodes_along{};
  for (int d = 0; d < Dim; ++d) nodes_along[d] = grid.nodes_along(d);
  const bool same_layout = block_of_.size() == n && width == width_ && nodes_along == nodes_along_ && !order_.empty();
  block_of_.resize(n);
  width_ = width;
  nodes_along_ = nodes_along;
  std::atomic<bool> moved{!same_layout};
  std::vector<std::uint32_t>& block_of = block_of_;
  auto assign = [&](std::size_t p, std::size_t block) {
    const auto b = static_cast<std::uint32_t>(block);
    if (block_of[p] != b) {
      block_of[p] = b;
      // Stored once, not by every moved particle: the threads would take turns at its line.
      if (!moved.load(std::memory_order_relaxed)) moved.store(true, std::memory_order_relaxed);
    }
  };
  parallel_for(n, [&](std::size_t p) {
    const auto* nodes = stencil.nodes(p);
    std::uint32_t lowest = nodes[0], highest = nodes[0];
    for (int k = 1; k < K; ++k) {
      lowest = std::min(lowest, nodes[k]);
      highest = std::max(highest, nodes[k]);
    }
    const auto low = grid.node_lattice(lowest);
    if (grid.any_periodic()) {
      const auto high = grid.node_lattice(highest);
      for (int d = 0; d < Dim; ++d)
        if (std::abs(high[d] - low[d]) >= width) {
          assign(p, wrapped_block);
          return;
        }
    }
    std::size_t index = 0;
    for (int d = Dim - 1; d >= 0; --d)
      index = index * static_cast<std::size_t>(blocks_along[d]) +
              static_cast<std::size_t>((low[d] + grid.ghost_layers) / size[d]);
    assign(p, index);
  });
  if (!moved.load()) {
    version_ = stencil.version();
    return;
  }
  std::vector<std::uint32_t> count(block_count + 1, 0);
  for (std::size_t p = 0; p < n; ++p) ++count[block_of[p]];
  auto colour_of = [&](std::size_t block) {
    if (block == wrapped_block) return kColours;
    int colour = 0;
    for (int d = 0; d < Dim; ++d) {
      colour |= static_cast<int>(block % static_cast<std::size_t>(blocks_along[d]) % 2) << d;
      block /= static_cast<std::size_t>(blocks_along[d]);
    }
    return colour;
  };
  // Non-empty blocks, sorted by colour (then by block index, for a fixed order).
  std::vector<std::uint32_t> used;
  for (std::size_t b = 0; b <= block_count; ++b)
    if (count[b]) used.push_back(static_cast<std::uint32_t>(b));
  std::stable_sort(used.begin(), used.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return colour_of(a) < colour_of(b); });
  std::vector<std::uint32_t> slot(block_count + 1, 0);
  block_begin_.assign(used.size() + 1, 0);
  colour_begin_.fill(0);
  for (std::size_t i = 0; i < used.size(); ++i) {
    block_begin_[i + 1] = block_begin_[i] + count[used[i]];
    slot[used[i]] = block_begin_[i];
    colour_begin_[colour_of(used[i]) + 1] = static_cast<std::uint32_t>(i + 1);
  }
  for (int c = 1; c <= kGroups; ++c) colour_begin_[c] = std::max(colour_begin_[c], colour_begin_[c - 1]);
  order_.resize(n);
  for (std::size_t p = 0; p < n; ++p) order_[slot[block_of[p]]++] = static_cast<std::uint32_t>(p);
  version_ = stencil.version();
}

template class ColouredBlocks<2>;
template class ColouredBlocks<3>;

}  // namespace frostmpm
