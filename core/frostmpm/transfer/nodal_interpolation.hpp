#pragma once
// A nodal field at a particle, through the particle's stencil: the value Σ_i S_ip f_i and the
// gradient Σ_i ∇S_ip f_i (G2P of one field). Every physics that reads grid values at its
// material points uses these.
#include <array>
#include <cstddef>

#include "frostmpm/shape/stencil_cache.hpp"

namespace frostmpm {

template <int Dim, class Nodal>
double nodal_value_at(const StencilCache<Dim>& st, std::size_t p, const Nodal& f) {
  const auto* nodes = st.nodes(p);
  const auto* w = st.weights(p);
  double value = 0;
  for (int k = 0; k < st.per_particle(); ++k) value += w[k] * f[nodes[k]];
  return value;
}

template <int Dim, class Nodal>
std::array<double, Dim> nodal_gradient_at(const StencilCache<Dim>& st, std::size_t p, const Nodal& f) {
  const auto* nodes = st.nodes(p);
  const auto* g = st.gradients(p);
  std::array<double, Dim> grad{};
  for (int k = 0; k < st.per_particle(); ++k)
    for (int d = 0; d < Dim; ++d) grad[d] += g[k * Dim + d] * f[nodes[k]];
  return grad;
}

}  // namespace frostmpm
