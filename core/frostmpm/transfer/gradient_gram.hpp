#pragma once
// G_ij = Σ_p c_p ∇S_ip·∇S_jp in a StencilGraph's pattern — the conduction and mobility matrices
// of the implicit heat and pressure equations — kept up to date incrementally.
//
// Why: on a rigid skeleton the stencils stay and only the coefficients near a phase front change
// from step to step (the ice moves the conductivity and the permeability), yet a full assembly
// costs K² entries per particle, every step. Here only the rows of nodes touched by a particle
// whose coefficient changed are rebuilt, from every particle touching them, in the same coloured
// order as a full assembly: the result is bitwise what a full assembly gives, so a restart (which
// assembles in full) continues bitwise. When particles move (a new stencil version) every row is
// rebuilt.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/transfer/stencil_graph.hpp"
#include "frostmpm/transfer/transfer.hpp"

namespace frostmpm {

template <int Dim>
class GradientGram {
 public:
  /// Forgets what was assembled: the next update() rebuilds every row (a new graph, a restart).
  void invalidate() { assembled_.clear(); }

  /// Brings values() to Σ_p c(p) ∇S_ip·∇S_jp for the transfer's current stencil in `graph`
  /// (whose scatter map must be current). c(p) is evaluated once per particle per call, on a new
  /// stencil by several threads at once (it must only read).
  /// Returns whether any entry changed.
  template <class Coefficient>
  bool update(const Transfer<Dim>& transfer, const StencilGraph& graph, Coefficient&& c) {
    const auto& st = transfer.stencil();
    const std::size_t n = st.particles(), rows = graph.rows();
    const int K = st.per_particle();
    bool any = false;
    if (values_.size() != graph.nonzeros() || version_ != st.version() || assembled_.size() != n) {
      // A new stencil (particles that move: every step): every entry assembled anew, in parallel.
      values_.resize(graph.nonzeros());
      assembled_.resize(n);
      version_ = st.version();
      parallel_for(values_.size(), [&](std::size_t e) { values_[e] = 0.0; });
      parallel_for(n, [&](std::size_t p) { assembled_[p] = c(p); });
      dirty_.assign(rows, 1);
      any = n > 0;
    } else {
      // The same stencil: only the rows of particles whose coefficient changed.
      dirty_.assign(rows, 0);
      for (std::size_t p = 0; p < n; ++p) {
        const double value = c(p);
        if (value == assembled_[p]) continue;
        assembled_[p] = value;
        const auto* nodes = st.nodes(p);
        for (int k = 0; k < K; ++k) dirty_[nodes[k]] = 1;
        any = true;
      }
      if (!any) return false;
      parallel_for(rows, [&](std::size_t i) {
        if (dirty_[i]) std::fill(values_.begin() + long(graph.offsets[i]), values_.begin() + long(graph.offsets[i + 1]), 0.0);
      });
    }
    if (!any) return false;
    transfer.scatter([&](std::size_t p) {
      const auto* nodes = st.nodes(p);
      bool touches = false;
      for (int k = 0; k < K; ++k) touches |= dirty_[nodes[k]] != 0;
      if (!touches) return;
      const auto* g = st.gradients(p);
      const int* slot = graph.scatter.data() + p * std::size_t(K) * std::size_t(K);
      const double a = assembled_[p];
      for (int i = 0; i < K; ++i) {
        if (!dirty_[nodes[i]]) continue;
        for (int j = 0; j < K; ++j) {
          double dot = 0;
          for (int d = 0; d < Dim; ++d) dot += g[i * Dim + d] * g[j * Dim + d];
          values_[slot[i * K + j]] += a * dot;
        }
      }
    });
    return true;
  }

  const std::vector<double>& values() const { return values_; }
  /// y = G x in `graph`'s pattern, row-parallel.
  void multiply(const StencilGraph& graph, std::span<const double> x, std::span<double> y) const {
    parallel_for(y.size(), [&](std::size_t i) {
      double s = 0;
      for (std::size_t e = graph.offsets[i]; e < graph.offsets[i + 1]; ++e) s += values_[e] * x[std::size_t(graph.columns[e])];
      y[i] = s;
    });
  }

 private:
  std::vector<double> values_;
  std::vector<double> assembled_;  ///< c_p as in values_ (NaN: not yet)
  std::vector<char> dirty_;
  std::uint64_t version_ = ~std::uint64_t{0};
};

}  // namespace frostmpm
