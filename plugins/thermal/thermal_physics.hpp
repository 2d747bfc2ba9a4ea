#pragma once
// Heat conduction with freezing and thawing (paper Sec. 2.4, Eqs. 17, 38, 51, 60, 64–65) in
// energy form. Theory-to-code map: docs/theory.md; design decisions: docs/architecture.md.
//
// State. Every particle has a heat content H_p(T_p) = (1 − φ) C_s T_p + φ G_m(T_p) (its own
// material's enthalpy table). The grid carries the nodal heat content e_i between steps while
// particles stand still (re-projecting particles onto the grid every step would add the
// P2G∘G2P smoothing, O(h²/Δt) of numerical diffusion, for nothing); each particle keeps its
// sub-grid deviation d_p = H_p(T_p) − Σ_i S_ip H_p(T_i) from the grid field. Energy is
// E = Σ_i V_i e_i + Σ_p V_p d_p, and Σ_p V_p H_p(T_p) = E exactly.
//
// Step. map_to_grid: (re)project particles onto the grid when they moved (or at the start),
// nodal T_i = H_i⁻¹(e_i), Dirichlet nodes at their value. solve: explicit
// e_i += Δt f_i / V_i and T_i = H_i⁻¹(e_i); or implicit backward Euler, a globalized Newton
// method on the nodal temperatures (consistent tangent, exact line search on the convex
// energy functional, a step that fails is retried in halves, never accepted). map_to_particles:
// H_p = Σ_i S_ip H_p(T_i^{n+1}) + flip_fraction · d_p — the FLIP update of heat content for
// flip_fraction = 1, PIC for 0, a blend of heat contents in between — inverted through the
// particle's own curve; a particle may not leave the range of its old temperature and its
// nodes' new ones (maximum principle), and whatever deviation it sheds goes to its nodes.
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "enthalpy_table.hpp"
#include "frostmpm/linalg/sparse_system.hpp"
#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/scene/time_function.hpp"
#include "frostmpm/physics/kernel.hpp"
#include "frostmpm/transfer/gradient_gram.hpp"
#include "frostmpm/transfer/stencil_graph.hpp"
#include "mixture_properties.hpp"
#include "nodal_heat.hpp"

namespace frostmpm::thermal {

/// The thermal physics runs in 2-D (plane); its kernels are written for the plane.
inline constexpr int kDim = 2;

class ThermalPhysics final : public Physics {
 public:
  static constexpr const char* kName = "thermal";
  static constexpr const char* kDoc = "heat conduction with latent heat of freezing/thawing (explicit or implicit)";

  static ParamSchema schema();
  explicit ThermalPhysics(const ParamSet& p);

  ParamSchema material_schema() const override { return thermal::material_schema(); }
  std::vector<ModelSlot> material_models() const override { return {{"sfcc", SfccModel::kKind, true}}; }
  static std::vector<BoundaryType> boundary_type_docs();
  std::vector<std::string> boundary_types() const override { return boundary_type_names(boundary_type_docs()); }

  void setup(Kernel<kDim>& kernel) override;
  std::vector<Stage> stages() override;
  void initialize() override;
  double stable_time_step() const override;
  void begin_step(double time, double dt) override;
  std::vector<PersistentArray> persistent_state() override;
  void restored() override;
  std::vector<std::pair<std::string, double>> statistics() const override;
  void removing_particles(const ParticleRemoval& removal) override;

 private:
  struct NodeCondition {
    std::vector<std::size_t> nodes;
    std::vector<double> areas;
    TimeFunction value;      ///< temperature, flux or ambient temperature
    double coefficient = 0;  ///< convective h
    std::string label;       ///< "temperature on face x_min", for messages
  };
  struct ParticleCondition {
    std::vector<std::size_t> particles;
    TimeFunction value;
    std::string label;
    std::vector<std::size_t> nodes;  ///< the nodes the particles make up most of (update_condition_nodes)
  };
  /// A boundary value at time t; a value that is not finite stops the run (NumericalBlowUp)
  /// naming the condition, a place on it, the time and the step.
  double value_at(const TimeFunction& f, const std::string& label, std::array<double, kDim> place, double t) const;
  double value_at(const NodeCondition& c, double t) const;
  double value_at(const ParticleCondition& c, double t) const;

