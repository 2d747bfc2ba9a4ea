#include "frostmpm/shape/shape_function.hpp"

#include "frostmpm/shape/shape_kernels.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace frostmpm {

const std::vector<std::string>& shape_kind_names() {
  static const std::vector<std::string> names = {"linear", "gimp", "cubic_bspline"};
  return names;
}

ShapeKind parse_shape_kind(const std::string& name) {
  if (name == "linear") return ShapeKind::Linear;
  if (name == "gimp") return ShapeKind::Gimp;
  if (name == "cubic_bspline") return ShapeKind::CubicBSpline;
  throw std::invalid_argument("unknown shape function '" + name + "'");
}

std::string to_string(ShapeKind kind) { return shape_kind_names()[static_cast<int>(kind)]; }

int shape_1d(ShapeKind kind, double xi, double h, double half_size, double* weight, double* gradient) {
  switch (kind) {
    case ShapeKind::Linear: return shape_kernels::shape_1d<ShapeKind::Linear>(xi, h, half_size, weight, gradient);
    case ShapeKind::Gimp: return shape_kernels::shape_1d<ShapeKind::Gimp>(xi, h, half_size, weight, gradient);
    case ShapeKind::CubicBSpline:
      return shape_kernels::shape_1d<ShapeKind::CubicBSpline>(xi, h, half_size, weight, gradient);
  }
  return 0;
}

}  // namespace frostmpm
