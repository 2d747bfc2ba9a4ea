// The pressure Poisson equation of the fractional step (paper Eq. 56, fixed skeleton):
//   ((M + H) / Δt + K) Δp = Σ_p V_p n_l ∇S_ip · v*_p − Σ_p S_ip V_p s_p + ∫ S_i q̂ dS,
//   M_ii = Σ_p V_p n_l c_w S_ip (lumped), K_ij = Σ_p V_p Δt η_p ∇S_ip · ∇S_jp,
//   s_p = (ζ φ ∂S_l/∂T − β_m) Ṫ the phase-change and thermal-expansion source (update_source),
//   H the polynomial pressure projection τ/(2G) ∫ (S − ΠS)ᵀ(S − ΠS) dV (Eq. 67, add_stabilization),
// with Δp = p̂(t + Δt) − p_i on pressure boundaries (rows and columns eliminated, so A stays
// symmetric positive definite for CG) and Δp = 0 on nodes no wet particle touches.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "frostmpm/linalg/csr_matrix.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/shape/shape_function.hpp"
#include "hydraulic_physics.hpp"

namespace frostmpm::hydraulic {

void HydraulicPhysics::assemble() {
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  const std::size_t nodes = node_mass_.size();
  // A rigid plate's nodes change as it moves (and as nodes gain or lose mass), and with them the
  // rows it couples as one body: when they leave the graph's plate rows, the graph is built anew
  // with the union of both (it only grows), so that every pair the plate term adds to is in it.
  // The plates and their rows are found once a step, for the graph here and the plate term.
  find_plates();
  const std::vector<std::vector<std::size_t>> plate_rows = group_rows();
  bool plates_outgrown = false;
  if (coupled_ && (system_ || restore_system_)) {  // after a restart: against the checkpoint's rows
    for (std::size_t g = 0; g < plate_rows.size() && !plates_outgrown; ++g)
      plates_outgrown = g >= graph_groups_.size() || !std::includes(graph_groups_[g].begin(), graph_groups_[g].end(),
                                                                   plate_rows[g].begin(), plate_rows[g].end());
    if (plates_outgrown) {
      graph_groups_.resize(std::max(graph_groups_.size(), plate_rows.size()));
      for (std::size_t g = 0; g < plate_rows.size(); ++g) {
        std::vector<std::size_t> both;
        std::set_union(graph_groups_[g].begin(), graph_groups_[g].end(), plate_rows[g].begin(), plate_rows[g].end(),
                       std::back_inserter(both));
        graph_groups_[g] = std::move(both);
      }
      system_.reset();  // rebuilt below, with a new preconditioner
    }
  }
  if (coupled_ && system_ && graph_.topology_version != kernel_->transfer().topology_version()) {
    // Particles moved into other stencils: the lattice patterns stay, only their map from
    // particle pairs to entries changes.
    graph_.build_scatter(st);
    compact_.build_scatter(st);
    graph_.topology_version = kernel_->transfer().topology_version();
    mobility_gram_.invalidate();
  }
  if (!system_ || graph_.topology_version != kernel_->transfer().topology_version()) {
    if (coupled_) {
      // A moving skeleton: fixed lattice patterns for the whole run. The matrix couples nodes two
      // stencils apart (Q M⁻¹ Qᵀ), and every node near a rigid plate with every other (the plate
      // moves as one body); Q itself one stencil apart.
      const int reach = support_width(st.kind()) - 1;
      if (!restore_system_ && !plates_outgrown) graph_groups_ = plate_rows;
      graph_.build_lattice(kernel_->grid(), 2 * reach, graph_groups_);
      graph_.build_scatter(st);
      compact_.build_lattice(kernel_->grid(), reach);
      compact_.build_scatter(st);
    } else {
      graph_.build(st, nodes);
    }
    graph_.topology_version = kernel_->transfer().topology_version();
    ++graph_builds_;
    mobility_gram_.invalidate();
    SolverOptions options;
    options.method = params_.string("solver");
    options.preconditioner = params_.string("preconditioner");
    options.tolerance = params_.real("linear_tolerance");
    options.max_iterations = static_cast<int>(params_.integer("max_linear_iterations"));
    system_ = std::make_unique<SparseSystem>(graph_.offsets, graph_.columns, options);
    if (restore_system_ && plates_outgrown) {  // a restart at the step the straight run rebuilt
      restore_system_ = false;
      saved_source_ = {};
      preconditioner_built_ = false;
    } else if (restore_system_) {  // a restart: the preconditioner the checkpointed run had (its flags came back)
      system_->restore_preconditioner(saved_source_);
      restore_system_ = false;
      saved_source_ = {};
    } else {
      preconditioner_built_ = false;
    }
  }
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
  node_storage_.assign(nodes, 0.0);
  const int K = st.per_particle();
  const auto v_star = predicted_.values();
  // A moving skeleton: the relative flux n_l (v_l* − v_s*) crosses the test functions' gradients
  // and (1 − ζ S_c) ∇·v_s* changes the volume (Eq. 56; the divergence at the particle, not
  // integrated by parts, so a free surface needs no boundary term). The coefficient is Eq. 6's:
  // its −ζ Dn_c/Dt, with n_c = φ S_c, S_c = S_c(T) and Dφ/Dt = (1 − φ) ∇·v_s, holds ζ S_c (1 − φ)
  // ∇·v_s besides the phase change, the ice that the pores' compression melts at a fixed S_c;
  // the printed Eq. 7 keeps only (1 − ζ n_c) and loses that water (docs/theory.md, Departures).
  const auto vs = coupled_ ? node_solid_predicted_.values() : std::span<const double>{};
  const auto phi = porosity_.values();
  kernel_->transfer().scatter([&](std::size_t q) {
    const auto* n = st.nodes(q);
    const auto* w = st.weights(q);
    const auto* g = st.gradients(q);
    double relative[kDim];
    const double* v = v_star.data() + q * kDim;
    double skeleton_volume = 0;  // V (1 − ζ S_c) ∇·v_s*
    if (coupled_) {
      const auto skeleton = kernel_->transfer().vector_at(q, vs);
      const auto stretch = kernel_->transfer().gradient_diagonal_at(q, vs);
      for (int d = 0; d < kDim; ++d) {
        relative[d] = v[d] - skeleton[d];
        skeleton_volume += stretch[d];
      }
      // Without the phase change's volume (the paper's Test C drops Eq. 6's ζ Dn_c/Dt whole) the
      // skeleton's coefficient is Eq. 6's remaining 1 − ζ n_c.
      const double S_c = phi[q] > 0 ? 1.0 - n_l_[q] / phi[q] : 0.0;
      const double ice = phase_change_source_ ? S_c : phi[q] - n_l_[q];
      ice_weight_[q] = vol[q] * materials_[material_[q]].zeta * ice;
      // and what the last step's projection left out of that volume (correct())
      skeleton_volume = (vol[q] - ice_weight_[q]) * skeleton_volume + melt_carried_[q] / dt_;
      v = relative;
    }
    const double flux = vol[q] * n_l_[q], storage = vol[q] * storage_[q] / dt_, source = vol[q] * source_[q];
    for (int a = 0; a < K; ++a) {
      node_storage_[n[a]] += w[a] * storage;  // M lumped (onto the diagonal below)
      double divergence = 0;
      for (int d = 0; d < kDim; ++d) divergence += g[a * kDim + d] * v[d];
      rhs_[n[a]] += flux * divergence - w[a] * source;
      if (coupled_) rhs_[n[a]] -= w[a] * skeleton_volume;
    }
  });
  // Δt K + M/Δt: K kept up to date row by row (only rows near a particle whose mobility changed).
  mobility_gram_.update(kernel_->transfer(), graph_, [&](std::size_t q) { return vol[q] * eta_[q]; });
  const auto& mobility = mobility_gram_.values();
  values_.resize(graph_.nonzeros());
  parallel_for(nodes, [&](std::size_t i) {
    for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e) values_[e] = dt_ * mobility[e];
    values_[graph_.diagonal[i]] += node_storage_[i];
  });
  if (coupled_) assemble_skeleton();
  if (stabilized_) add_stabilization();
  for (auto& bc : flux_bcs_) {
    const double q = bc.value(time_ + dt_);
    if (!std::isfinite(q)) {
      std::ostringstream msg;
      msg << "numerical blow-up: water flux boundary value " << q << " from the " << bc.label << " at t = "
          << time_ + dt_ << " s, step " << kernel_->step() << " (dt = " << dt_
          << " s); check the value's table or expression";
      throw NumericalBlowUp(msg.str());
    }
    bc.applied = 0;
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
      rhs_[bc.nodes[j]] += q * bc.areas[j];
      bc.applied += q * bc.areas[j];
    }
  }

  // The pressure-boundary rows as assembled, for the inflow they measure after the solve.
  boundary_rows_.clear();
  boundary_rhs_.clear();
  for (const std::size_t i : pressure_nodes_) {
    boundary_rows_.insert(boundary_rows_.end(), values_.begin() + static_cast<std::ptrdiff_t>(graph_.offsets[i]),
                          values_.begin() + static_cast<std::ptrdiff_t>(graph_.offsets[i + 1]));
    boundary_rhs_.push_back(rhs_[i]);
  }

  // Fixed rows: pressure boundaries (Δp prescribed) and dry or empty nodes (Δp = 0). Their
  // columns move to the right-hand side, so A stays symmetric.
  auto& dp = *dp_;
  fixed_.assign(nodes, 0);
  for (std::size_t i = 0; i < nodes; ++i)  // free nodes keep the last increment: the warm start
    if (node_mass_[i] <= 0) {
      fixed_[i] = 1;
      dp[i] = 0.0;
    }
  for (const auto& bc : pressure_bcs_) {
    const auto target = boundary_pressures(bc, time_ + dt_);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
      dp[bc.nodes[j]] = target[j] - (*p_)[bc.nodes[j]];
      fixed_[bc.nodes[j]] = 1;
    }
  }
  if (cavitation_) {
    values_free_ = values_;
    rhs_free_ = rhs_;
  }
  eliminate_rows(fixed_);
}