  // ---- configuration -------------------------------------------------------------------------
  ParamSet params_;
  Kernel<kDim>* kernel_ = nullptr;
  // The fields the stages declare (bound by the kernel once the step is resolved).
  FieldHandle position_ = FieldHandle::particle("position", kDim, FieldKind::Vector);
  FieldHandle volume_ = FieldHandle::particle("volume");
  FieldHandle porosity_ = FieldHandle::particle("porosity");
  FieldHandle temperature_ = FieldHandle::particle("temperature");
  FieldHandle deviation_ = FieldHandle::particle("heat_deviation");
  FieldHandle temperature_pic_ = FieldHandle::particle("temperature_pic");
  FieldHandle saturation_ = FieldHandle::particle("liquid_saturation");
  FieldHandle water_flux_ = FieldHandle::particle("water_flux", kDim, FieldKind::Vector);
  FieldHandle node_temperature_ = FieldHandle::node("temperature");
  /// The skeleton's nodal velocity of the step (a mechanical physics): how far material moved.
  FieldHandle solid_velocity_ = FieldHandle::node("solid_velocity", kDim);
  bool implicit_ = false, pic_properties_ = true;
  double flip_fraction_ = 1, subgrid_relaxation_ = 0, cfl_ = 0.5, advection_cfl_ = 0.9;
  double nonlinear_tolerance_ = 1e-6;
  long max_nonlinear_iterations_ = 25, max_step_halvings_ = 12;
  std::vector<PhaseConstants> constants_;
  std::vector<std::unique_ptr<EnthalpyTable>> tables_;
  std::vector<NodeCondition> fixed_T_, flux_, convective_;
  std::vector<ParticleCondition> particle_T_;
  void update_condition_nodes();
  std::vector<double> condition_share_;  ///< scratch of update_condition_nodes
  /// A heat_flux or convective condition on particles: the surface they stand for, and the node
  /// condition (in flux_ or convective_) whose nodes and areas follow from them.
  struct ParticleSurface {
    std::vector<std::size_t> particles;
    double area = 0;
    std::vector<NodeCondition>* list = nullptr;
    std::size_t index = 0;
  };
  std::vector<ParticleSurface> particle_surfaces_;
  std::uint64_t surfaces_version_ = ~std::uint64_t{0};
  void update_particle_surfaces();

  // ---- particles (besides the fields temperature, temperature_pic, liquid_saturation,
  // porosity and heat_deviation) ----------------------------------------------------------------
  std::span<const std::uint16_t> material_;  ///< material index of every particle (the kernel's)
  std::vector<double> conductivity_;     ///< κ_p at the property temperature
  double transport_scaling_ = 1;         ///< time.transport_scaling: the factor on every conductivity
  std::vector<double> energy_;           ///< scratch: heat content, or deviation shed to the grid
  std::vector<int> hint_;                ///< enthalpy-table interval of every particle

  // ---- grid ------------------------------------------------------------------------------------
  NodalHeat nodal_;
  std::vector<double> node_volume_, node_heat_, node_force_;
  std::vector<double>* node_T_ = nullptr;  ///< the kernel's node field 'temperature' (from initialize() on)
  std::vector<double> node_pending_;  ///< heat [J] shed by particles, joins node_heat_ next step
  std::vector<std::vector<double>> node_pore_heat_;  ///< G_m(T_i), per material
  std::vector<char> dirichlet_;
  std::vector<double> dirichlet_target_;  ///< Dirichlet values at the step's end
  std::uint64_t grid_stencil_version_ = 0;
  bool grid_valid_ = false;  ///< node_heat_ holds the state (carried between steps)

