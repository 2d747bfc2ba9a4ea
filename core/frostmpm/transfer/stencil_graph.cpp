#include "frostmpm/transfer/stencil_graph.hpp"

#include <algorithm>
#include <array>

#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm {

std::size_t StencilGraph::position(std::size_t row, int col) const {
  const auto begin = columns.begin() + static_cast<long>(offsets[row]);
  const auto end = columns.begin() + static_cast<long>(offsets[row + 1]);
  return static_cast<std::size_t>(std::lower_bound(begin, end, col) - columns.begin());
}

template <int Dim>
void StencilGraph::build(const StencilCache<Dim>& st, std::size_t nodes, bool squared,
                         const std::vector<std::vector<std::size_t>>& cliques) {
  const int K = st.per_particle();
  std::vector<std::vector<int>> rows(nodes);
  for (std::size_t i = 0; i < nodes; ++i) rows[i].push_back(static_cast<int>(i));
  for (std::size_t p = 0; p < st.particles(); ++p) {
    const auto* n = st.nodes(p);
    for (int a = 0; a < K; ++a)
      for (int b = 0; b < K; ++b) rows[n[a]].push_back(static_cast<int>(n[b]));
  }
  for (auto& c : rows) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
  }
  if (squared) {
    std::vector<std::vector<int>> wide(nodes);
    parallel_for(nodes, [&](std::size_t i) {
      for (const int j : rows[i]) wide[i].insert(wide[i].end(), rows[std::size_t(j)].begin(), rows[std::size_t(j)].end());
      std::sort(wide[i].begin(), wide[i].end());
      wide[i].erase(std::unique(wide[i].begin(), wide[i].end()), wide[i].end());
    });
    rows = std::move(wide);
  }
  for (const auto& clique : cliques) {
    for (std::size_t i : clique) {
      auto& c = rows[i];
      for (std::size_t k : clique) c.push_back(static_cast<int>(k));
      std::sort(c.begin(), c.end());
      c.erase(std::unique(c.begin(), c.end()), c.end());
    }
  }
  offsets.assign(nodes + 1, 0);
  columns.clear();
  for (std::size_t i = 0; i < nodes; ++i) {
    columns.insert(columns.end(), rows[i].begin(), rows[i].end());
    offsets[i + 1] = columns.size();
  }
  scatter.resize(st.particles() * K * K);
  parallel_for(st.particles(), [&](std::size_t p) {
    const auto* n = st.nodes(p);
    for (int a = 0; a < K; ++a)
      for (int b = 0; b < K; ++b) scatter[(p * K + a) * K + b] = static_cast<int>(position(n[a], static_cast<int>(n[b])));
  });
  diagonal.resize(nodes);
  for (std::size_t i = 0; i < nodes; ++i) diagonal[i] = position(i, static_cast<int>(i));
  fill_transpose();
}

template <int Dim>
void StencilGraph::build_lattice(const UniformGrid<Dim>& grid, int radius,
                                 const std::vector<std::vector<std::size_t>>& cliques) {
  const std::size_t nodes = grid.node_count();
  std::vector<std::vector<int>> extra(nodes);
  for (const auto& clique : cliques)
    for (std::size_t i : clique) extra[i].insert(extra[i].end(), clique.begin(), clique.end());
  offsets.assign(nodes + 1, 0);
  columns.clear();
  std::vector<int> row;
  for (std::size_t i = 0; i < nodes; ++i) {
    row.clear();
    const auto ijk = grid.node_lattice(i);
    // A periodic axis's last node row duplicates its first and no stencil reaches it: its row
    // holds its diagonal alone.
    bool seam = false;
    for (int d = 0; d < Dim; ++d) seam = seam || (grid.periodic[d] && grid.wrap(d, ijk[d]) != ijk[d]);
    if (seam) {
      columns.push_back(static_cast<int>(i));
      offsets[i + 1] = columns.size();
      continue;
    }
    std::array<int, Dim> lo{}, hi{}, at{};
    for (int d = 0; d < Dim; ++d) {
      // Along a periodic axis the neighbourhood wraps round the seam (the stencils do too).
      lo[d] = grid.periodic[d] ? ijk[d] - radius : std::max(ijk[d] - radius, -grid.ghost_layers);
      hi[d] = grid.periodic[d] ? ijk[d] + radius : std::min(ijk[d] + radius, grid.cells[d] + grid.ghost_layers);
    }
    at = lo;
    while (true) {
      std::array<int, Dim> wrapped{};
      for (int d = 0; d < Dim; ++d) wrapped[d] = grid.wrap(d, at[d]);
      row.push_back(static_cast<int>(grid.node_index(wrapped)));
      int d = 0;
      while (d < Dim && ++at[d] > hi[d]) {
        at[d] = lo[d];
        ++d;
      }
      if (d == Dim) break;
    }
    for (std::size_t k : extra[i]) row.push_back(static_cast<int>(k));
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    columns.insert(columns.end(), row.begin(), row.end());
    offsets[i + 1] = columns.size();
  }
  diagonal.resize(nodes);
  for (std::size_t i = 0; i < nodes; ++i) diagonal[i] = position(i, static_cast<int>(i));
  fill_transpose();
}

void StencilGraph::fill_transpose() {
  transpose.resize(columns.size());
  parallel_for(rows(), [&](std::size_t i) {
    for (std::size_t e = offsets[i]; e < offsets[i + 1]; ++e)
      transpose[e] = position(static_cast<std::size_t>(columns[e]), static_cast<int>(i));
  });
}

template <int Dim>
void StencilGraph::build_scatter(const StencilCache<Dim>& st) {
  const int K = st.per_particle();
  scatter.resize(st.particles() * K * K);
  parallel_for(st.particles(), [&](std::size_t p) {
    const auto* n = st.nodes(p);
    for (int a = 0; a < K; ++a)
      for (int b = 0; b < K; ++b) scatter[(p * K + a) * K + b] = static_cast<int>(position(n[a], static_cast<int>(n[b])));
  });
}

template void StencilGraph::build_lattice<2>(const UniformGrid<2>&, int, const std::vector<std::vector<std::size_t>>&);
template void StencilGraph::build_lattice<3>(const UniformGrid<3>&, int, const std::vector<std::vector<std::size_t>>&);
template void StencilGraph::build_scatter<2>(const StencilCache<2>&);
template void StencilGraph::build_scatter<3>(const StencilCache<3>&);
template void StencilGraph::build<2>(const StencilCache<2>&, std::size_t, bool,
                                     const std::vector<std::vector<std::size_t>>&);
template void StencilGraph::build<3>(const StencilCache<3>&, std::size_t, bool,
                                     const std::vector<std::vector<std::size_t>>&);

}  // namespace frostmpm