void HydraulicPhysics::eliminate_rows(const std::vector<char>& held) {
  const auto& dp = *dp_;
  for (std::size_t i = 0; i < held.size(); ++i) {
    if (!held[i]) continue;
    for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(graph_.columns[e]);
      if (j == i) continue;
      const std::size_t ji = graph_.transpose[e];
      if (!held[j]) rhs_[j] -= values_[ji] * dp[i];
      values_[ji] = 0.0;
      values_[e] = 0.0;
    }
    values_[graph_.diagonal[i]] = 1.0;
    rhs_[i] = dp[i];
  }
}

/// The skeleton's part of the projection, exact for its lumped nodal correction. The mass balance
/// depends on the skeleton's nodal velocity through Q_ij = Σ_p V_p [S_ip ∇S_jp + (n_l ξ)_p ∇S_ip S_jp]
/// (its volume change, strong form, and the relative flux the drag leaves it); the mechanical
/// physics corrects the skeleton by (m_j + Δt D_j) Δv_j = Δt Σ_i Q_ij Δp_i — the weak form of the
/// mixture's pressure force plus the liquid's share — with its lumped mobility 1/(m_j + Δt D_j)
/// (0 where a velocity condition holds a component). So the pressure equation gains
/// Δt Q M⁻¹ Qᵀ: symmetric, and wider than the particle Laplacian (two stencils).
void HydraulicPhysics::assemble_skeleton() {
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  const auto share = liquid_share_.values();
  const auto mobility = node_solid_mobility_.values();
  const int K = st.per_particle();
  const std::size_t nodes = node_mass_.size();
  // Q in the particle-stencil pattern (compact_), Dim values per entry.
  coupling_.resize(compact_.nonzeros() * kDim);
  coupling_transposed_.resize(compact_.nonzeros() * kDim);  // every entry written below
  parallel_for(coupling_.size(), [&](std::size_t e) { coupling_[e] = 0.0; });
  double* coupling = coupling_.data();
  const auto& transfer = kernel_->transfer();
  constexpr int kWidest = kDim == 2 ? 16 : 64;  // cubic B-splines
  for_support<kDim>(K, [&](auto support) {
    // A fixed support (GIMP) unrolls; the contributions are formed first and then added, so that
    // the arithmetic is not held up by stores that might alias its inputs (as the mechanical scatters).
    transfer.scatter([&](std::size_t q) {
      const auto* w = st.weights(q);
      const auto* g = st.gradients(q);
      const int* slot = compact_.scatter.data() + q * support * support;
      double c[kWidest * kWidest * kDim];
      for (int a = 0; a < support; ++a)
        for (int b = 0; b < support; ++b)
          for (int d = 0; d < kDim; ++d)
            c[(a * support + b) * kDim + d] = vol[q] * (w[a] * g[b * kDim + d] + share[q] * g[a * kDim + d] * w[b]);
      for (int ab = 0; ab < support * support; ++ab)
        for (int d = 0; d < kDim; ++d) coupling[std::size_t(slot[ab]) * kDim + d] += c[ab * kDim + d];
    });
  });
  // Qᵀ in the same (structurally symmetric) pattern: row j holds Q_kj at column k.
  parallel_for(nodes, [&](std::size_t j) {
    for (std::size_t f = compact_.offsets[j]; f < compact_.offsets[j + 1]; ++f) {
      const std::size_t e = compact_.transpose[f];
      for (int d = 0; d < kDim; ++d) coupling_transposed_[f * kDim + d] = coupling_[e * kDim + d];
    }
  });
  // A_ik += Δt Σ_j Σ_d Q_ij,d M_jd⁻¹ Q_kj,d, row by row (each row its own: no race, any thread
  // count), with the row's columns found through a per-thread map from node to CSR position.
  // Nodes of a rigid plate move as one: their tied component is one column, Σ_j∈plate Q_ij,axis.
  const auto group = node_solid_group_.bound() ? node_solid_group_.values() : std::span<const double>{};
  auto tied = [&](std::size_t j, int d) { return !group.empty() && group[j] > 0 && int(group[j] - 1) % kDim == d; };
#pragma omp parallel if (nodes >= kParallelMinimum)
  {
    std::vector<std::size_t> slot_of(nodes, 0);
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < nodes; ++i) {
      for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e) slot_of[std::size_t(graph_.columns[e])] = e;
      for (std::size_t e = compact_.offsets[i]; e < compact_.offsets[i + 1]; ++e) {
        const auto j = static_cast<std::size_t>(compact_.columns[e]);
        double a[kDim];
        bool any = false;
        for (int d = 0; d < kDim; ++d) {
          a[d] = tied(j, d) ? 0.0 : dt_ * coupling_[e * kDim + d] * mobility[j * kDim + d];
          any = any || a[d] != 0;
        }
        if (!any) continue;
        for (std::size_t f = compact_.offsets[j]; f < compact_.offsets[j + 1]; ++f) {
          double sum = 0;
          for (int d = 0; d < kDim; ++d) sum += a[d] * coupling_transposed_[f * kDim + d];
          values_[slot_of[std::size_t(compact_.columns[f])]] += sum;
        }
      }
    }
  }
  if (plates_.empty()) return;
  // The plates: Q_g,i = Σ_{j ∈ g} Q_ij,axis over the rows that touch them; A += Δt Q_g Q_gᵀ / M_g,
  // group by group in ascending order, each Q_g,i summed over j and then over row j's entries.
  plate_column_.assign(nodes, 0.0);
  plate_touched_.assign(nodes, 0);
  slot_of_.resize(nodes);
  for (const auto& [g, plate_nodes] : plates_) {
    const int d = (g - 1) % kDim;
    double plate_mobility = 0;
    std::vector<std::size_t> rows;
    for (const std::size_t j : plate_nodes) {
      plate_mobility = mobility[j * kDim + d];  // the same on every node of the plate
      for (std::size_t f = compact_.offsets[j]; f < compact_.offsets[j + 1]; ++f) {
        const auto k = std::size_t(compact_.columns[f]);
        if (!plate_touched_[k]) rows.push_back(k);
        plate_touched_[k] = 1;
        plate_column_[k] += coupling_transposed_[f * kDim + d];  // Q_kj,d
      }
    }
    std::sort(rows.begin(), rows.end());
    const double factor = dt_ * plate_mobility;
    for (const std::size_t i : rows) {
      for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e) slot_of_[std::size_t(graph_.columns[e])] = e;
      for (const std::size_t k : rows) {
        const std::size_t e = slot_of_[k];  // stale unless row i holds column k
        if (e < graph_.offsets[i] || e >= graph_.offsets[i + 1] || std::size_t(graph_.columns[e]) != k)
          throw std::logic_error("pressure graph: rows " + std::to_string(i) + " and " + std::to_string(k) +
                                 " of a rigid plate are not coupled in the graph built at the start");
        values_[e] += factor * plate_column_[i] * plate_column_[k];
      }
    }
    for (const std::size_t k : rows) {
      plate_column_[k] = 0.0;
      plate_touched_[k] = 0;
    }
  }
}

