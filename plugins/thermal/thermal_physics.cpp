// Heat conduction with freezing and thawing (paper Sec. 2.4, Eqs. 17, 38, 51, 60, 64–65).
//
// Energy is the conserved quantity: each step produces nodal energy increments Δe_i [J/m³]
// (explicit: Δt f_i / V_i; implicit: backward Euler with a chord-capacity Picard iteration),
// every particle receives ΔE_p = Σ_i S_ip Δe_i, and its new temperature solves
// heat(T_p → T_p') = ΔE_p through its SFCC. Latent heat therefore can never be stepped over,
// however narrow the freezing window, and the total energy is conserved to round-off.
// The particle temperature is FLIP-updated; the PIC temperature (Eq. 65) feeds the
// temperature-dependent properties as in the paper, and `flip_fraction` < 1 blends it in.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "frostmpm/linalg/sparse_system.hpp"
#include "frostmpm/plugin/plugin_api.hpp"
#include "frostmpm/scene/time_function.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "mixture_properties.hpp"

namespace frostmpm::thermal {

class ThermalPhysics final : public Physics {
 public:
  static constexpr const char* kName = "thermal";
  static constexpr const char* kDoc = "heat conduction with latent heat of freezing/thawing (explicit or implicit)";

  static ParamSchema schema() {
    ParamSchema s;
    s.choice("scheme", {"explicit", "implicit"}, "time integration: explicit (paper) or backward Euler")
        .defaults_to("explicit");
    s.choice("conductivity_average", {"arithmetic", "geometric"}, "mixing rule for κ_m").defaults_to("arithmetic");
    s.choice("latent_heat_density", {"ice", "water"}, "density multiplying L_f (paper: ice; Kurylyk/INTERFROST: water)")
        .defaults_to("ice");
    s.choice("property_temperature", {"pic", "flip"}, "temperature that feeds S_l, C_m, κ_m (paper: pic)")
        .defaults_to("pic");
    s.real("flip_fraction", "-", "particle update: 1 = FLIP (Eq. 64), 0 = PIC (Eq. 65), between = blend")
        .defaults_to(1.0).at_least(0).at_most(1);
    s.real("subgrid_relaxation", "-",
           "sub-grid exchange: particle deviations from the grid field relax over this many cell "
           "diffusion times h^2/alpha, energy-conservatively; 0 = off (pure FLIP). Use ~10 when "
           "initial fields jump inside a cell; it smears sharp fronts")
        .defaults_to(0.0).at_least(0);
    s.real("cfl", "-", "explicit: fraction of the diffusion stability limit used as Δt").defaults_to(0.5).above(0).at_most(1);
    s.real("nonlinear_tolerance", "degC", "implicit: Picard stops when the nodal update changes less")
        .defaults_to(1e-6).above(0);
    s.integer("max_nonlinear_iterations", "implicit: Picard iteration cap per step").defaults_to(100L).at_least(1);
    s.choice("preconditioner", {"jacobi", "ilu", "multigrid", "none"}, "implicit: preconditioner for CG")
        .defaults_to("jacobi");
    s.real("linear_tolerance", "-", "implicit: relative residual of the linear solves").defaults_to(1e-12).above(0);
    return s;
  }

  explicit ThermalPhysics(const ParamSet& p) : params_(p) {
    implicit_ = p.string("scheme") == "implicit";
    flip_fraction_ = p.real("flip_fraction");
    pic_properties_ = p.string("property_temperature") == "pic";
    cfl_ = p.real("cfl");
    subgrid_relaxation_ = p.real("subgrid_relaxation");
  }

  ParamSchema material_schema() const override { return thermal::material_schema(); }
  std::vector<ModelSlot> material_models() const override { return {{"sfcc", SfccModel::kKind, true}}; }
  std::vector<std::string> boundary_types() const override { return {"temperature", "heat_flux", "convective"}; }

