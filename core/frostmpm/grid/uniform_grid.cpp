#include "frostmpm/grid/uniform_grid.hpp"

#include <algorithm>
#include <cmath>

namespace frostmpm {

GridFace GridFace::parse(const std::string& name, int dim, bool& ok) {
  static const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < dim; ++a)
    for (int side : {-1, 1})
      if (name == std::string(axes[a]) + (side < 0 ? "_min" : "_max")) {
        ok = true;
        return {a, side};
      }
  ok = false;
  return {};
}

std::string GridFace::name() const {
  static const char* axes[] = {"x", "y", "z"};
  return std::string(axes[axis]) + (side < 0 ? "_min" : "_max");
}

template <int Dim>
void face_nodes(const UniformGrid<Dim>& grid, GridFace face, std::vector<std::size_t>& nodes,
                std::vector<double>& areas) {
  nodes.clear();
  areas.clear();
  // Iterate the domain lattice of the face: fixed coordinate on `axis`, all others free.
  std::array<int, Dim> ijk{};
  std::array<int, Dim> count{};
  // Along a periodic axis node `cells` is node 0: the face has `cells` nodes, each a full cell.
  for (int d = 0; d < Dim; ++d) count[d] = grid.cells[d] + (grid.periodic[d] ? 0 : 1);
  count[face.axis] = 1;
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) total *= static_cast<std::size_t>(count[d]);
  for (std::size_t n = 0; n < total; ++n) {
    std::size_t rest = n;
    double area = 1.0;
    for (int d = 0; d < Dim; ++d) {
      ijk[d] = static_cast<int>(rest % static_cast<std::size_t>(count[d]));
      rest /= static_cast<std::size_t>(count[d]);
      if (d == face.axis) continue;
      // Tributary length: half a cell at the ends of the face, a full cell inside.
      const bool end = !grid.periodic[d] && (ijk[d] == 0 || ijk[d] == grid.cells[d]);
      area *= end ? 0.5 * grid.spacing[d] : grid.spacing[d];
    }
    ijk[face.axis] = face.side < 0 ? 0 : grid.cells[face.axis];
    nodes.push_back(grid.node_index(ijk));
    areas.push_back(area);
  }
}

template <int Dim>
std::vector<std::size_t> box_nodes(const UniformGrid<Dim>& grid, const std::array<double, Dim>& lo,
                                   const std::array<double, Dim>& hi) {
  std::vector<std::size_t> out;
  std::array<int, Dim> first{}, last{};
  for (int d = 0; d < Dim; ++d) {
    const double tol = 1e-9 * grid.spacing[d];
    first[d] = std::max(0, static_cast<int>(std::ceil((lo[d] - tol - grid.origin[d]) / grid.spacing[d])));
    last[d] = std::min(grid.cells[d] - (grid.periodic[d] ? 1 : 0), static_cast<int>(std::floor((hi[d] + tol - grid.origin[d]) / grid.spacing[d])));
    if (last[d] < first[d]) return out;
  }
  std::array<int, Dim> ijk = first;
  while (true) {
    out.push_back(grid.node_index(ijk));
    int d = 0;
    while (d < Dim && ++ijk[d] > last[d]) {
      ijk[d] = first[d];
      ++d;
    }
    if (d == Dim) break;
  }
  std::sort(out.begin(), out.end());
  return out;
}

template void face_nodes<2>(const UniformGrid<2>&, GridFace, std::vector<std::size_t>&, std::vector<double>&);
template void face_nodes<3>(const UniformGrid<3>&, GridFace, std::vector<std::size_t>&, std::vector<double>&);
template std::vector<std::size_t> box_nodes<2>(const UniformGrid<2>&, const std::array<double, 2>&,
                                               const std::array<double, 2>&);
template std::vector<std::size_t> box_nodes<3>(const UniformGrid<3>&, const std::array<double, 3>&,
                                               const std::array<double, 3>&);

}  // namespace frostmpm