/// This step's rigid plates (read from the node field the mechanical physics writes): each
/// group's number and its nodes, both ascending.
void HydraulicPhysics::find_plates() {
  plates_.clear();
  if (!coupled_ || !node_solid_group_.bound()) return;
  const auto group = node_solid_group_.values();
  std::map<int, std::vector<std::size_t>> by_group;
  for (std::size_t j = 0; j < group.size(); ++j)
    if (group[j] > 0) by_group[int(group[j])].push_back(j);
  plates_.assign(by_group.begin(), by_group.end());
}

/// For each rigid plate (find_plates()), the rows its nodes' columns of Q can reach, ascending:
/// the graph must couple all of them with each other.
std::vector<std::vector<std::size_t>> HydraulicPhysics::group_rows() const {
  std::vector<std::vector<std::size_t>> out;
  const auto& grid = kernel_->grid();
  const int reach = support_width(kernel_->transfer().stencil().kind()) - 1;
  // A row i touches plate node j when some particle's stencil could hold both: within `reach`
  // lattice steps along each axis.
  for (const auto& [_, plate_nodes] : plates_) {
    std::vector<std::size_t> rows;
    for (const std::size_t j : plate_nodes) {
      const auto ijk = grid.node_lattice(j);
      std::array<int, kDim> at{};
      for (at[1] = ijk[1] - reach; at[1] <= ijk[1] + reach; ++at[1])
        for (at[0] = ijk[0] - reach; at[0] <= ijk[0] + reach; ++at[0]) {
          bool inside = true;
          std::array<int, kDim> wrapped{};
          for (int d = 0; d < kDim; ++d) {
            wrapped[d] = grid.wrap(d, at[d]);
            inside = inside && wrapped[d] >= -grid.ghost_layers && wrapped[d] <= grid.cells[d] + grid.ghost_layers;
          }
          if (inside) rows.push_back(grid.node_index(wrapped));
        }
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    out.push_back(std::move(rows));
  }
  return out;
}

namespace {
/// ∫ (S − ΠS)ᵀ(S − ΠS) dA of a bilinear cell of area A, in units of A / 144, nodes counter-
/// clockwise: the consistent mass A/36 (4 2 1 2) minus the cell average (A/16 everywhere).
// Integrated exactly per cell, not at the particles: at a cell's centre (one particle per
// cell) a checkerboard mode has S − ΠS = 0 and would escape the projection.
constexpr double kProjection[4][4] = {{7, -1, -5, -1}, {-1, 7, -1, -5}, {-5, -1, 7, -1}, {-1, -5, -1, 7}};

/// The four nodes of cell `c`, counter-clockwise from the lower left.
std::array<std::size_t, 4> cell_nodes(const UniformGrid<kDim>& grid, std::size_t c) {
  const int i = static_cast<int>(c % static_cast<std::size_t>(grid.cells[0]));
  const int j = static_cast<int>(c / static_cast<std::size_t>(grid.cells[0]));
  const int right = grid.wrap(0, i + 1), top = grid.wrap(1, j + 1);  // a periodic grid's last cell closes on its first nodes
  return {grid.node_index({i, j}), grid.node_index({right, j}), grid.node_index({right, top}), grid.node_index({i, top})};
}
}  // namespace

/// H = Σ_cells τ/(2G) ∫ (S − ΠS)ᵀ(S − ΠS) dV (Eq. 67), each cell weighted by the volume of its
/// particles (a cell the material half fills gets half), added as H / Δt: the paper's
/// H_stab (p^{k+1} − p^k) read as a rate, like M33 — τ/(2G) is a compressibility, so only
/// H Δp/Δt has the units of the other terms (docs/architecture.md).
void HydraulicPhysics::add_stabilization() {
  const auto& grid = kernel_->grid();
  // G of a constitutive model changes with the ice: then every step.
  if (stabilization_version_ != kernel_->transfer().version() || shear_modulus_.bound()) update_cell_stabilization();
  // Each cell's 16 entries found once per graph (a cell's slots are looked up when it first takes
  // the projection: an empty cell's node pairs need not be in the pattern).
  constexpr std::size_t kUnknown = ~std::size_t{0};
  if (stabilization_slots_graph_ != graph_builds_) {
    stabilization_slots_.assign(cell_stabilization_.size() * 16, kUnknown);
    stabilization_slots_graph_ = graph_builds_;
  }
  for (std::size_t c = 0; c < cell_stabilization_.size(); ++c) {
    const double w = cell_stabilization_[c] / (144.0 * dt_);
    if (w == 0) continue;
    std::size_t* slot = stabilization_slots_.data() + 16 * c;
    if (slot[0] == kUnknown) {
      const auto n = cell_nodes(grid, c);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) slot[4 * a + b] = graph_.position(n[a], static_cast<int>(n[b]));
    }
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) values_[slot[4 * a + b]] += w * kProjection[a][b];
  }
}