  void setup(Simulation& sim) override {
    sim_ = &sim;
    auto& particles = sim.particles();
    sim.declare_state_field("temperature", 1, 0.0);
    sim.declare_state_field("porosity", 1, 0.0);
    particles.declare("temperature_pic", 1);
    particles.declare("liquid_saturation", 1, 1.0);

    const auto average = params_.string("conductivity_average") == "geometric" ? ConductivityAverage::Geometric
                                                                              : ConductivityAverage::Arithmetic;
    const bool water = params_.string("latent_heat_density") == "water";
    for (const auto& m : sim.materials()) {
      constants_.push_back(phase_constants(m.params, average, water));
      sfcc_.push_back(m.models.at("sfcc").create<SfccModel>(sim.registry()));
    }
    auto phi = particles.field("porosity");
    for (const auto& r : particles.ranges())
      std::fill(phi.begin() + r.begin, phi.begin() + r.end, sim.materials()[r.material].params.real("porosity"));

    read_boundaries(sim);
    if (implicit_ && sim.fixed_dt() <= 0)
      throw InputError("physics.thermal: the implicit scheme needs a fixed step: set time.dt (seconds)");

    const std::size_t nodes = sim.grid().node_count();
    for (auto* v : {&node_volume_, &node_T_, &node_force_, &node_capacity_, &node_dT_, &dirichlet_target_,
                    &dirichlet_start_})
      v->assign(nodes, 0.0);
    dirichlet_.assign(nodes, 0);
  }

  std::vector<Stage> stages() override {
    return {{"thermal.properties", [this] { update_properties(); }},
            {"thermal.map_to_grid", [this] { map_to_grid(); }},
            {"thermal.solve", [this] { implicit_ ? solve_implicit() : solve_explicit(); }},
            {"thermal.map_to_particles", [this] { map_to_particles(); }}};
  }

  double stable_time_step() const override {
    if (implicit_) return std::numeric_limits<double>::infinity();
    if (!initialized_) const_cast<ThermalPhysics*>(this)->initialize();
    if (!properties_valid_) const_cast<ThermalPhysics*>(this)->update_properties();
    const double h = sim_->grid().min_spacing();
    double dt = cfl_ * h * h / (2.0 * kDim * max_diffusivity_);
    // A convective face is a spring h·A on the node: keep Δt below C V_i/(h A_i) ≈ C (Δx/2)/h.
    for (const auto& bc : convective_) dt = std::min(dt, cfl_ * min_capacity_ * 0.5 * h / bc.coefficient);
    return dt;
  }

  void initialize() override {
    // Before any step the PIC temperature is the initial temperature.
    auto T = sim_->particles().field("temperature");
    auto T_pic = sim_->particles().field("temperature_pic");
    apply_particle_dirichlet(sim_->time());
    std::copy(T.begin(), T.end(), T_pic.begin());
    update_properties();
    initialized_ = true;
  }

  void begin_step(double time, double dt) override {
    if (!initialized_) initialize();
    start_saturation_valid_ = false;
    time_ = time;
    dt_ = dt;
  }

  std::vector<std::pair<std::string, double>> statistics() const override {
    return {{"thermal.nonlinear_iterations_total", double(nonlinear_total_)},
            {"thermal.nonlinear_iterations_max", double(nonlinear_max_)},
            {"thermal.linear_iterations_total", double(linear_total_)},
            {"thermal.unconverged_steps", double(unconverged_steps_)},
            {"thermal.energy_inversion_iterations_max", double(inversion_max_)}};
  }

 private:
  struct NodeCondition {
    std::vector<std::size_t> nodes;
    std::vector<double> areas;
    TimeFunction value;    ///< temperature or flux or ambient temperature
    double coefficient = 0;  ///< convective h
  };
  struct ParticleCondition {
    std::vector<std::size_t> particles;
    TimeFunction value;
  };

  ParamSet params_;
  Simulation* sim_ = nullptr;
  bool implicit_ = false, pic_properties_ = true, initialized_ = false, properties_valid_ = false,
       start_saturation_valid_ = false;
  double flip_fraction_ = 1, subgrid_relaxation_ = 0, cfl_ = 0.5, time_ = 0, dt_ = 0, max_diffusivity_ = 0, min_capacity_ = 0;
  std::vector<PhaseConstants> constants_;
  std::vector<std::shared_ptr<SfccModel>> sfcc_;
  std::vector<NodeCondition> fixed_T_, flux_, convective_;
  std::vector<ParticleCondition> particle_T_;

