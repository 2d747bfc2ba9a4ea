#pragma once
// Uniform Cartesian background grid in Dim dimensions. Node (i, j[, k]) sits at
// origin + (i, j[, k]) * spacing; `ghost_layers` extra node layers on every side serve
// shape functions whose support reaches past the domain (cubic B-splines). A periodic axis
// identifies its max face with its min face: lattice coordinates wrap into [0, cells), so the
// nodes of lattice coordinate `cells` (and the ghost layers) along it are never used.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace frostmpm {

template <int Dim>
struct UniformGrid {
  static constexpr int kDim = Dim;
  std::array<double, Dim> origin{};
  std::array<double, Dim> spacing{};
  std::array<int, Dim> cells{};
  int ghost_layers = 0;
  std::array<bool, Dim> periodic{};

  bool any_periodic() const {
    for (int d = 0; d < Dim; ++d)
      if (periodic[d]) return true;
    return false;
  }
  /// Lattice coordinate i along axis d, brought into [0, cells) when the axis is periodic.
  int wrap(int d, int i) const {
    if (!periodic[d]) return i;
    const int n = cells[d];
    return ((i % n) + n) % n;
  }
  /// Position x along axis d, brought into [origin, origin + length) when the axis is periodic.
  double wrap_position(int d, double x) const {
    if (!periodic[d]) return x;
    const double length = cells[d] * spacing[d];
    double shifted = std::fmod(x - origin[d], length);
    if (shifted < 0) shifted += length;
    if (shifted >= length) shifted = 0;  // -1e-17 + length rounds to length
    return origin[d] + shifted;
  }

  int nodes_along(int d) const { return cells[d] + 1 + 2 * ghost_layers; }
  std::size_t node_count() const {
    std::size_t n = 1;
    for (int d = 0; d < Dim; ++d) n *= static_cast<std::size_t>(nodes_along(d));
    return n;
  }
  /// Linear index of node with lattice coordinates `ijk` (domain nodes are 0..cells[d]).
  std::size_t node_index(const std::array<int, Dim>& ijk) const {
    std::size_t index = 0;
    for (int d = Dim - 1; d >= 0; --d)
      index = index * static_cast<std::size_t>(nodes_along(d)) + static_cast<std::size_t>(ijk[d] + ghost_layers);
    return index;
  }
  std::array<int, Dim> node_lattice(std::size_t index) const {
    std::array<int, Dim> ijk{};
    for (int d = 0; d < Dim; ++d) {
      const auto n = static_cast<std::size_t>(nodes_along(d));
      ijk[d] = static_cast<int>(index % n) - ghost_layers;
      index /= n;
    }
    return ijk;
  }
  std::array<double, Dim> node_position(std::size_t index) const {
    const auto ijk = node_lattice(index);
    std::array<double, Dim> x{};
    for (int d = 0; d < Dim; ++d) x[d] = origin[d] + ijk[d] * spacing[d];
    return x;
  }
  std::size_t cell_count() const {
    std::size_t n = 1;
    for (int d = 0; d < Dim; ++d) n *= static_cast<std::size_t>(cells[d]);
    return n;
  }
  /// Linear index of the domain cell holding point x (points outside go to the nearest cell).
  std::size_t cell_of(const double* x) const {
    std::size_t index = 0;
    for (int d = Dim - 1; d >= 0; --d) {
      const int c = std::clamp(static_cast<int>(std::floor((x[d] - origin[d]) / spacing[d])), 0, cells[d] - 1);
      index = index * static_cast<std::size_t>(cells[d]) + static_cast<std::size_t>(c);
    }
    return index;
  }
  double cell_volume() const {
    double v = 1;
    for (int d = 0; d < Dim; ++d) v *= spacing[d];
    return v;
  }
  double min_spacing() const {
    double h = spacing[0];
    for (int d = 1; d < Dim; ++d) h = std::min(h, spacing[d]);
    return h;
  }
  std::array<double, Dim> upper() const {
    std::array<double, Dim> x{};
    for (int d = 0; d < Dim; ++d) x[d] = origin[d] + cells[d] * spacing[d];
    return x;
  }
};

/// A face of the grid's domain box: axis 0..Dim-1, side -1 (min) or +1 (max).
struct GridFace {
  int axis = 0;
  int side = -1;
  static GridFace parse(const std::string& name, int dim, bool& ok);  ///< "x_min", "y_max", ...
  std::string name() const;
};

/// Domain nodes on a face, and the area (length in 2D, per unit thickness) each represents.
template <int Dim>
void face_nodes(const UniformGrid<Dim>& grid, GridFace face, std::vector<std::size_t>& nodes,
                std::vector<double>& areas);

/// Domain nodes inside an axis-aligned box (inclusive, with a tolerance of 1e-9 h).
template <int Dim>
std::vector<std::size_t> box_nodes(const UniformGrid<Dim>& grid, const std::array<double, Dim>& lo,
                                   const std::array<double, Dim>& hi);

}  // namespace frostmpm