/// Σ V_p τ/(2G_p) of the particles in each cell: changes only when particles move.
///
/// Only cells the material fills to at least kProjectionMinimumFill (by particle volume) take the
/// projection. The exact bilinear integral spans the whole cell; in a cell at a free surface
/// holding one particle of four it couples, as strongly as the particle's volume allows, nodes
/// the material barely reaches and whose other coefficients are tiny. There it excited a local
/// mode that grew by about 15 % a step (rock freezing on 1 cm cells: the cell at the borehole
/// wall with one particle, frozen, its pore pressure running to −760 MPa in 30 steps). Since
/// nodes the material only grazes carry no unknown (map_to_grid()), that run holds without the rule
/// too (15 h on 1 cm cells; p_A at 15 h 513 kPa without it, 570 kPa with it; at 5 mm and 2 h
/// 257 against 268 kPa, T_A within 3e-4 K): it stays because a cell so sparsely filled has no
/// checkerboard of its own to suppress, not for stability.
void HydraulicPhysics::update_cell_stabilization() {
  constexpr double kProjectionMinimumFill = 0.4;
  const auto& grid = kernel_->grid();
  const auto x = position_.values();
  const auto vol = volume_.values();
  std::fill(cell_stabilization_.begin(), cell_stabilization_.end(), 0.0);
  std::vector<double> fill(cell_stabilization_.size(), 0.0);
  const auto G = shear_modulus_.bound() ? shear_modulus_.values() : std::span<const double>{};
  const double tau = params_.real("stabilization");
  for (std::size_t q = 0; q < vol.size(); ++q) {
    const std::size_t c = grid.cell_of(x.data() + q * kDim);
    fill[c] += vol[q];  // every particle fills its cell, whether or not it adds to H
    cell_stabilization_[c] +=
        vol[q] * (G.empty() ? materials_[material_[q]].stabilization : G[q] > 0 ? tau / (2.0 * G[q]) : 0.0);
  }
  for (std::size_t c = 0; c < fill.size(); ++c)
    if (fill[c] < kProjectionMinimumFill * grid.cell_volume()) cell_stabilization_[c] = 0;
  stabilization_version_ = kernel_->transfer().version();
}