  // Per-particle scratch (plugin-owned, not particle fields): capacity, conductivity, dS/dT.
  std::vector<double> capacity_, conductivity_, slope_, energy_, scratch_a_;
  // Nodal arrays.
  std::vector<double> node_volume_, node_T_, node_force_, node_capacity_, node_dT_,
      dirichlet_target_, dirichlet_start_;
  std::vector<char> dirichlet_;
  std::vector<double> particle_chord_, nodal_capacity_, c_T1_, c_S0_, c_S1_, c_dS0_, c_dS1_, c_unused_, c_delta_;
  // Implicit: matrix graph built from the stencil, reused while the stencil topology holds.
  std::unique_ptr<SparseSystem> system_;
  std::vector<double> stiffness_, matrix_values_, rhs_, constraint_dT_;
  std::vector<std::size_t> offsets_;  ///< CSR pattern (kept for constraint elimination)
  std::vector<int> columns_;
  std::vector<int> scatter_;         ///< CSR position of every (particle, k1, k2) pair
  std::vector<std::size_t> diagonal_;  ///< CSR position of (i, i)
  std::uint64_t graph_version_ = 0;
  long nonlinear_total_ = 0, nonlinear_max_ = 0, linear_total_ = 0, unconverged_steps_ = 0, inversion_max_ = 0;

  // ------------------------------------------------------------------------------------------
  void read_boundaries(Simulation& sim) {
    for (auto* bc : sim.boundary_conditions("temperature")) {
      TimeFunction value = TimeFunction::read(bc->node->child("value"));
      if (bc->on_particles) particle_T_.push_back({bc->particles, value});
      else fixed_T_.push_back({bc->nodes, bc->node_areas, value, 0});
    }
    for (auto* bc : sim.boundary_conditions("heat_flux")) {
      if (bc->on_particles || !std::any_of(bc->node_areas.begin(), bc->node_areas.end(), [](double a) { return a > 0; }))
        throw bc->node->error("heat_flux acts on a grid face: use nodes: {face: ...}");
      fixed_flux(bc, TimeFunction::read(bc->node->child("value")), 0.0, flux_);
    }
    for (auto* bc : sim.boundary_conditions("convective")) {
      if (bc->on_particles || !std::any_of(bc->node_areas.begin(), bc->node_areas.end(), [](double a) { return a > 0; }))
        throw bc->node->error("convective acts on a grid face: use nodes: {face: ...}");
      const ConfigNode h = bc->node->child("h");
      const double coefficient = h.as_real();
      if (!(coefficient > 0)) throw h.error("heat transfer coefficient h must be positive (W/m^2/K)");
      fixed_flux(bc, TimeFunction::read(bc->node->child("ambient")), coefficient, convective_);
    }
  }
  static void fixed_flux(BoundaryCondition* bc, TimeFunction value, double h, std::vector<NodeCondition>& into) {
    into.push_back({bc->nodes, bc->node_areas, std::move(value), h});
  }

  /// S_l, C_m, κ_m and dS_l/dT of every particle at its property temperature.
  void update_properties() {
    auto& particles = sim_->particles();
    const std::size_t n = particles.size();
    capacity_.resize(n);
    conductivity_.resize(n);
    slope_.resize(n);
    scratch_a_.resize(n);
    const auto T = particles.field(pic_properties_ ? "temperature_pic" : "temperature");
    const auto phi = particles.field("porosity");
    auto S = particles.field("liquid_saturation");
    max_diffusivity_ = 0;
    min_capacity_ = std::numeric_limits<double>::infinity();
    for (const auto& r : particles.ranges()) {
      const auto& pc = constants_[r.material];
      sfcc_[r.material]->evaluate(T.subspan(r.begin, r.size()), {},
                                  SfccResult{S.subspan(r.begin, r.size()), std::span(slope_).subspan(r.begin, r.size()),
                                             std::span(scratch_a_).subspan(r.begin, r.size())});
      for (std::size_t p = r.begin; p < r.end; ++p) {
        capacity_[p] = pc.capacity(phi[p], S[p]);
        conductivity_[p] = pc.conductivity(phi[p], S[p]);
        max_diffusivity_ = std::max(max_diffusivity_, conductivity_[p] / capacity_[p]);
        min_capacity_ = std::min(min_capacity_, capacity_[p]);
      }
    }
    properties_valid_ = true;
  }

