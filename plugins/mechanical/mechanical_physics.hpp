#pragma once
// The solid skeleton (solid grains and ice, paper Sec. 2.3, 3.3, 4.1–4.4, Algorithm 1): the
// momentum balance of the mixture with gravity and tractions, effective stress σ′ (tension
// positive; total σ = σ′ − p_l I), the objective (Jaumann) stress rate, strain increments from
// the nodal solid velocity, porosity from the conserved solid volume and the trapezoidal
// position update. Written once for 2-D (plane strain) and 3-D; stress is always 3×3.
//
// Step (update stress first, as Algorithm 1):
//   map_to_grid       P2G of inertia and momentum; velocity conditions on v^k; at every particle
//                     L = Σ_i v_i ⊗ ∇S_ip, Δε = sym(L) Δt − β_s ΔT/3 I, the Jaumann rotation of
//                     σ′ by W = skew(L), the constitutive model (per material range), F ← (I + LΔt) F,
//                     porosity from the solid volume, the skeleton's inertia for the liquid;
//   predict           nodal forces −Σ V ∇S·(σ′ − p I) + Σ S V ρ_m g + tractions (+ the liquid's
//                     reaction and its implicit drag when a hydraulic physics runs), local damping,
//                     v* = (m v + Δt f)/(m + Δt D); velocity conditions on v* (their reaction kept);
//   correct           with a pressure increment: Δv = −Δt Σ S V (1 − n_l ξ) ∇Δp / (m + Δt D)
//                     (the skeleton's share of the two-phase corrector, models/two_phase.hpp);
//   map_to_particles  FLIP/PIC blend of the velocity; x += Δt Σ S v_i^k (symplectic with the stress
//                     update; Alg. 1 step 21's trapezoid as an option, see map_to_particles).
// The kernel derives particle volumes V = V0 det F and GIMP domains from the deformation
// gradient and recomputes the stencils every step, since this physics writes `position`.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "frostmpm/models/mechanical_model.hpp"
#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/scene/time_function.hpp"

namespace frostmpm::mechanical {

/// The skeleton's boundary-condition types and their keys (boundary_conditions.cpp): what
/// `describe boundary_conditions/TYPE` prints and what each condition accepts.
std::vector<BoundaryType> mechanical_boundary_types();

template <int Dim>
class MechanicalPhysics final : public Physics {
 public:
  static ParamSchema schema();
  explicit MechanicalPhysics(const ParamSet& p);

  ParamSchema material_schema() const override;
  std::vector<ModelSlot> material_models() const override {
    return {{"mechanical_model", MechanicalModel::kKind, true}};
  }
  std::vector<std::string> boundary_types() const override { return boundary_type_names(mechanical_boundary_types()); }

  void setup(Kernel<Dim>& kernel) override;
  std::vector<Stage> stages() override;
  void initialize() override;
  double stable_time_step() const override;
  void begin_step(double time, double dt) override;
  std::vector<PersistentArray> persistent_state() override;
  void restored() override;
  std::optional<std::array<double, 3>> reaction(const BoundaryCondition& bc) const override;
  std::optional<RigidBodyMotion> rigid_body(const BoundaryCondition& bc) const override;
  std::vector<std::pair<std::string, double>> statistics() const override;
  void removing_particles(const ParticleRemoval& removal) override;