/// The water that entered in this step: on each pressure-boundary node the residual of its
/// unconstrained mass-balance row, r_i = (A Δp − b)_i = ((M + H) Δp / Δt + s − Σ_p V_p ∇S_ip · q_p
/// − q̂)_i (the corrector makes K Δp exactly the change of Σ V n ∇S · v), plus the prescribed
/// fluxes. Rows saved before the elimination: no particle pass.
void HydraulicPhysics::account_boundary_inflow() {
  const auto& dp = *dp_;
  double inflow = 0;
  std::size_t at = 0;
  for (std::size_t k = 0; k < pressure_nodes_.size(); ++k) {
    const std::size_t i = pressure_nodes_[k];
    double residual = -boundary_rhs_[k];
    for (std::size_t e = graph_.offsets[i]; e < graph_.offsets[i + 1]; ++e)
      residual += boundary_rows_[at++] * dp[static_cast<std::size_t>(graph_.columns[e])];
    inflow += residual;
  }
  for (const auto& bc : flux_bcs_) inflow += bc.applied;
  boundary_inflow_ += dt_ * inflow;
}

void HydraulicPhysics::solve_pressure() {
  assemble();
  // With vapour from earlier steps, the first solve already holds its nodes (limit_to_cavitation).
  const bool vapour = cavitation_ && gather_vapour();
  // The matrix changes every step a thermal physics moves the ice, but only near the front:
  // the preconditioner of an earlier step stays good for a while. A refresh (new values on the
  // kept aggregates) costs about two CG iterations (9 % frozen inclusion: 19 ms against 8.7 ms an
  // iteration at 0.01 m, 4.3 against 2.0 ms at 0.02 m), so it is due as soon as a step needs more
  // than two iterations over the count right after the last refresh (and built on a new graph).
  if (!vapour)
    solve_system(!preconditioner_built_ ? PreconditionerUpdate::Rebuild
                 : refresh_due_         ? PreconditionerUpdate::Refresh
                                        : PreconditionerUpdate::Reuse);
  if (cavitation_) limit_to_cavitation(vapour);
}