  /// T_i = Σ_p V_p C_p S_ip T_p / Σ_p V_p C_p S_ip (Algorithm 1, line 7) into node_T_, the
  /// denominator into node_capacity_, and optionally V_i = Σ_p V_p S_ip into node_volume_.
  void capacity_weighted_nodal_temperature(bool with_volume) {
    const auto& st = sim_->stencil();
    const auto& particles = sim_->particles();
    const auto T = particles.field("temperature");
    const auto vol = particles.field("volume");
    if (with_volume) std::fill(node_volume_.begin(), node_volume_.end(), 0.0);
    std::fill(node_T_.begin(), node_T_.end(), 0.0);
    std::fill(node_capacity_.begin(), node_capacity_.end(), 0.0);
    const int K = st.per_particle();
    for (std::size_t p = 0; p < particles.size(); ++p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      const double vc = vol[p] * capacity_[p];
      for (int k = 0; k < K; ++k) {
        if (with_volume) node_volume_[nodes[k]] += vol[p] * w[k];
        node_capacity_[nodes[k]] += vc * w[k];
        node_T_[nodes[k]] += vc * w[k] * T[p];
      }
    }
    for (std::size_t i = 0; i < node_T_.size(); ++i)
      node_T_[i] = node_capacity_[i] > 0 ? node_T_[i] / node_capacity_[i] : 0.0;
  }

  /// Capacity-weighted nodal temperature and nodal volume; Dirichlet nodes marked.
  void map_to_grid() {
    capacity_weighted_nodal_temperature(/*with_volume=*/true);
    // Dirichlet nodes: the prescribed value now, and the target at the end of the step.
    std::fill(dirichlet_.begin(), dirichlet_.end(), 0);
    for (const auto& bc : fixed_T_) {
      const double now = bc.value(time_), target = bc.value(time_ + dt_);
      for (std::size_t i : bc.nodes) {
        if (node_volume_[i] <= 0) continue;
        dirichlet_start_[i] = node_T_[i];  // what the node's particles are at now
        node_T_[i] = now;
        dirichlet_[i] = 1;
        dirichlet_target_[i] = target;
      }
    }
  }

  /// f_i = −Σ_p V_p κ_p ∇S_ip·∇T_p (+ boundary fluxes at `T_face` for convection).
  void conduction_force() {
    const auto& st = sim_->stencil();
    const auto& particles = sim_->particles();
    const auto vol = particles.field("volume");
    std::fill(node_force_.begin(), node_force_.end(), 0.0);
    const int K = st.per_particle();
    for (std::size_t p = 0; p < particles.size(); ++p) {
      const auto* nodes = st.nodes(p);
      const auto* g = st.gradients(p);
      double grad[kDim] = {};
      for (int k = 0; k < K; ++k)
        for (int d = 0; d < kDim; ++d) grad[d] += node_T_[nodes[k]] * g[k * kDim + d];
      const double a = vol[p] * conductivity_[p];
      for (int k = 0; k < K; ++k) {
        double dot = 0;
        for (int d = 0; d < kDim; ++d) dot += g[k * kDim + d] * grad[d];
        node_force_[nodes[k]] -= a * dot;
      }
    }
    for (const auto& bc : flux_) {
      const double q = bc.value(time_);
      for (std::size_t j = 0; j < bc.nodes.size(); ++j) node_force_[bc.nodes[j]] += q * bc.areas[j];
    }
    for (const auto& bc : convective_) {
      const double ambient = bc.value(time_);
      for (std::size_t j = 0; j < bc.nodes.size(); ++j)
        node_force_[bc.nodes[j]] += bc.coefficient * bc.areas[j] * (ambient - node_T_[bc.nodes[j]]);
    }
  }