 private:
  /// A velocity condition: the components it prescribes (value at time t), on nodes.
  struct VelocityCondition {
    const BoundaryCondition* bc = nullptr;
    std::vector<std::size_t> nodes;
    std::array<std::optional<TimeFunction>, Dim> value;
    std::array<double, 3> reaction{};  ///< force on the material over the last step [N (per m in 2-D)]
  };
  /// A rigid wall along a grid face with Coulomb friction (`type: friction`): the material may
  /// leave it but not cross it, and slides along it only while the tangential force it needs
  /// exceeds μ times the normal force it presses with (μ = tan δ).
  struct FrictionCondition {
    const BoundaryCondition* bc = nullptr;
    std::vector<std::size_t> nodes;
    int axis = 0;                      ///< the face's normal axis
    int side = -1;                     ///< the face's outward normal: −1 on a min face, +1 on a max face
    double coefficient = 0;            ///< μ = tan δ
    std::array<double, 3> reaction{};  ///< force on the material over the last step [N (per m in 2-D)]
  };
  /// A traction condition: force per area on face nodes, or on the surface of a set of
  /// particles (which it follows as the material moves: `particles:` with an outward `normal:`).
  struct TractionCondition {
    const BoundaryCondition* bc = nullptr;
    std::vector<std::size_t> nodes;
    std::vector<double> areas;
    std::vector<std::size_t> particles;
    int normal_axis = -1;  ///< particles: the axis of the outward normal (their loaded face is ⟂ to it)
    std::array<TimeFunction, Dim> value;  ///< traction vector components [Pa]
    std::array<double, 3> applied{};      ///< force it applied over the last step
  };
  /// A rigid, frictionless plate on a face: the normal velocity of all its nodes is one, driven
  /// by the total force on it (the load it carries and the material's reaction).
  struct PlateCondition {
    const BoundaryCondition* bc = nullptr;
    std::vector<std::size_t> nodes;
    int axis = 0, side = 1;
    TimeFunction load;                 ///< total force pushing into the material [N (per m in 2-D)]
    std::array<double, 3> applied{};   ///< the load over the last step, as a force on the material
  };
  /// A rigid footing driven along one axis: the nodes inside its box, which moves with it, follow
  /// its velocity (rough: the other components held at 0; smooth: left free). The prescribing
  /// is a velocity condition (velocity_bcs_[velocity]) whose nodes are re-placed every step.
  struct FootingCondition {
    std::size_t velocity = 0;            ///< its condition in velocity_bcs_: values, nodes, reaction
    std::array<double, Dim> lo{}, hi{};  ///< its box at t = 0 [m]
    int axis = 0;
    double direction = 1;     ///< the sign of its motion along `axis`
    double contact_area = 0;  ///< the box across the axis, within the grid [m² (m in 2-D)]
    double displacement = 0;  ///< along `axis` since t = 0, signed [m]
  };
  void warn_of_locking(const Kernel<Dim>& kernel) const;
  struct MaterialData {
    std::shared_ptr<MechanicalModel> model;
    std::string model_name;
    std::vector<std::size_t> variables;  ///< index of each of the model's internal variables in variables_
    double solid_density = 0, water_density = 0, ice_density = 0, expansion = 0, k0 = 0;
  };

  // ---- configuration
  ParamSet params_;
  Kernel<Dim>* kernel_ = nullptr;
  double flip_ = 1, cfl_ = 0.5, damping_ = 0, mass_scaling_ = 1;
  /// A node's inertia is at least this fraction of the heaviest particle reaching it (predict(); the
  /// scene's minimum_node_mass, whose default the schema holds).
  double minimum_node_mass_ = 0;
  bool jaumann_ = true, geostatic_ = false, trapezoidal_ = false;
  bool cell_average_ = false;  ///< volumetric_strain: cell_average (average_volumetric_strain())
  std::vector<MaterialData> materials_;
  std::vector<VelocityCondition> velocity_bcs_;
  std::vector<TractionCondition> traction_bcs_;
  std::vector<FrictionCondition> friction_bcs_;
  std::vector<PlateCondition> plates_;
  std::vector<FootingCondition> footings_;
  double footing_limit_ = std::numeric_limits<double>::infinity();  ///< h / the fastest footing speed of the run [s]
  std::vector<int> constraint_owner_;  ///< node·Dim + d → velocity condition k ≥ 0, −1 free, −2 − k rigid plate k

  // ---- fields (bound by the kernel once the step is resolved)
  FieldHandle position_, half_size_, volume_, porosity_, velocity_, displacement_, stress_, stress_start_, strain_, deformation_,
      inertia_, shear_, temperature_, saturation_, pore_pressure_, liquid_drag_, liquid_reaction_, liquid_share_;
  /// The grains' accumulated free thermal strain on each normal component, β_s (T − T_0)/3.
  FieldHandle grain_thermal_strain_;
  FieldHandle node_velocity_, node_predicted_, node_increment_, node_pressure_, node_mobility_, node_group_;
  std::vector<InternalVariable> variable_list_;             ///< internal variables of every model, once each
  std::vector<FieldHandle> variables_, variables_start_;    ///< their particle fields