void HydraulicPhysics::solve_system(PreconditionerUpdate update, double tolerance) {
  system_->set_values(values_);
  const auto start = std::chrono::steady_clock::now();
  const SolveStats stats = system_->solve(rhs_, *dp_, update, tolerance);
  solve_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  preconditioner_seconds_ += stats.setup_seconds;
  ++solves_;
  step_iterations_.push_back(stats.iterations);
  step_residuals_.push_back(stats.relative_residual);
  if (update != PreconditionerUpdate::Reuse) {
    iterations_after_refresh_ = stats.iterations;
    ++preconditioner_updates_;
    preconditioner_built_ = true;
  }
  refresh_due_ = stats.iterations > iterations_after_refresh_ + 2;
  iterations_total_ += stats.iterations;
  iterations_max_ = std::max<long>(iterations_max_, stats.iterations);
  residual_max_ = std::max(residual_max_, stats.relative_residual);
  if (!stats.converged || !std::isfinite(stats.relative_residual)) {
    std::ostringstream msg;
    msg << "pressure solve did not converge at t = " << time_ << " s (step " << kernel_->step() << ", dt = " << dt_
        << " s): relative residual " << stats.relative_residual << " after " << stats.iterations
        << " " << params_.string("solver") << " iterations (physics.hydraulic.linear_tolerance " << params_.real("linear_tolerance")
        << ", max_linear_iterations " << params_.integer("max_linear_iterations")
        << "); raise max_linear_iterations, try another preconditioner or a smaller time.dt";
    throw NumericalBlowUp(msg.str());
  }
}

