#pragma once
// Pore-water flow through a fixed solid skeleton (paper Sec. 2.2–2.3, 4.1–4.3, Eqs. 14, 43–48,
// 53–57, 61–63), by the fractional-step (pressure projection) method. Theory-to-code map:
// docs/theory.md; design decisions: docs/architecture.md.
//
// Fixed solid (v_s ≡ 0, the paper's thermo-hydraulic examples): the corrector gives
// ξ = n_l ρ_l / (n_l ρ_l + Δt C_d), η = ξ n_l / ρ_l, the ρ_s → ∞ limit of Eqs. 46 and 49, with
// the drag coefficient C_d = n_l² ρ_l g_ref / (K k_r) (K the hydraulic conductivity, g_ref the
// gravity it is defined with). Per step:
//   map_to_grid   per-particle coefficients; the nodal pressure is carried between steps while
//                 particles stand still (re-projected from the particles when they move);
//   predict       at every material point v* = (n_l ρ_l (v + Δt b) − Δt n_l ∇p(x_p)) /
//                 (n_l ρ_l + Δt C_d) (Eq. 43 with the gradient form of the pressure force, Eq. 14);
//   pressure      (M/Δt + K) Δp = Σ_p V_p n_l ∇S_ip · v*_p + ∫ S_i q̂ dS, M lumped
//                 Σ_p V_p n_l c_w S_ip, K = Σ_p V_p Δt η ∇S_ip·∇S_jp (Eq. 56), Δp prescribed on
//                 pressure boundaries; CG through SparseSystem, the graph kept while the
//                 stencil is unchanged, the preconditioner refreshed only when values change;
//   correct       v_p = v*_p − Δt (ξ_p / ρ_l) ∇Δp(x_p) (Eq. 47), q_p = n_l v_p; p_i += Δp_i;
//   map_to_particles  particle pressure interpolated from the nodes.
// The momentum steps run at the material points, the quadrature points of the pressure
// equation, so K is exactly the operator the corrector applies: mass balances in every step
// (docs/architecture.md, "Pore-water flow").
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "frostmpm/linalg/sparse_system.hpp"
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/scene/time_function.hpp"
#include "frostmpm/physics/kernel.hpp"
#include "frostmpm/transfer/gradient_gram.hpp"
#include "frostmpm/transfer/stencil_graph.hpp"

namespace frostmpm::hydraulic {

/// The hydraulic physics runs in 2-D (plane).
inline constexpr int kDim = 2;

class HydraulicPhysics final : public Physics {
 public:
  static constexpr const char* kName = "hydraulic";
  static constexpr const char* kDoc = "pore-water flow through a fixed skeleton (fractional-step pressure projection)";

  static ParamSchema schema();
  explicit HydraulicPhysics(const ParamSet& p);

  ParamSchema material_schema() const override;
  std::vector<ModelSlot> material_models() const override {
    return {{"absolute_permeability", AbsolutePermeabilityModel::kKind, true},
            {"relative_permeability", RelativePermeabilityModel::kKind, false}};
  }
  static std::vector<BoundaryType> boundary_type_docs();
  std::vector<std::string> boundary_types() const override { return boundary_type_names(boundary_type_docs()); }

  void setup(Kernel<kDim>& kernel) override;
  std::vector<Stage> stages() override;
  void initialize() override;
  void begin_step(double time, double dt) override;
  std::vector<PersistentArray> persistent_state() override;
  void restored() override;
  void checkpoint_written() override;
  std::vector<std::pair<std::string, double>> statistics() const override;
  void removing_particles(const ParticleRemoval& removal) override;
  std::vector<std::pair<std::string, const std::vector<double>*>> step_series() const override {
    return {{"hydraulic.linear_iterations", &step_iterations_}, {"hydraulic.relative_residual", &step_residuals_}};
  }

 private:
  struct PressureCondition {
    std::vector<std::size_t> nodes;      ///< on particles: the nodes they make up at least half of
    std::vector<std::size_t> particles;  ///< a condition on particles (a surface inside the grid)
    TimeFunction value;     ///< pressure [Pa], or the water-table elevation [m] when hydrostatic
    bool hydrostatic = false;
    std::string label;
  };
  struct FluxCondition {
    std::vector<std::size_t> nodes;
    std::vector<double> areas;
    TimeFunction value;  ///< inflow Darcy flux [m/s]
    std::string label;
    double applied = 0;  ///< inflow rate of the current step [m³/s per m]
  };
  struct MaterialModels {
    std::shared_ptr<AbsolutePermeabilityModel> absolute;
    std::shared_ptr<RelativePermeabilityModel> relative;  ///< none: k_r = 1
    double water_density = 1000, compressibility = 0;
    double zeta = 0;                                   ///< 1 − ρ_c/ρ_l: water volume lost per unit of ice melted
    double solid_expansion = 0, water_expansion = 0, ice_expansion = 0;  ///< β_s, β_l, β_c [1/K]
    double stabilization = 0;                          ///< τ / (2G); 0 for a rigid skeleton (G → ∞)
  };

