// Explicit (forward Euler) step on the nodal heat content: e_i += Δt f_i / V_i, then
// T_i = H_i⁻¹(e_i) — latent heat is absorbed exactly, however narrow the freezing window.
#include <algorithm>

#include "frostmpm/parallel/parallel.hpp"
#include "thermal_physics.hpp"

namespace frostmpm::thermal {

/// The particles' flows at the nodal temperatures T_i, with ∇T_p = Σ_j T_j ∇S_jp computed once
/// per particle (matrix-free, coloured scatter):
///  - conduction, into node_force_: f_i = −Σ_p V_p κ_p ∇S_ip·∇T_p;
///  - convection, into advection_force_: a_i = −Σ_p V_p S_ip ρ_l c_l q_p·∇T_p with the particle
///    Darcy flux q_p (the paper's Eq. A15, first term; explicit in both schemes).
/// Returns Σ_i a_i: heat carried in by the flow [W per m], part of the boundary heat in the
/// energy balance (0 without convection).
double ThermalPhysics::particle_flows(bool conduction, bool convection) {
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  const auto q = convection ? water_flux_.values() : std::span<const double>{};
  if (conduction) std::fill(node_force_.begin(), node_force_.end(), 0.0);
  if (convection) std::fill(advection_force_.begin(), advection_force_.end(), 0.0);
  const int K = st.per_particle();
  kernel_->transfer().scatter([&](std::size_t p) {
    const auto* nodes = st.nodes(p);
    const auto* g = st.gradients(p);
    double grad[kDim] = {};
    for (int k = 0; k < K; ++k)
      for (int d = 0; d < kDim; ++d) grad[d] += (*node_T_)[nodes[k]] * g[k * kDim + d];
    if (conduction) {
      const double a = vol[p] * conductivity_[p];
      for (int k = 0; k < K; ++k) {
        double dot = 0;
        for (int d = 0; d < kDim; ++d) dot += g[k * kDim + d] * grad[d];
        node_force_[nodes[k]] -= a * dot;
      }
    }
    if (convection) {
      double rate = 0;
      for (int d = 0; d < kDim; ++d) rate += q[p * kDim + d] * grad[d];
      const double a = vol[p] * constants_[material_[p]].water_capacity * rate;
      const auto* w = st.weights(p);
      for (int k = 0; k < K; ++k) advection_force_[nodes[k]] -= a * w[k];
    }
  });
  if (!convection) return 0.0;
  return reproducible_sum(advection_force_.size(), [&](std::size_t i) { return advection_force_[i]; });
}

double ThermalPhysics::boundary_flow(double time, const std::vector<double>& T, std::vector<double>& into) const {
  double total = 0;
  for (const auto& bc : flux_) {
    const double q = value_at(bc, time);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
      if (node_volume_[bc.nodes[j]] <= 0) continue;
      into[bc.nodes[j]] += q * bc.areas[j];
      total += q * bc.areas[j];
    }
  }
  for (const auto& bc : convective_) {
    const double ambient = value_at(bc, time);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
      const std::size_t i = bc.nodes[j];
      if (node_volume_[i] <= 0) continue;
      const double flow = bc.coefficient * bc.areas[j] * (ambient - T[i]);
      into[i] += flow;
      total += flow;
    }
  }
  return total;
}

void ThermalPhysics::solve_explicit() {
  const double advected = particle_flows(/*conduction=*/true, /*convection=*/advection_);
  double boundary = boundary_flow(time_, (*node_T_), node_force_);
  if (advection_) {
    for (std::size_t i = 0; i < node_force_.size(); ++i) node_force_[i] += advection_force_[i];
    boundary += advected;
    advected_heat_ += dt_ * advected;
  }
  // Dirichlet nodes are reset to their target; what that takes beyond the heat the node's
  // neighbours and boundary flows gave it is the boundary's (the reaction).
  double reaction = 0;
  for (std::size_t i = 0; i < node_heat_.size(); ++i)
    if (dirichlet_[i] && node_volume_[i] > 0) {
      const double target = nodal_.heat(i, dirichlet_target_[i]);
      reaction += node_volume_[i] * (target - node_heat_[i]) - dt_ * node_force_[i];
      node_heat_[i] = target;
      (*node_T_)[i] = dirichlet_target_[i];
    }
  boundary_heat_ += dt_ * boundary + reaction;
  parallel_for(node_heat_.size(), [&](std::size_t i) {
    if (!is_free(i)) return;
    node_heat_[i] += dt_ * node_force_[i] / node_volume_[i];
    (*node_T_)[i] = nodal_.invert(i, node_heat_[i], (*node_T_)[i]);
  });
}

}  // namespace frostmpm::thermal