  /// Chord capacity of every particle for the temperature change ΔT_p = Σ_i S_ip node_dT_i:
  /// c_p = heat(T_p → T_p + ΔT_p)/ΔT_p, or the apparent capacity C + ρL φ dS/dT when ΔT_p is
  /// tiny (stored in particle_chord_), and the nodal chord capacity C̃_i = Σ_p V_p S_ip c_p / V_i.
  void nodal_chord_capacity(std::vector<double>& nodal) {
    const auto& st = sim_->stencil();
    auto& particles = sim_->particles();
    const auto T = particles.field("temperature");
    const auto phi = particles.field("porosity");
    const auto vol = particles.field("volume");
    const int K = st.per_particle();
    const std::size_t n = particles.size();
    std::fill(nodal.begin(), nodal.end(), 0.0);
    for (auto* v : {&particle_chord_, &c_T1_, &c_S0_, &c_S1_, &c_dS0_, &c_dS1_, &c_unused_, &c_delta_}) v->resize(n);
    for (std::size_t p = 0; p < n; ++p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      double d = 0;
      for (int k = 0; k < K; ++k) d += w[k] * node_dT_[nodes[k]];
      c_delta_[p] = d;
      c_T1_[p] = T[p] + d;
    }
    bool any_change = false;
    for (std::size_t p = 0; p < n && !any_change; ++p) any_change = std::abs(c_delta_[p]) > 1e-9;
    for (const auto& r : particles.ranges()) {
      auto sub = [&](std::vector<double>& v) { return std::span(v).subspan(r.begin, r.size()); };
      // S_l(T_p) is the same for every call within a step: evaluate it once.
      if (!start_saturation_valid_)
        sfcc_[r.material]->evaluate(T.subspan(r.begin, r.size()), {}, SfccResult{sub(c_S0_), sub(c_dS0_), sub(c_unused_)});
      if (any_change)
        sfcc_[r.material]->evaluate(sub(c_T1_), {}, SfccResult{sub(c_S1_), sub(c_dS1_), sub(c_unused_)});
      const auto& pc = constants_[r.material];
      for (std::size_t p = r.begin; p < r.end; ++p) {
        const double chord = std::abs(c_delta_[p]) > 1e-9
                                 ? pc.heat(phi[p], T[p], c_S0_[p], c_T1_[p], c_S1_[p]) / c_delta_[p]
                                 : pc.capacity(phi[p], c_S0_[p]) + pc.latent_density * phi[p] * c_dS0_[p];
        particle_chord_[p] = chord;
        const auto* nodes = st.nodes(p);
        const auto* w = st.weights(p);
        for (int k = 0; k < K; ++k) nodal[nodes[k]] += vol[p] * w[k] * chord;
      }
    }
    start_saturation_valid_ = true;
    for (std::size_t i = 0; i < nodal.size(); ++i) nodal[i] = node_volume_[i] > 0 ? nodal[i] / node_volume_[i] : 0.0;
  }

  void solve_explicit() {
    conduction_force();
    // Free nodes gain Δt f_i of energy per V_i; their temperature change is that energy over
    // the nodal chord capacity, found by two fixed-point passes (tangent, then chord).
    // Dirichlet nodes move their particles from where they are to the prescribed value.
    const std::size_t nodes = node_volume_.size();
    std::fill(node_dT_.begin(), node_dT_.end(), 0.0);
    for (std::size_t i = 0; i < nodes; ++i)
      if (dirichlet_[i]) node_dT_[i] = dirichlet_target_[i] - dirichlet_start_[i];
    nodal_capacity_.resize(nodes);
    for (int pass = 0; pass < 2; ++pass) {
      nodal_chord_capacity(nodal_capacity_);
      for (std::size_t i = 0; i < nodes; ++i)
        if (!dirichlet_[i])
          node_dT_[i] = node_volume_[i] > 0 ? dt_ * node_force_[i] / (node_volume_[i] * nodal_capacity_[i]) : 0.0;
    }
  }

