// Implicit (backward Euler) step: for the nodal temperatures T of the free nodes solve
//     R_i(T) = V_i (H_i(T_i) − e_i^n)/Δt + (K T)_i + h A_i T_i − (q A_i + h A_i T_a) = 0
// by Newton's method. R is the gradient of the strictly convex functional
//     Ψ(T) = Σ_i V_i (∫H_i − e_i^n T_i)/Δt + ½ Tᵀ(K + hA)T − Tᵀ(qA + hA T_a),
// so the Newton direction (tangent J = K + diag(V_i H_i'(T_i)/Δt + h A_i), symmetric positive
// definite: CG) is a descent direction, and an exact line search on Ψ along it — finding the
// zero of the monotone φ'(s) = δ·R(T + s δ), nodal work only, since K T and K δ are known —
// makes every iteration decrease Ψ: the iteration converges from any start, however narrow
// the freezing window. A step that still does not converge within max_nonlinear_iterations is
// never accepted: it is restarted as two half steps (recursively, up to max_step_halvings).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "frostmpm/parallel/parallel.hpp"
#include "thermal_physics.hpp"

namespace frostmpm::thermal {

void ThermalPhysics::build_graph() {
  const std::size_t nodes = node_volume_.size();
  graph_.build(kernel_->transfer().stencil(), nodes);
  graph_.topology_version = kernel_->transfer().topology_version();
  SolverOptions options;
  options.method = "cg";
  options.preconditioner = params_.string("preconditioner");
  options.tolerance = params_.real("linear_tolerance");
  options.max_iterations = 5000;
  options.restorable_preconditioner = false;  // each step builds its own (newton())
  system_ = std::make_unique<SparseSystem>(graph_.offsets, graph_.columns, options);
  free_stiffness_.assign(graph_.nonzeros(), 0.0);
  for (auto* v : {&boundary_diagonal_, &boundary_load_, &residual_, &rhs_, &increment_, &K_times_T_,
                  &K_times_increment_, &start_heat_, &start_T_})
    v->assign(nodes, 0.0);
  // The last substep's start temperatures stay: a new graph (particles moved into other stencils,
  // or a restart, which restored them) does not change the nodes, and the next first guess
  // extrapolates from them. Zeroed, that guess would be twice the temperature.
  if (node_T_before_.size() != nodes) node_T_before_.assign(nodes, 0.0);
  conduction_.invalidate();  // a new graph is assembled in full
}

/// K = Σ_p V_p κ_p ∇S_ip·∇S_jp, once per step (κ is fixed within it; only the rows near a
/// particle whose κ changed are rebuilt, bitwise as a full assembly). Then the copy with the rows
/// and columns of fixed nodes (Dirichlet, empty) replaced by the identity: the Newton correction
/// is zero there, so no right-hand side changes.
void ThermalPhysics::assemble_conductivity() {
  const auto vol = volume_.values();
  conduction_.update(kernel_->transfer(), graph_, [&](std::size_t p) { return vol[p] * conductivity_[p]; });
  const auto& stiffness = conduction_.values();
  parallel_for(node_volume_.size(), [&](std::size_t i) {
    const bool fixed_row = !is_free(i);
    for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(graph_.columns[e]);
      free_stiffness_[e] = fixed_row ? (i == j ? 1.0 : 0.0) : is_free(j) ? stiffness[e] : 0.0;
    }
  });
}

void ThermalPhysics::multiply_conductivity(const std::vector<double>& x, std::vector<double>& y) const {
  conduction_.multiply(graph_, x, y);
}

/// R(T) into residual_ (zero at fixed nodes) and K T into K_times_T_; returns the largest
/// residual as temperature: max |R_i| Δt / (V_i C_i) with C_i the node's sensible capacity.
double ThermalPhysics::nodal_residual(double h) {
  multiply_conductivity((*node_T_), K_times_T_);
  return parallel_max(
      (*node_T_).size(),
      [&](std::size_t i) {
        if (!is_free(i)) {
          residual_[i] = 0;
          return 0.0;
        }
        const double Hi = nodal_.heat(i, (*node_T_)[i]);
        residual_[i] = node_volume_[i] * (Hi - node_heat_[i]) / h + K_times_T_[i] +
                       boundary_diagonal_[i] * (*node_T_)[i] - boundary_load_[i];
        const double worst = std::abs(residual_[i]) * h / (node_volume_[i] * nodal_.min_capacity(i));
        return std::isfinite(worst) ? worst : std::numeric_limits<double>::infinity();
      },
      0.0);
}

