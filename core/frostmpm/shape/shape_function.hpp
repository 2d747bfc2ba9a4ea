#pragma once
// 1-D shape functions of the MPM background grid; multi-dimensional weights are tensor
// products. Each kernel gives, for a particle coordinate, the first node of its support and
// the weights and derivatives on `width` consecutive nodes.
#include <string>
#include <type_traits>
#include <vector>

namespace frostmpm {

enum class ShapeKind { Linear, Gimp, CubicBSpline };

ShapeKind parse_shape_kind(const std::string& name);  ///< "linear", "gimp", "cubic_bspline"
std::string to_string(ShapeKind kind);
const std::vector<std::string>& shape_kind_names();

/// Nodes per dimension in the support of one particle.
constexpr int support_width(ShapeKind kind) {
  return kind == ShapeKind::Linear ? 2 : kind == ShapeKind::Gimp ? 3 : 4;
}

/// The most nodes a particle's support has (cubic B-splines in 3-D): the size of the per-particle
/// buffers that scatters fill before adding into the nodes.
constexpr int kMaxSupport = 64;

/// f(std::integral_constant<int, 3^Dim>) for GIMP stencils — loops over the support of a fixed
/// length, which the compiler unrolls — and f(K) for any other support size K.
template <int Dim, class F>
void for_support(int K, F&& f) {
  constexpr int gimp = Dim == 2 ? 9 : 27;
  if (K == gimp)
    f(std::integral_constant<int, gimp>{});
  else
    f(K);
}
/// Ghost node layers the grid needs beyond the domain for this kernel.
constexpr int ghost_layers(ShapeKind kind) { return kind == ShapeKind::CubicBSpline ? 1 : 0; }

/// 1-D weights for coordinate `xi` = (x - origin)/h in cell units. `half_size` is the GIMP
/// particle half-width in cell units (ignored by the others). Writes `width` weights and
/// d/dx derivatives (already divided by h) and returns the first node's lattice index.
int shape_1d(ShapeKind kind, double xi, double h, double half_size, double* weight, double* gradient);

}  // namespace frostmpm