  // ---- implicit -----------------------------------------------------------------------------
  void build_graph() {
    const auto& st = sim_->stencil();
    const std::size_t nodes = node_volume_.size();
    const int K = st.per_particle();
    std::vector<std::vector<int>> columns(nodes);
    for (std::size_t i = 0; i < nodes; ++i) columns[i].push_back(static_cast<int>(i));
    for (std::size_t p = 0; p < st.particles(); ++p) {
      const auto* n = st.nodes(p);
      for (int a = 0; a < K; ++a)
        for (int b = 0; b < K; ++b) columns[n[a]].push_back(static_cast<int>(n[b]));
    }
    std::vector<std::size_t> offsets(nodes + 1, 0);
    std::vector<int> cols;
    for (std::size_t i = 0; i < nodes; ++i) {
      auto& c = columns[i];
      std::sort(c.begin(), c.end());
      c.erase(std::unique(c.begin(), c.end()), c.end());
      cols.insert(cols.end(), c.begin(), c.end());
      offsets[i + 1] = cols.size();
    }
    auto position = [&](std::size_t row, int col) {
      const auto begin = cols.begin() + static_cast<long>(offsets[row]);
      const auto end = cols.begin() + static_cast<long>(offsets[row + 1]);
      return static_cast<std::size_t>(std::lower_bound(begin, end, col) - cols.begin());
    };
    scatter_.resize(st.particles() * K * K);
    for (std::size_t p = 0; p < st.particles(); ++p) {
      const auto* n = st.nodes(p);
      for (int a = 0; a < K; ++a)
        for (int b = 0; b < K; ++b)
          scatter_[(p * K + a) * K + b] = static_cast<int>(position(n[a], static_cast<int>(n[b])));
    }
    diagonal_.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i) diagonal_[i] = position(i, static_cast<int>(i));
    SolverOptions options;
    options.method = "cg";
    options.preconditioner = params_.string("preconditioner");
    options.tolerance = params_.real("linear_tolerance");
    options.max_iterations = 5000;
    offsets_ = offsets;
    columns_ = cols;
    system_ = std::make_unique<SparseSystem>(std::move(offsets), std::move(cols), options);
    stiffness_.assign(system_->nonzeros(), 0.0);
    matrix_values_.assign(system_->nonzeros(), 0.0);
    graph_version_ = st.version();
  }

  void solve_implicit() {
    const auto& st = sim_->stencil();
    if (!system_ || (st.topology_changed() && st.version() != graph_version_)) build_graph();
    conduction_force();  // f^n = −K T^n + boundary fluxes at T^n
    // Conductivity matrix K (constant over the Picard iteration of this step).
    const auto vol = sim_->particles().field("volume");
    const int K = st.per_particle();
    std::fill(stiffness_.begin(), stiffness_.end(), 0.0);
    for (std::size_t p = 0; p < st.particles(); ++p) {
      const auto* g = st.gradients(p);
      const double a = vol[p] * conductivity_[p];
      for (int i = 0; i < K; ++i)
        for (int j = 0; j < K; ++j) {
          double dot = 0;
          for (int d = 0; d < kDim; ++d) dot += g[i * kDim + d] * g[j * kDim + d];
          stiffness_[scatter_[(p * K + i) * K + j]] += a * dot;
        }
    }
    for (const auto& bc : convective_)  // implicit convective term h A (T_a − T^{n+1})
      for (std::size_t j = 0; j < bc.nodes.size(); ++j)
        stiffness_[diagonal_[bc.nodes[j]]] += bc.coefficient * bc.areas[j];

    // A Dirichlet node has two increments: its particles must go from where they are to the
    // target (energy, node_dT_), while the conduction operator already saw the prescribed value
    // now, so the system eliminates it with target − now (constraint_dT_).
    const std::size_t nodes = node_volume_.size();
    std::fill(node_dT_.begin(), node_dT_.end(), 0.0);
    constraint_dT_.assign(nodes, 0.0);
    for (std::size_t i = 0; i < nodes; ++i)
      if (dirichlet_[i]) {
        node_dT_[i] = dirichlet_target_[i] - dirichlet_start_[i];
        constraint_dT_[i] = dirichlet_target_[i] - node_T_[i];
      }
    std::vector<double> nodal_capacity(nodes), solution(nodes);
    rhs_.assign(nodes, 0.0);
    const double tolerance = params_.real("nonlinear_tolerance");
    const long max_iterations = params_.integer("max_nonlinear_iterations");
    bool converged = false;
    long iteration = 0;
    while (iteration < max_iterations) {
      ++iteration;
      nodal_chord_capacity(nodal_capacity);
      // A = diag(V_i C̃_i/Δt) + K ; rhs = f^n ; Dirichlet rows eliminated symmetrically.
      matrix_values_ = stiffness_;
      for (std::size_t i = 0; i < nodes; ++i) {
        matrix_values_[diagonal_[i]] += node_volume_[i] * nodal_capacity[i] / dt_;
        rhs_[i] = node_volume_[i] > 0 ? node_force_[i] : 0.0;
      }
      eliminate_constraints();
      check_finite_system();
      system_->set_values(matrix_values_);
      for (std::size_t i = 0; i < nodes; ++i) solution[i] = is_fixed(i) ? constraint_dT_[i] : node_dT_[i];
      const SolveStats stats = system_->solve(rhs_, solution, /*rebuild_preconditioner=*/iteration == 1);
      linear_total_ += stats.iterations;
      // Chord-capacity Picard can cycle when the front sits on a node; past 10 iterations the
      // update is under-relaxed (0.5, then 0.25 past 30), which restores contraction.
      const double relax = iteration <= 10 ? 1.0 : iteration <= 30 ? 0.5 : 0.25;
      double change = 0;
      for (std::size_t i = 0; i < nodes; ++i) {
        if (is_fixed(i)) continue;
        change = std::max(change, std::abs(solution[i] - node_dT_[i]));
        node_dT_[i] += relax * (solution[i] - node_dT_[i]);
      }
      if (change <= tolerance) {
        converged = true;
        break;
      }
    }
    nonlinear_total_ += iteration;
    nonlinear_max_ = std::max(nonlinear_max_, iteration);
    if (!converged) ++unconverged_steps_;
    // Particle chords consistent with the converged increments.
    nodal_chord_capacity(nodal_capacity);
  }