  // ---- configuration
  ParamSet params_;
  Kernel<kDim>* kernel_ = nullptr;
  std::array<double, kDim> gravity_{};
  // The fields the stages declare (bound by the kernel once the step is resolved).
  FieldHandle position_ = FieldHandle::particle("position", kDim, FieldKind::Vector);
  FieldHandle volume_ = FieldHandle::particle("volume");
  FieldHandle porosity_ = FieldHandle::particle("porosity");
  FieldHandle saturation_ = FieldHandle::particle("liquid_saturation");
  FieldHandle temperature_field_ = FieldHandle::particle("temperature");
  FieldHandle pressure_ = FieldHandle::particle("pore_pressure");
  FieldHandle velocity_ = FieldHandle::particle("liquid_velocity", kDim, FieldKind::Vector);
  FieldHandle predicted_ = FieldHandle::particle("liquid_velocity_predicted", kDim, FieldKind::Vector);
  FieldHandle flux_ = FieldHandle::particle("water_flux", kDim, FieldKind::Vector);
  FieldHandle node_pressure_ = FieldHandle::node("pore_pressure");
  FieldHandle node_increment_ = FieldHandle::node("pressure_increment");
  // Coupling with a moving skeleton (a mechanical physics): what it provides and what the
  // liquid hands back (models/two_phase.hpp)
  FieldHandle skeleton_inertia_ = FieldHandle::particle("skeleton_inertia");
  FieldHandle node_solid_predicted_ = FieldHandle::node("solid_velocity_predicted", kDim);
  FieldHandle node_solid_velocity_ = FieldHandle::node("solid_velocity", kDim);
  /// The same node field as read in map_to_grid: the skeleton's velocity at the step's start.
  FieldHandle node_solid_start_ = FieldHandle::node("solid_velocity", kDim);
  FieldHandle node_solid_mobility_ = FieldHandle::node("solid_mobility", kDim);
  FieldHandle node_solid_group_ = FieldHandle::node("solid_group");  ///< nodes moving as one body (rigid plates)
  FieldHandle shear_modulus_ = FieldHandle::particle("shear_modulus");  ///< G of the skeleton's model, when it has one
  // Created by the drag stage, which runs only with a moving skeleton: the units are given here.
  FieldHandle liquid_drag_ = FieldHandle::particle("liquid_drag", 1, FieldKind::Scalar, "kg/(m^3 s)");
  FieldHandle liquid_reaction_ = FieldHandle::particle("liquid_reaction", kDim, FieldKind::Vector, "N/m^3");
  FieldHandle liquid_share_ = FieldHandle::particle("liquid_pressure_share", 1, FieldKind::Scalar, "1");
  /// With a cavitation limit: the vapour in each particle's pores, a volume like the particle's
  /// (written by the pressure stage; carried, checkpointed and compacted as particle state).
  FieldHandle vapour_ = FieldHandle::particle("vapour_volume", 1, FieldKind::Scalar, "m^3/m");
  bool coupled_ = false;   ///< a skeleton that moves: the two-phase fractional step
  bool moving_ = false;    ///< particles move: the pressure state lives on the particles (FLIP)
  double mass_scaling_ = 1;
  double transport_scaling_ = 1;  ///< time.transport_scaling: the factor on every permeability
  bool phase_change_source_ = true;
  bool cavitation_ = false;          ///< physics.hydraulic.cavitation_pressure given
  double cavitation_pressure_ = 0;   ///< the lowest pore pressure the water takes [Pa]
  double reference_gravity_ = 9.81;
  double hydrostatic_density_ = 1000;  ///< ρ_l of a hydrostatic boundary (the scene's one water density)
  std::vector<MaterialModels> materials_;
  std::vector<PressureCondition> pressure_bcs_;
  std::vector<FluxCondition> flux_bcs_;