/// The step length s in (0, 1] minimizing Ψ(T + s δ): the zero of the increasing
/// φ'(s) = δ·R(T + s δ), by the Illinois variant of regula falsi, to 10 % of φ'(0).
double ThermalPhysics::line_search(double h) {
  auto slope = [&](double s) {
    return reproducible_sum((*node_T_).size(), [&](std::size_t i) {
      if (!is_free(i) || increment_[i] == 0) return 0.0;
      const double Ti = (*node_T_)[i] + s * increment_[i];
      const double Ri = node_volume_[i] * (nodal_.heat(i, Ti) - node_heat_[i]) / h + K_times_T_[i] +
                        s * K_times_increment_[i] + boundary_diagonal_[i] * Ti - boundary_load_[i];
      return increment_[i] * Ri;
    });
  };
  const double f0 = slope(0.0);
  if (!(f0 < 0)) return 1.0;  // not a descent direction (round-off at convergence): take it
  double a = 0, fa = f0, b = 1, fb = slope(1.0);
  if (fb <= 0) return 1.0;  // the minimum lies at or beyond the full Newton step
  int side = 0;
  for (int it = 0; it < 40; ++it) {
    const double s = (a * fb - b * fa) / (fb - fa);
    const double fs = slope(s);
    if (std::abs(fs) <= 0.1 * std::abs(f0)) return s;
    if (fs < 0) {
      a = s;
      fa = fs;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = s;
      fb = fs;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return 0.5 * (a + b);
}

void ThermalPhysics::report_not_finite(double t_end, double h) const {
  std::size_t i = 0;
  while (i + 1 < residual_.size() && std::isfinite(residual_[i]) && std::isfinite((*node_T_)[i])) ++i;
  const auto x = kernel_->grid().node_position(i);
  std::ostringstream msg;
  msg << "numerical blow-up: temperature equation not finite at grid node " << i << " (x = " << x[0] << ", y = " << x[1]
      << ") at t = " << t_end << " s, step " << kernel_->step() << " (dt = " << h
      << " s); check boundary values and material parameters";
  throw NumericalBlowUp(msg.str());
}

bool ThermalPhysics::newton(double t_end, double h) {
  std::fill(boundary_diagonal_.begin(), boundary_diagonal_.end(), 0.0);
  std::fill(boundary_load_.begin(), boundary_load_.end(), 0.0);
  for (const auto& bc : flux_) {
    const double q = value_at(bc, t_end);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) boundary_load_[bc.nodes[j]] += q * bc.areas[j];
  }
  if (advection_)
    for (std::size_t i = 0; i < boundary_load_.size(); ++i) boundary_load_[i] += advection_force_[i];
  for (const auto& bc : convective_) {
    const double ambient = value_at(bc, t_end);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
      boundary_diagonal_[bc.nodes[j]] += bc.coefficient * bc.areas[j];
      boundary_load_[bc.nodes[j]] += bc.coefficient * bc.areas[j] * ambient;
    }
  }
  // Inexact Newton: each linear solve only needs to shrink the residual in proportion to how far
  // Newton still is from the solution (Eisenstat–Walker, choice 2), down to linear_tolerance.
  const double linear_floor = params_.real("linear_tolerance");
  double previous_worst = 0, forcing = 1e-2;
  for (long it = 1; it <= max_nonlinear_iterations_; ++it) {
    const double worst = nodal_residual(h);
    if (worst <= nonlinear_tolerance_) {
      nonlinear_total_ += it - 1;
      nonlinear_max_ = std::max(nonlinear_max_, it - 1);
      return true;
    }
    if (!std::isfinite(worst)) report_not_finite(t_end, h);
    if (it > 1) forcing = std::clamp(0.9 * std::pow(worst / previous_worst, 2.0), linear_floor, 1e-2);
    previous_worst = worst;
    // The tangent K + C/h, written straight into the system's values.
    const auto tangent = system_->mutable_values();
    std::copy(free_stiffness_.begin(), free_stiffness_.end(), tangent.begin());
    parallel_for((*node_T_).size(), [&](std::size_t i) {
      rhs_[i] = -residual_[i];
      increment_[i] = 0.0;
      if (is_free(i))
        tangent[graph_.diagonal[i]] += node_volume_[i] * nodal_.capacity(i, (*node_T_)[i]) / h + boundary_diagonal_[i];
    });
    // The preconditioner is built once per step, from the step's first tangent, and reused by the
    // later iterations (a private copy of the values keeps it a fixed SPD operator); Jacobi costs
    // nothing to refresh. A fixed policy keeps restarts bitwise.
    const auto update = !preconditioner_fresh_ ? PreconditionerUpdate::Rebuild
                         : params_.string("preconditioner") == "jacobi" ? PreconditionerUpdate::Refresh
                                                                         : PreconditionerUpdate::Reuse;
    SolveStats stats;
    try {
      stats = system_->solve(rhs_, increment_, update, forcing);
    } catch (const std::exception&) {
      break;  // a breakdown: retried in halves like any failed step
    }
    preconditioner_fresh_ = true;
    linear_total_ += stats.iterations;
    multiply_conductivity(increment_, K_times_increment_);
    const double s = line_search(h);
    parallel_for((*node_T_).size(), [&](std::size_t i) {
      if (is_free(i)) (*node_T_)[i] += s * increment_[i];
    });
  }
  nonlinear_total_ += max_nonlinear_iterations_;
  return false;
}