double HydraulicPhysics::unconstrained_residual(std::size_t i) const {
  return row_dot(values_free_.data(), graph_.columns.data(), graph_.offsets[i], graph_.offsets[i + 1], dp_->data()) -
         rhs_free_[i];
}

bool HydraulicPhysics::gather_vapour() {
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  const auto f = vapour_.values();
  const std::size_t nodes = fixed_.size();
  node_vapour_.assign(nodes, 0.0);
  vapour_weight_.assign(nodes, 0.0);
  const int K = st.per_particle();
  // Each particle's vapour (a volume: the skeleton's own volume change is the pressure
  // equation's, so it must not scale with V) onto its free nodes only, by weight: a fixed node
  // (a pressure boundary, a dry or empty node) has no balance to hold it. The free nodes next to
  // a drained boundary then draw its water in through the flow, counted as inflow there.
  kernel_->transfer().scatter([&](std::size_t q) {
    const auto* n = st.nodes(q);
    const auto* w = st.weights(q);
    double on_free = 0;
    for (int k = 0; k < K; ++k) on_free += fixed_[n[k]] ? 0.0 : w[k];
    for (int k = 0; k < K; ++k) {
      if (fixed_[n[k]]) continue;
      if (f[q] > 0) node_vapour_[n[k]] += f[q] * w[k] / on_free;
      vapour_weight_[n[k]] += w[k] * vol[q];
    }
  });
  bool any = false;
  for (std::size_t i = 0; i < nodes && !any; ++i) any = node_vapour_[i] > 0;
  return any;
}