  // ---- particles: per-step coefficients
  std::span<const std::uint16_t> material_;  ///< material index of every particle (the kernel's)
  std::vector<double> n_l_, drag_, xi_, eta_, storage_, k_a_, k_r_, scratch_;
  std::vector<double> mobility_;  ///< n_l / (m_l + Δt C_d): the liquid's own velocity change per Δt ∇Δp
  // Coupled: Q, the mass balance's dependence on the skeleton's nodal velocity (Dim values per
  // entry of the graph), and its transpose; the pressure matrix holds Δt Q M⁻¹ Qᵀ
  std::vector<double> coupling_, coupling_transposed_;
  std::vector<std::pair<int, std::vector<std::size_t>>> plates_;  ///< this step's rigid plates: group number, nodes (find_plates())
  // assemble_skeleton()'s scratch for the rigid plates: Q_g by row, rows already met, and the
  // CSR position of each column of the row being added to
  std::vector<double> plate_column_;
  std::vector<char> plate_touched_;
  std::vector<std::size_t> slot_of_;
  std::vector<double> was_active_;  ///< moving particles: nodes the material covered last step (1/0)
  // Volume source of the mass balance, (ζ φ ∂S_l/∂T − β_m) Ṫ (Eq. 48), from the change of S_l
  // and T over the last completed step (kept per particle: S_prev_, T_prev_)
  std::vector<double> source_, S_prev_, T_prev_;
  // The projection's matrix counts the skeleton's correction Δv_s with the weight 1 (Δt Q M⁻¹ Qᵀ,
  // symmetric: the pressure pushes the skeleton with its whole increment), where the mass balance
  // weighs ∇·v_s by 1 − ζ S_c (1 − ζ n_c without the phase change's volume). So each step leaves
  // the volume −ζ S_c V ∇·Δv_s Δt out of its balance: ice_weight_ = V ζ S_c (this step),
  // melt_carried_ the volume left out last step, added to this step's balance so that no water
  // goes missing over a run (one step late).
  std::vector<double> ice_weight_, melt_carried_;
  /// Every array above with one value per particle (sized at setup, compacted on removal).
  std::array<std::vector<double>*, 14> per_particle_arrays() {
    return {&n_l_,    &drag_,   &xi_,     &eta_,     &storage_,  &k_a_,        &k_r_,
            &scratch_, &source_, &S_prev_, &T_prev_, &mobility_, &ice_weight_, &melt_carried_};
  }
  bool primed_ = false;        ///< S_prev_ and T_prev_ hold a step's start
  bool temperature_ = false;   ///< a thermal physics provides the particle temperature

  // ---- grid (the kernel's node fields pore_pressure and pressure_increment) and the lumped
  // liquid mass (a node no wet particle touches has none and no pressure unknown)
  std::vector<double>*p_ = nullptr, *dp_ = nullptr;
  std::vector<double> node_mass_, rhs_;
  std::vector<double> node_storage_;  ///< Σ_p S_ip V_p n_l c_w / Δt, the lumped storage of this step
  // Polynomial pressure projection (Eqs. 66–67): per grid cell, ∫ τ/(2G) over its material
  std::vector<double> cell_stabilization_;
  std::uint64_t stabilization_version_ = ~std::uint64_t{0};  ///< stencil the cell weights belong to (none yet)
  bool stabilized_ = false;
  std::uint64_t graph_builds_ = 0;  ///< counts the pressure graph's builds (when its positions change)
  /// Each cell's 16 CSR positions of the projection in graph_ (build graph_builds_ at the time).
  std::vector<std::size_t> stabilization_slots_;
  std::uint64_t stabilization_slots_graph_ = ~std::uint64_t{0};
  // The pressure-boundary nodes (each once) and their rows as assembled, before the elimination
  std::vector<std::size_t> pressure_nodes_;
  std::vector<double> condition_share_;  ///< scratch of update_pressure_nodes
  std::vector<double> boundary_rows_, boundary_rhs_;
  std::uint64_t projected_version_ = 0;  ///< stencil the nodal state belongs to
  bool grid_valid_ = false;

  // ---- pressure system
  StencilGraph graph_;
  GradientGram<kDim> mobility_gram_;  ///< Σ_p V_p η_p ∇S_ip·∇S_jp in graph_ (the Darcy term over Δt)
  StencilGraph compact_;  ///< coupled: the particle-stencil pattern of Q (graph_ is its square)
  std::unique_ptr<SparseSystem> system_;
  std::vector<double> values_;
  std::vector<char> fixed_;  ///< rows whose Δp is prescribed (pressure boundaries, dry or empty nodes)
  // With a cavitation limit: the system before the elimination, from which the rows of the nodes
  // that cavitate are eliminated in turn (limit_to_cavitation())
  std::vector<double> values_free_, rhs_free_;
  std::vector<double> node_vapour_;  ///< vapour volume at each free node at the step's start (the particles', by weight)
  std::vector<double> vapour_weight_;  ///< Σ_p S_ip V_p: how a node's vapour goes back to its particles
  bool preconditioner_built_ = false;  ///< for the current system
  long iterations_after_refresh_ = 0, preconditioner_updates_ = 0;
  bool refresh_due_ = false;           ///< the iteration count grew by more than 2 since the last update
  /// The rigid plates' rows the coupled graph was built with (group_rows() at the time).
  std::vector<std::vector<std::size_t>> graph_groups_;
  // The solver's state in a checkpoint: the graph's plate rows (flattened: count, then each
  // group's size and rows) and the values the preconditioner was built and refreshed from. A
  // restart builds the same system and preconditioner with them (assemble()), so that it
  // continues bit for bit from any step.
  std::vector<double> saved_groups_;
  PreconditionerSource saved_source_;
  bool restore_system_ = false;  ///< restored(): assemble() rebuilds the system from the saved state