  // ---- per particle (scratch and the step's moduli)
  std::vector<double> strain_increment_, rotated_, wave_modulus_, previous_T_;
  std::vector<double> particle_mass_;  ///< without pore-water flow: each particle's constant mass
  std::vector<std::uint8_t> failed_;
  // ---- cell-averaged volumetric strain (only with cell_average_)
  std::vector<double> thermal_strain_;            ///< per particle: its thermal strain of the step (one component)
  std::vector<double> volume_ratio_;              ///< per particle: its kinematic volume ratio J of the step
  std::vector<std::size_t> cell_of_;              ///< per particle: its grid cell
  std::vector<double> cell_volume_, cell_mean_;   ///< per cell: Σ V and the volume-weighted mean (average_over_cells)
  std::vector<double> force_stress_;              ///< per particle: σ′ with its cell's mean trace, for the forces (predict())
  // ---- per node
  std::vector<double> mass_, drag_, force_, momentum_, weight_, start_velocity_;  ///< start_velocity_: v^k after its conditions
  /// max(mass, minimum_node_mass × the heaviest particle whose domain reaches the node): predict(), correct()
  std::vector<double> nodal_inertia_;
  std::vector<double> mapped_velocity_;  ///< momentum / mass as mapped (before the conditions), for FLIP

  // ---- step and counters
  double time_ = 0, dt_ = 0;
  /// min h / (c_p + |v|) over the particles, taken by map_to_particles from the state it leaves
  /// (stable_time_step() then needs no pass of its own); invalid until then.
  double step_limit_ = 0;
  bool step_limit_valid_ = false;
  bool primed_ = false;  ///< previous_T_ holds the temperature of the last stress update
  double kinetic_energy_ = 0, elastic_energy_ = 0, external_work_ = 0, kinetic_to_work_max_ = 0;
  double removed_mass_ = 0;  ///< mass of the particles removed after leaving the grid
  static inline double elastic_energy_density(const double* stress, double p_wave_modulus, double shear_modulus);
  std::vector<double> saved_scalars_;

  void read_boundaries(Kernel<Dim>& kernel);
  static int particle_normal_axis(const BoundaryCondition& bc);
  /// Sets the prescribed components of the nodal velocity `v` at time t; with `force_scale` > 0
  /// adds each condition's reaction (force_scale · (v_prescribed − v_free) per component).
  void constrain(std::vector<double>& v, double t, double force_scale);
  void apply_friction(std::vector<double>& v, double force_scale);
  /// Gives every plate's nodes one normal velocity, momentum-weighted with the nodal inertia
  /// m (+ Δt D when `with_drag`), plus `dt` times the plate's load at time t.
  void tie_plates(std::vector<double>& v, double t, double dt, bool with_drag);
  /// Reads a footing condition (after the velocity conditions and plates, whose nodes it checks).
  void read_footing(BoundaryCondition& bc, const Kernel<Dim>& kernel);
  /// Gives each footing the nodes of its body where it now is (each step, before the stages).
  void place_footings();
  /// The nodes' region a footing holds at t = 0 (footing_body() in boundary_conditions.cpp).
  static std::pair<std::array<double, Dim>, std::array<double, Dim>> footing_body(const FootingCondition& f,
                                                                                  const UniformGrid<Dim>& grid);
  /// ρ_m, the skeleton's inertia per volume and n_l of particle p (S_l from the thermal physics, else 1).
  void densities(std::size_t p, double& rho_m, double& skeleton, double& n_l) const;
  /// densities() with what it reads fetched once, for loops over particles (a handle's values()
  /// and the kernel's transfer() are calls, as costly as the arithmetic when made per particle).
  struct DensityView {
    const MaterialData* materials;
    const std::uint16_t* material;
    const double *porosity, *saturation, *particle_mass, *volume;  ///< saturation, particle_mass: null if none
    void operator()(std::size_t p, double& rho_m, double& skeleton, double& n_l) const;
  };
  DensityView density_view() const;
  void map_to_grid();
  void update_stress();
  void predict();
  void correct();
  void map_to_particles();
  void set_geostatic_stress();
  void average_volumetric_strain();
  template <class CloseVolume>
  void average_volume_ratio(std::span<double> F, CloseVolume close_volume);
  template <class Value>
  void average_over_cells(Value value);
  [[noreturn]] void report_failure(std::size_t p) const;
};

}  // namespace frostmpm::mechanical