  /// Rows of Dirichlet and empty nodes become identity; their known values move to the
  /// right-hand side of the other rows so the matrix stays symmetric for CG.
  void eliminate_constraints() {
    const auto& offsets = offsets_;
    const auto& columns = columns_;
    const std::size_t nodes = node_volume_.size();
    for (std::size_t i = 0; i < nodes; ++i) {
      const bool fixed_row = is_fixed(i);
      for (std::size_t e = offsets[i]; e < offsets[i + 1]; ++e) {
        const auto j = static_cast<std::size_t>(columns[e]);
        const bool fixed_col = is_fixed(j);
        if (fixed_row) {
          matrix_values_[e] = i == j ? 1.0 : 0.0;
        } else if (fixed_col) {
          rhs_[i] -= matrix_values_[e] * constraint_dT_[j];
          matrix_values_[e] = 0.0;
        }
      }
      if (fixed_row) rhs_[i] = constraint_dT_[i];
    }
  }
  bool is_fixed(std::size_t i) const { return dirichlet_[i] || node_volume_[i] <= 0; }

  /// A non-finite right-hand side (e.g. a boundary value that became NaN) stops the run with
  /// the node, time and step rather than reaching the linear solver.
  void check_finite_system() const {
    for (std::size_t i = 0; i < rhs_.size(); ++i)
      if (!std::isfinite(rhs_[i]) || !std::isfinite(matrix_values_[diagonal_[i]])) {
        const auto x = sim_->grid().node_position(i);
        std::ostringstream msg;
        msg << "numerical blow-up: temperature equation not finite at grid node " << i << " (x = " << x[0]
            << ", y = " << x[1] << ") at t = " << time_ << " s, step " << sim_->step() << " (dt = " << dt_
            << " s); check boundary values and material parameters";
        throw NumericalBlowUp(msg.str());
      }
  }
  // ---- particles ----------------------------------------------------------------------------
  void map_to_particles() {
    const auto& st = sim_->stencil();
    auto& particles = sim_->particles();
    const std::size_t n = particles.size();
    const int K = st.per_particle();
    auto T = particles.field("temperature");
    auto T_pic = particles.field("temperature_pic");
    auto S = particles.field("liquid_saturation");
    const auto phi = particles.field("porosity");
    const auto vol = particles.field("volume");
    energy_.resize(n);
    // Each particle takes the interpolated nodal temperature change at its own chord capacity:
    // ΔE_p = c_p Σ_i S_ip ΔT_i. Summed over particles this is exactly Σ_i V_i C̃_i ΔT_i, the
    // energy the nodes gained, and particles in different states cannot drift apart.
    for (std::size_t p = 0; p < n; ++p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      double dT = 0;
      for (int k = 0; k < K; ++k) dT += w[k] * node_dT_[nodes[k]];
      energy_[p] = particle_chord_[p] * dT;
    }
    for (const auto& r : particles.ranges()) {
      const int it = invert_heat(*sfcc_[r.material], constants_[r.material], phi.subspan(r.begin, r.size()),
                                 std::span<const double>(energy_).subspan(r.begin, r.size()),
                                 T.subspan(r.begin, r.size()), S.subspan(r.begin, r.size()));
      inversion_max_ = std::max<long>(inversion_max_, it);
    }
    if (subgrid_relaxation_ > 0) subgrid_exchange();
    // PIC temperature (Eq. 65) from the capacity-weighted nodal temperature at t^{n+1}.
    capacity_weighted_nodal_temperature(/*with_volume=*/false);
    for (std::size_t i = 0; i < node_T_.size(); ++i) {
      if (dirichlet_[i]) node_T_[i] = dirichlet_target_[i];
    }
    for (std::size_t p = 0; p < n; ++p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      double t = 0;
      for (int k = 0; k < K; ++k) t += w[k] * node_T_[nodes[k]];
      T_pic[p] = t;
    }
    if (flip_fraction_ < 1.0)
      for (std::size_t p = 0; p < n; ++p) T[p] = flip_fraction_ * T[p] + (1.0 - flip_fraction_) * T_pic[p];
    // Particles on a Dirichlet node take the PIC value, in which that node holds the prescribed
    // temperature: a FLIP increment there (target − mean of the node's particles) would push a
    // particle already at the boundary value past it. The boundary is an energy reservoir, so
    // nothing is lost that the physics conserves.
    for (std::size_t p = 0; p < n; ++p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      for (int k = 0; k < K; ++k)
        if (w[k] > 0 && dirichlet_[nodes[k]]) {
          T[p] = T_pic[p];
          break;
        }
    }
    apply_particle_dirichlet(time_ + dt_);
    properties_valid_ = false;
  }