/// The pore water cannot take a pressure below the cavitation pressure p_c; below it, vapour
/// fills the pores the water cannot. Per node, with V_i the vapour of the step's start and
/// r_i = (A Δp − b)_i the water the node takes in (its unconstrained row): either the node is
/// free, p_i ≥ p_c, and its water fills the vapour (r_i = −V_i/Δt), or it is held at p_c and
/// keeps V_i + Δt r_i ≥ 0 of vapour — a complementarity problem, solved by a primal–dual active
/// set: free nodes below p_c are held, held nodes whose vapour would be used up are let go, and
/// the system is solved again, until nothing changes. Releases stop after kReleaseRounds
/// checks, so the set only grows from then on and the loop ends; a held node whose vapour is
/// then overdrawn is counted (hydraulic.cavitation_unresolved_volume). Without vapour and with no
/// node below p_c, the first solve stands.
void HydraulicPhysics::limit_to_cavitation(bool vapour) {
  constexpr int kReleaseRounds = 8;
  const std::size_t nodes = fixed_.size();
  const auto& p = *p_;
  auto& dp = *dp_;
  // Below by more than the solve's round-off (a released node may land a hair under p_c).
  const double margin = 1e-9 * std::max(std::abs(cavitation_pressure_), 1.0);
  // Nodes with vapour that are at the limit start held (free, one would have to draw its
  // vapour's volume of water through frozen ground within the step: a first solve far from the
  // answer); vapour a node above the limit received from its particles is filled if it can be.
  std::vector<char> held(nodes, 0);
  for (std::size_t i = 0; i < nodes; ++i) held[i] = node_vapour_[i] > 0 && p[i] <= cavitation_pressure_ + margin;
  const double tolerance = params_.real("linear_tolerance");
  for (int round = 0, checks = 0;; ++round) {
    bool changed = vapour && round == 0;  // the first solve is still to come
    if (!changed) {
      for (std::size_t i = 0; i < nodes; ++i) {
        if (fixed_[i]) continue;
        if (!held[i] && p[i] + dp[i] < cavitation_pressure_ - margin) {
          held[i] = 1;
          changed = true;
        } else if (held[i] && checks < kReleaseRounds && node_vapour_[i] + dt_ * unconstrained_residual(i) < 0) {
          held[i] = 0;
          changed = true;
        }
      }
      ++checks;
    }
    if (!changed) break;
    values_ = values_free_;
    rhs_ = rhs_free_;
    for (std::size_t i = 0; i < nodes; ++i)
      if (node_vapour_[i] > 0) rhs_[i] -= node_vapour_[i] / dt_;  // a free node's water fills its vapour
    std::vector<char> rows(fixed_);
    for (std::size_t i = 0; i < nodes; ++i)
      if (held[i]) {
        rows[i] = 1;
        dp[i] = cavitation_pressure_ - p[i];
      }
    eliminate_rows(rows);
    // Solved for the correction to the Δp just set, to the tolerance relative to the free rows'
    // right-hand side: the held rows' (their jumps to p_c, in Pa) would otherwise dominate |b|
    // and leave the free rows' water balance unsolved. Their correction is zero.
    double free_norm2 = 0, start_norm2 = 0;
    for (std::size_t i = 0; i < nodes; ++i)
      if (!rows[i]) free_norm2 += rhs_[i] * rhs_[i];
    const std::vector<double> start(dp);
    parallel_for(nodes, [&](std::size_t i) {
      rhs_[i] -= row_dot(values_.data(), graph_.columns.data(), graph_.offsets[i], graph_.offsets[i + 1], start.data());
    });
    for (std::size_t i = 0; i < nodes; ++i) start_norm2 += rhs_[i] * rhs_[i];
    std::fill(dp.begin(), dp.end(), 0.0);
    // Not below 1e-13: a correction far smaller than the free rows' balance meets round-off first.
    const double relative = start_norm2 > 0 ? std::clamp(tolerance * std::sqrt(free_norm2 / start_norm2), 1e-13, 0.1)
                                            : tolerance;
    solve_system(preconditioner_built_ ? PreconditionerUpdate::Refresh : PreconditionerUpdate::Rebuild, relative);
    for (std::size_t i = 0; i < nodes; ++i) dp[i] += start[i];
    refresh_due_ = true;  // the next step's matrix is the unconstrained one again
  }
  // The vapour at the step's end: what the held nodes keep; free nodes' water filled theirs.
  double total = 0, overdrawn = 0;
  long count = 0;
  for (std::size_t i = 0; i < nodes; ++i) {
    const double kept = held[i] ? node_vapour_[i] + dt_ * unconstrained_residual(i) : 0.0;
    overdrawn += std::min(kept, 0.0);
    node_vapour_[i] = std::max(kept, 0.0);
    total += node_vapour_[i];
    count += held[i];
  }
  cavitated_volume_ = total;
  unresolved_volume_ -= overdrawn;
  cavitated_nodes_max_ = std::max(cavitated_nodes_max_, count);
  // Back to the particles in proportion to S_ip V_p, so that their vapour sums to the nodes'.
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  auto f = vapour_.mutable_values();
  const int K = st.per_particle();
  parallel_for(f.size(), [&](std::size_t q) {
    const auto* n = st.nodes(q);
    const auto* w = st.weights(q);
    double share = 0;
    for (int k = 0; k < K; ++k)
      if (vapour_weight_[n[k]] > 0) share += w[k] * vol[q] * node_vapour_[n[k]] / vapour_weight_[n[k]];
    f[q] = share;
  });
}

}  // namespace frostmpm::hydraulic