  // ---- step and counters
  double time_ = 0, dt_ = 0;
  long solves_ = 0, iterations_total_ = 0, iterations_max_ = 0;
  double residual_max_ = 0, solve_seconds_ = 0;
  double preconditioner_seconds_ = 0;  ///< of solve_seconds_: uploading values and building or refreshing the preconditioner
  double source_volume_ = 0;    ///< water volume the phase change and thermal expansion removed [m³ per m]
  double removed_water_ = 0;  ///< liquid water volume of the particles removed after leaving the grid
  double boundary_inflow_ = 0;  ///< water volume that entered through pressure and flux boundaries
  double cavitated_volume_ = 0;  ///< vapour volume in the pores at the end of the last step [m³ per m]
  long cavitated_nodes_max_ = 0;  ///< most nodes held at the cavitation pressure in one step
  double unresolved_volume_ = 0;  ///< vapour held nodes overdrew once releases had stopped (water made up)
  std::vector<double> saved_scalars_;
  std::vector<double> step_iterations_, step_residuals_;  ///< of every pressure solve, for run.json

  void read_boundaries(Kernel<kDim>& kernel);
  /// The condition's pressure on each of its nodes at time t; not finite stops the run.
  std::vector<double> boundary_pressures(const PressureCondition& c, double t) const;
  /// Nodal pressure = the boundary values at t on every pressure boundary.
  void set_boundary_pressures(double t);
  /// The nodes of pressure conditions on particles, from where the particles are now, and
  /// pressure_nodes_ (every condition's nodes, sorted) with them.
  void update_pressure_nodes(const std::vector<double>& node_volume);
  void update_coefficients();
  /// The volume source of every particle over the step that just ended; primes on the first call.
  void update_source();
  /// Adds (τ/2G) ∫ (S − ΠS)ᵀ(S − ΠS) dV / Δt of every cell with material to the matrix (Eq. 67).
  void add_stabilization();
  void update_cell_stabilization();
  /// Water that entered through the boundaries in this step: the residual of the mass balance
  /// on the nodes whose pressure is prescribed, plus the prescribed fluxes.
  void account_boundary_inflow();
  void project_to_grid();
  void project_particles(std::vector<double>& into) const;
  void advect_grid_pressure();
  void map_to_grid();
  void predict();
  /// Coupled: the drag stiffness C_d ξ, the reaction k ṽ − f_l and the share n_l ξ the skeleton needs.
  void drag();
  void solve_pressure();
  /// One solve of the system as it stands (values_, rhs_ into Δp), its counters and the stop on
  /// a solve that did not converge; `tolerance` > 0: this relative residual instead of linear_tolerance.
  void solve_system(PreconditionerUpdate update, double tolerance = 0.0);
  /// Replaces the rows and columns of the `held` nodes by the identity, their Δp (already set)
  /// moved to the right-hand side: A stays symmetric.
  void eliminate_rows(const std::vector<char>& held);
  /// The particles' vapour gathered on their free nodes; whether any node has some.
  bool gather_vapour();
  /// The cavitation limit: nodes whose pressure fell below it are held there and the system
  /// solved again, until every free node is at or above it and every held node keeps vapour;
  /// the nodes' new vapour goes back to the particles.
  /// `vapour`: nodes hold vapour from earlier steps, and no solve has been made yet.
  void limit_to_cavitation(bool vapour);
  /// (A Δp − b)_i of node i's unconstrained row: the water the node takes in, per unit time.
  double unconstrained_residual(std::size_t i) const;
  void correct();
  void map_to_particles();
  void assemble();
  /// Coupled: adds Δt Q M⁻¹ Qᵀ, the skeleton's exact response to the pressure increment.
  void assemble_skeleton();
  void find_plates();
  std::vector<std::vector<std::size_t>> group_rows() const;
};

}  // namespace frostmpm::hydraulic