  // ---- implicit --------------------------------------------------------------------------------
  std::unique_ptr<SparseSystem> system_;
  StencilGraph graph_;  ///< CSR pattern of the conductivity matrix
  GradientGram<kDim> conduction_;  ///< K = Σ_p V_p κ_p ∇S_ip·∇S_jp
  std::vector<double> free_stiffness_;
  std::vector<double> boundary_diagonal_, boundary_load_;  ///< h A_i and q A_i + h A_i T_a
  std::vector<double> residual_, rhs_, increment_, K_times_T_, K_times_increment_, start_heat_, start_T_;
  long halvings_ = 0;  ///< the last step's substep level (the next step starts one coarser)
  std::vector<double> node_T_before_;  ///< nodal T at the start of the last accepted substep
  double previous_substep_ = 0;       ///< its length (0: no history, e.g. after a re-projection)
  bool preconditioner_fresh_ = false;  ///< built for this step's conductivity matrix

  // ---- step and bookkeeping --------------------------------------------------------------------
  double time_ = 0, dt_ = 0, max_diffusivity_ = 0, min_capacity_ = 0;
  bool initialized_ = false;
  double initial_heat_ = 0;    ///< Σ V_p H_p(T_p) at the start
  double boundary_heat_ = 0;   ///< heat that entered through boundaries so far [J per m thickness]
  bool advection_ = false;     ///< the scene has a Darcy flux (particle field water_flux)
  std::vector<double> advection_force_;  ///< convective term of this step, per node [W per m]
  double advected_rate_ = 0;   ///< Σ_i advection_force_ [W per m]
  double deformation_heat_ = 0;  ///< heat change of the particles as the skeleton deformed them
  double removed_heat_ = 0;      ///< heat of the particles removed after leaving the grid
  double heat_after_step_ = 0;    ///< Σ V_p H_p at the end of the last step (a moving skeleton)
  bool heat_after_step_valid_ = false;
  double advected_heat_ = 0;   ///< heat carried in by the flow so far (included in boundary_heat_)
  long nonlinear_total_ = 0, nonlinear_max_ = 0, linear_total_ = 0, rejected_substeps_ = 0, substeps_ = 0,
       clipped_ = 0;
  double smallest_substep_ = std::numeric_limits<double>::infinity();
  std::vector<double> saved_scalars_;  ///< persistent_state() packs the scalars here

  // thermal_physics.cpp
  void read_boundaries(Kernel<kDim>& kernel);
  /// (1 − φ) C_s: the solid's share of a particle's heat capacity.
  double sensible(std::size_t p, double phi) const { return (1.0 - phi) * constants_[material_[p]].solid_capacity; }
  void evaluate_particle_properties(std::size_t p, double phi, double T_property);
  /// The smaller of the thawed and frozen sensible capacities of particle p.
  double sensible_capacity(std::size_t p, double phi) const {
    const auto& pc = constants_[material_[p]];
    return std::min(pc.capacity(phi, 0.0), pc.capacity(phi, 1.0));
  }
  void update_step_limits();
  void project_to_grid(bool with_heat);
  void invert_nodes();
  void update_node_pore_heat();
  void apply_dirichlet_nodes(double time);
  void set_dirichlet_targets(double time);
  void map_to_grid();
  void map_to_particles();
  void shed_to_grid();
  void apply_particle_dirichlet(double time, bool count_heat);
  /// V_p times the heat content of particle p at its temperature (the enthalpy table's).
  double particle_heat(std::size_t p, std::span<const double> T, std::span<const double> phi,
                       std::span<const double> vol) const;
  double particle_heat_total() const;
  // explicit_step.cpp
  double particle_flows(bool conduction, bool convection);
  /// Adds the heat-flux and convective flows at `time` (convection from temperatures T) into
  /// `into`; returns their sum [W per m of thickness].
  double boundary_flow(double time, const std::vector<double>& T, std::vector<double>& into) const;
  void solve_explicit();
  // implicit_step.cpp
  void build_graph();
  void assemble_conductivity();
  void solve_implicit();
  bool newton(double t_end, double h);
  double nodal_residual(double h);
  double line_search(double h);
  [[noreturn]] void report_not_finite(double t_end, double h) const;
  void multiply_conductivity(const std::vector<double>& x, std::vector<double>& y) const;
  bool is_free(std::size_t i) const { return node_volume_[i] > 0 && !dirichlet_[i]; }
};

}  // namespace frostmpm::thermal
