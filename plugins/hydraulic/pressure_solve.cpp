// The pressure Poisson equation of the fractional step (paper Eq. 56, fixed skeleton):
//   (M / Δt + K) Δp = Σ_p V_p n_l ∇S_ip · v*_p + ∫ S_i q̂ dS,
//   M_ii = Σ_p V_p n_l c_w S_ip (lumped), K_ij = Σ_p V_p Δt η_p ∇S_ip · ∇S_jp,
// with Δp = p̂(t + Δt) − p_i on pressure boundaries (rows and columns eliminated, so A stays
// symmetric positive definite for CG) and Δp = 0 on nodes no wet particle touches.
#include <chrono>
#include <cmath>
#include <sstream>

#include "frostmpm/parallel/parallel.hpp"
#include "hydraulic_physics.hpp"

namespace frostmpm::hydraulic {

void HydraulicPhysics::assemble() {
  const auto& st = sim_->stencil();
  const auto vol = sim_->particles().field("volume");
  const std::size_t nodes = node_mass_.size();
  if (!system_ || graph_.stencil_version != st.version()) {
    graph_.build(st, nodes);
    SolverOptions options;
    options.method = params_.string("solver");
    options.preconditioner = params_.string("preconditioner");
    options.tolerance = params_.real("linear_tolerance");
    options.max_iterations = static_cast<int>(params_.integer("max_linear_iterations"));
    system_ = std::make_unique<SparseSystem>(graph_.offsets, graph_.columns, options);
    preconditioner_built_ = false;
  }
  values_.assign(graph_.nonzeros(), 0.0);
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
  std::vector<double> node_storage(nodes, 0.0);
  const int K = st.per_particle();
  const auto v_star = sim_->particles().field("liquid_velocity_predicted");
  blocks_.for_each([&](std::size_t q) {
    const auto* n = st.nodes(q);
    const auto* w = st.weights(q);
    const auto* g = st.gradients(q);
    const int* slot = graph_.scatter.data() + q * K * K;
    const double k = vol[q] * dt_ * eta_[q];
    const double* v = v_star.data() + q * kDim;
    const double flux = vol[q] * n_l_[q];
    for (int a = 0; a < K; ++a) {
      node_storage[n[a]] += w[a] * vol[q] * storage_[q];
      double divergence = 0;
      for (int d = 0; d < kDim; ++d) divergence += g[a * kDim + d] * v[d];
      rhs_[n[a]] += flux * divergence;
      if (k == 0) continue;
      for (int b = 0; b < K; ++b) {
        double dot = 0;
        for (int d = 0; d < kDim; ++d) dot += g[a * kDim + d] * g[b * kDim + d];
        values_[slot[a * K + b]] += k * dot;
      }
    }
  });
  for (std::size_t i = 0; i < nodes; ++i) values_[graph_.diagonal[i]] += node_storage[i] / dt_;
  for (const auto& bc : flux_bcs_) {
    const double q = bc.value(time_ + dt_);
    if (!std::isfinite(q)) {
      std::ostringstream msg;
      msg << "numerical blow-up: water flux boundary value " << q << " from the " << bc.label << " at t = "
          << time_ + dt_ << " s, step " << sim_->step() << "; check the value's table or expression";
      throw NumericalBlowUp(msg.str());
    }
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) rhs_[bc.nodes[j]] += q * bc.areas[j];
  }

  // Fixed rows: pressure boundaries (Δp prescribed) and dry or empty nodes (Δp = 0). Their
  // columns move to the right-hand side, so A stays symmetric.
  auto& dp = *dp_;
  std::vector<char> fixed(nodes, 0);
  for (std::size_t i = 0; i < nodes; ++i)  // free nodes keep the last increment: the warm start
    if (node_mass_[i] <= 0) {
      fixed[i] = 1;
      dp[i] = 0.0;
    }
  for (const auto& bc : pressure_bcs_) {
    const auto target = boundary_pressures(bc, time_ + dt_);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
      dp[bc.nodes[j]] = target[j] - (*p_)[bc.nodes[j]];
      fixed[bc.nodes[j]] = 1;
    }
  }
  for (std::size_t i = 0; i < nodes; ++i) {
    if (!fixed[i]) continue;
    for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(graph_.columns[e]);
      if (j == i) continue;
      const std::size_t ji = graph_.position(j, static_cast<int>(i));
      if (!fixed[j]) rhs_[j] -= values_[ji] * dp[i];
      values_[ji] = 0.0;
      values_[e] = 0.0;
    }
    values_[graph_.diagonal[i]] = 1.0;
    rhs_[i] = dp[i];
  }
}

void HydraulicPhysics::solve_pressure() {
  assemble();
  // The matrix changes every step a thermal physics moves the ice, but only near the front:
  // the preconditioner of an earlier step stays good. It is refreshed when the iteration count
  // has grown by half over the count right after the last refresh (and built on a new graph).
  const PreconditionerUpdate update = !preconditioner_built_ ? PreconditionerUpdate::Rebuild
                                     : refresh_due_         ? PreconditionerUpdate::Refresh
                                                            : PreconditionerUpdate::Reuse;
  system_->set_values(values_);
  const auto start = std::chrono::steady_clock::now();
  const SolveStats stats = system_->solve(rhs_, *dp_, update);
  solve_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++solves_;
  step_iterations_.push_back(stats.iterations);
  step_residuals_.push_back(stats.relative_residual);
  if (update != PreconditionerUpdate::Reuse) {
    iterations_after_refresh_ = stats.iterations;
    ++preconditioner_updates_;
    preconditioner_built_ = true;
  }
  refresh_due_ = stats.iterations > 1.5 * iterations_after_refresh_ + 2;
  iterations_total_ += stats.iterations;
  iterations_max_ = std::max<long>(iterations_max_, stats.iterations);
  residual_max_ = std::max(residual_max_, stats.relative_residual);
  if (!stats.converged || !std::isfinite(stats.relative_residual)) {
    std::ostringstream msg;
    msg << "pressure solve did not converge at t = " << time_ << " s (step " << sim_->step() << ", dt = " << dt_
        << " s): relative residual " << stats.relative_residual << " after " << stats.iterations
        << " " << params_.string("solver") << " iterations (physics.hydraulic.linear_tolerance " << params_.real("linear_tolerance")
        << ", max_linear_iterations " << params_.integer("max_linear_iterations")
        << "); raise max_linear_iterations, try another preconditioner or a smaller time.dt";
    throw NumericalBlowUp(msg.str());
  }
}

}  // namespace frostmpm::hydraulic