void ThermalPhysics::solve_implicit() {
  if (!system_ || kernel_->transfer().topology_version() != graph_.topology_version) build_graph();
  assemble_conductivity();
  preconditioner_fresh_ = false;  // the tangent's off-diagonal part changed with κ
  // The convective term is lagged (the temperatures and flux of the step's start): a source for
  // the whole step, so the Newton tangent stays symmetric (CG) and the step keeps its energy
  // functional; stable_time_step() bounds Δt by 2α/u².
  advected_rate_ = advection_ ? particle_flows(/*conduction=*/false, /*convection=*/true) : 0.0;
  const std::size_t nodes = (*node_T_).size();
  const double end = time_ + dt_;
  long level = std::max(0L, halvings_ - 1);  // start one level coarser than last time
  double t = time_;
  while (end - t > 1e-12 * dt_) {
    double h = std::min(dt_ / std::ldexp(1.0, int(level)), end - t);
    if (end - t - h < 1e-9 * dt_) h = end - t;
    start_heat_ = node_heat_;
    start_T_ = (*node_T_);
    set_dirichlet_targets(t + h);
    // First guess: the free nodes continue their last change (the solution does not depend on
    // it — Ψ is strictly convex — but Newton starts closer).
    const double ratio = previous_substep_ > 0 ? h / previous_substep_ : 0.0;
    for (std::size_t i = 0; i < nodes; ++i) {
      if (dirichlet_[i]) (*node_T_)[i] = dirichlet_target_[i];
      else if (ratio > 0 && node_volume_[i] > 0) (*node_T_)[i] += ratio * (start_T_[i] - node_T_before_[i]);
    }
    if (!newton(t + h, h)) {
      node_heat_ = start_heat_;
      (*node_T_) = start_T_;
      ++rejected_substeps_;
      if (++level > max_step_halvings_) {
        std::size_t worst = 0;
        for (std::size_t i = 0; i < nodes; ++i)
          if (std::abs(residual_[i]) > std::abs(residual_[worst])) worst = i;
        const auto x = kernel_->grid().node_position(worst);
        std::ostringstream msg;
        msg << "numerical blow-up: the implicit thermal step from t = " << t << " s (step " << kernel_->step()
            << ") did not converge even at dt = " << h << " s after " << max_step_halvings_
            << " halvings; largest energy residual at grid node " << worst << " (x = " << x[0] << ", y = " << x[1]
            << "); check the material parameters and boundary values";
        throw NumericalBlowUp(msg.str());
      }
      continue;
    }
    // Accept. The nodes' heat is updated by the flows at the converged temperatures, so the step
    // conserves energy to round-off whatever is left of the Newton residual; the temperatures
    // then follow the heat (they move by less than nonlinear_tolerance). Boundary heat of the
    // substep: the flux and convective flows, plus the Dirichlet reactions.
    multiply_conductivity((*node_T_), K_times_T_);
    double reaction = 0, flows = 0;
    for (std::size_t i = 0; i < nodes; ++i) {
      if (node_volume_[i] <= 0) continue;
      const double flow = boundary_load_[i] - boundary_diagonal_[i] * (*node_T_)[i];
      flows += flow;
      if (dirichlet_[i]) {
        const double e = nodal_.heat(i, (*node_T_)[i]);
        reaction += node_volume_[i] * (e - start_heat_[i]) - h * (flow - K_times_T_[i]);
        node_heat_[i] = e;
      } else {
        node_heat_[i] += h * (flow - K_times_T_[i]) / node_volume_[i];
      }
    }
    boundary_heat_ += h * flows + reaction;
    advected_heat_ += h * advected_rate_;
    parallel_for(nodes, [&](std::size_t i) {
      if (is_free(i)) (*node_T_)[i] = nodal_.invert(i, node_heat_[i], (*node_T_)[i]);
    });
    node_T_before_ = start_T_;
    previous_substep_ = h;
    ++substeps_;
    smallest_substep_ = std::min(smallest_substep_, h);
    t += h;
  }
  halvings_ = level;
}

}  // namespace frostmpm::thermal
