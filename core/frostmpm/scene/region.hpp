#pragma once
// Regions fill the domain with particles: box, disk, half_disk, polygon. Particles sit at the
// centres of an n×n sub-cell lattice of the background grid, keeping those inside the shape.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/grid/uniform_grid.hpp"

namespace frostmpm {

struct RegionShape {
  std::string kind;  ///< box, disk, half_disk, polygon
  std::function<bool(const std::array<double, 2>&)> contains;
  YAML::Node resolved;
};

/// Reads `{box: {min, max}}`, `{disk: {center, radius}}`, `{half_disk: {center, radius,
/// side: top|bottom|left|right}}` or `{polygon: [[x, y], ...]}` (exactly one key).
RegionShape read_region_shape(const ConfigNode& node);

/// Lattice points of the grid (n per cell per axis) inside `shape` and inside the domain.
std::vector<std::array<double, 2>> sample_region(const UniformGrid<2>& grid, const RegionShape& shape,
                                                 int particles_per_cell);

}  // namespace frostmpm