  /// FLIP keeps any particle-scale deviation from the grid field forever (the grid cannot see
  /// it), e.g. the corners of a frozen inclusion. Here each particle exchanges heat with the
  /// grid field, q_p = −γ V_p c_p (T_p − Σ_i S_ip T_i), where T_i is the c-weighted nodal
  /// temperature and c_p the sensible capacity; then Σ_p q_p = 0 exactly, so energy is
  /// conserved, and extremes shrink. γ = 1 − exp(−Δt α_max/(r h²)) with r = subgrid_relaxation.
  void subgrid_exchange() {
    const auto& st = sim_->stencil();
    auto& particles = sim_->particles();
    const std::size_t n = particles.size();
    const int K = st.per_particle();
    auto T = particles.field("temperature");
    auto S = particles.field("liquid_saturation");
    const auto phi = particles.field("porosity");
    const auto vol = particles.field("volume");
    const double h = sim_->grid().min_spacing();
    const double gamma = 1.0 - std::exp(-dt_ * max_diffusivity_ / (subgrid_relaxation_ * h * h));
    // Weights: the sensible capacity C_m. With the latent peak in the weights, the few
    // particles inside the freezing window would dominate the mean and pull heat across a
    // sharp front. Any weights conserve energy as long as the mean uses the same ones.
    capacity_weighted_nodal_temperature(/*with_volume=*/false);
    for (std::size_t p = 0; p < n; ++p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      double mean = 0;
      for (int k = 0; k < K; ++k) mean += w[k] * node_T_[nodes[k]];
      energy_[p] = -gamma * capacity_[p] * (T[p] - mean);
    }
    for (const auto& r : particles.ranges())
      invert_heat(*sfcc_[r.material], constants_[r.material], phi.subspan(r.begin, r.size()),
                  std::span<const double>(energy_).subspan(r.begin, r.size()), T.subspan(r.begin, r.size()),
                  S.subspan(r.begin, r.size()));
  }

  void apply_particle_dirichlet(double time) {
    auto T = sim_->particles().field("temperature");
    auto T_pic = sim_->particles().field("temperature_pic");
    for (const auto& bc : particle_T_) {
      const double value = bc.value(time);
      for (std::size_t p : bc.particles) T[p] = T_pic[p] = value;
    }
  }
};

FROSTMPM_REGISTER(Physics, ThermalPhysics)

}  // namespace frostmpm::thermal

FROSTMPM_PLUGIN("frostmpm-thermal", "0.1.0")
