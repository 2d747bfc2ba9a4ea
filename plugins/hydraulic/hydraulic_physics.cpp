#include "hydraulic_physics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "frostmpm/models/pore_space.hpp"
#include "frostmpm/models/two_phase.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/plugin/plugin_api.hpp"
#include "frostmpm/transfer/nodal_interpolation.hpp"

namespace frostmpm::hydraulic {

ParamSchema HydraulicPhysics::schema() {
  ParamSchema s;
  s.real("reference_gravity", "m/s^2", "g in the drag n_l² ρ_l g / (K k_r): the gravity the hydraulic conductivity K "
                                       "[m/s] is defined with (not the body force)")
      .defaults_to(9.81)
      .above(0);
  s.choice("solver", {"cg", "gmres"}, "Krylov method of the pressure solve (the matrix is symmetric positive "
                                      "definite: CG; GMRES for comparison)")
      .defaults_to("cg");
  s.choice("preconditioner", {"none", "jacobi", "ilu", "multigrid"}, "preconditioner of the pressure solve")
      .defaults_to("multigrid");
  s.real("linear_tolerance", "-", "relative residual of the pressure solve").defaults_to(1e-8).above(0).below(1);
  s.integer("max_linear_iterations", "Krylov iterations per pressure solve before the run stops")
      .defaults_to(2000L)
      .at_least(1);
  s.boolean("phase_change_source", "count the water volume freezing and thawing give up or take, ζ φ ΔS_l "
             "(Eq. 48; the paper's Test C of Sec. 5.2.1 switches it off)")
      .defaults_to(true);
  s.real("stabilization", "-",
         "τ of the polynomial pressure projection (Eqs. 66–67): adds τ/(2G) ∫(S−ΠS)ᵀ(S−ΠS) dV · Δp/Δt, G the "
         "material's shear_modulus; damps checkerboard pressure modes; 0 switches it off")
      .defaults_to(1.0)
      .at_least(0);
  s.real("cavitation_pressure", "Pa",
         "lowest pore pressure (gauge) the water takes: below it the water cavitates, the nodes are held at this "
         "value and the volume they lack counts as vapour (hydraulic.cavitated_volume); about -1.0e5 for water "
         "at atmospheric pressure")
      .optional("no limit: the pore water takes any suction")
      .at_most(0)
      .at_least(-1e9);
  return s;
}

HydraulicPhysics::HydraulicPhysics(const ParamSet& p) : params_(p) {
  reference_gravity_ = p.real("reference_gravity");
  phase_change_source_ = p.boolean("phase_change_source");
  cavitation_ = p.has("cavitation_pressure");
  if (cavitation_) cavitation_pressure_ = p.real("cavitation_pressure");
}

ParamSchema HydraulicPhysics::material_schema() const {
  ParamSchema s;
  declare_pore_space_keys(s);  // shared with the thermal physics
  s.real("water_compressibility", "1/Pa", "compressibility of pore water c_w = 1/K_l (INTERFROST: 1e-8)")
      .defaults_to(4.6e-10)
      .at_least(0);
  declare_solid_thermal_expansion(s);
  s.real("water_thermal_expansion", "1/K", "volumetric thermal expansion of water β_l").defaults_to(0.0);
  s.real("ice_thermal_expansion", "1/K", "volumetric thermal expansion of ice β_c").defaults_to(0.0);
  s.real("shear_modulus", "Pa",
         "shear modulus G of the skeleton in the pressure stabilization τ/(2G); 0: a rigid skeleton (G → ∞), "
         "no stabilization")
      .defaults_to(0.0)
      .at_least(0);
  return s;
}

void HydraulicPhysics::setup(Kernel<kDim>& sim) {
  kernel_ = &sim;
  // The body force on the pore water is the scene's gravity; [0, 0] makes pressure the excess
  // (non-hydrostatic) pressure, as in the INTERFROST cases.
  gravity_ = sim.gravity();
  mass_scaling_ = sim.time_params().real("mass_scaling");
  transport_scaling_ = sim.time_params().real("transport_scaling");
  sim.declare_state_field("porosity", "1", 1, 0.0);
  sim.declare_state_field("pore_pressure", "Pa", 1, 0.0, /*max_magnitude=*/1e10);
  sim.declare_field("liquid_saturation", "1", 1, 1.0);  // 1 unless a thermal physics says otherwise
  sim.declare_field("liquid_velocity", "m/s", kDim, 0.0, FieldKind::Vector);
  sim.declare_field("water_flux", "m/s", kDim, 0.0, FieldKind::Vector);
  sim.declare_field("liquid_velocity_predicted", "m/s", kDim, 0.0, FieldKind::Vector);

  bool compressible = false;
  for (const auto& m : sim.materials()) {
    MaterialModels models;
    models.absolute = m.models.at("absolute_permeability").create<AbsolutePermeabilityModel>(sim.registry());
    if (m.models.count("relative_permeability"))
      models.relative = m.models.at("relative_permeability").create<RelativePermeabilityModel>(sim.registry());
    models.water_density = m.params.real("water_density");
    models.compressibility = m.params.real("water_compressibility");
    models.zeta = 1.0 - m.params.real("ice_density") / models.water_density;
    models.solid_expansion = m.params.real("solid_thermal_expansion");
    models.water_expansion = m.params.real("water_thermal_expansion");
    models.ice_expansion = m.params.real("ice_thermal_expansion");
    const double G = m.params.real("shear_modulus");
    models.stabilization = G > 0 ? params_.real("stabilization") / (2.0 * G) : 0.0;
    stabilized_ = stabilized_ || models.stabilization > 0;
    compressible = compressible || models.compressibility > 0;
    materials_.push_back(std::move(models));
  }
  sim.fill_from_materials("porosity", "porosity");
  material_ = sim.transfer().materials();
  read_boundaries(sim);
  update_pressure_nodes({});
  // A hydrostatic boundary acts on nodes, not on a material: it needs one water density.
  hydrostatic_density_ = materials_.front().water_density;
  for (const auto& bc : pressure_bcs_)
    if (bc.hydrostatic)
      for (const auto& m : sim.materials())
        if (m.params.real("water_density") != hydrostatic_density_)
          throw m.params.error("water_density", "a hydrostatic pore_pressure boundary (" + bc.label +
                                                    ") needs one water density in every material");
  if (!compressible && pressure_bcs_.empty())
    throw params_.section_error("with incompressible water (water_compressibility: 0 in every material) the "
                                "pressure is fixed only up to a constant: add a pore_pressure boundary condition");

  const std::size_t n = sim.particle_count(), nodes = sim.grid().node_count();
  for (auto* v : per_particle_arrays()) v->assign(n, 0.0);
  for (auto* v : {&node_mass_, &rhs_}) v->assign(nodes, 0.0);
}

namespace {
// Boundary values beyond these are typos or overflow, refused at setup (Pa and m/s).
constexpr double kMaxPressure = 1e10, kMaxWaterFlux = 1e3;
}  // namespace

std::vector<BoundaryType> HydraulicPhysics::boundary_type_docs() {
  std::vector<BoundaryType> types(2);
  types[0].name = "pore_pressure";
  types[0].doc = "a prescribed pore pressure (Eq. 19) on faces, node boxes or particles; on particles it holds the nodes "
                 "they make up at least half of, following the material as it moves (a drained surface inside the grid)";
  time_function_key(types[0].keys, "value", "-",
                    "the pressure [Pa], or with hydrostatic: true the water table's elevation [m]", kMaxPressure);
  types[0].keys.boolean("hydrostatic", "p = ρ_l g (h − y) below the water table h given as value (a suction above it)")
      .defaults_to(false);
  types[1].name = "water_flux";
  types[1].doc = "Darcy flux flowing into the domain (Eq. 22) through a face";
  time_function_key(types[1].keys, "value", "m/s", "the flux into the domain", kMaxWaterFlux);
  return types;
}

void HydraulicPhysics::read_boundaries(Kernel<kDim>& sim) {
  const auto types = boundary_type_docs();
  const auto keys = [&](const char* type) { return boundary_type(types, type).keys.names(); };
  const double end = sim.end_time();
  for (auto* bc : sim.boundary_conditions("pore_pressure")) {
    bc->accept_keys(keys("pore_pressure"));
    PressureCondition c;
    c.nodes = bc->nodes;
    c.particles = bc->particles;
    if (auto h = bc->node->optional_child("hydrostatic")) c.hydrostatic = h->as_bool();
    // Hydrostatic: the value is the water table's elevation.
    c.value = TimeFunction::read(bc->node->child("value"), c.hydrostatic ? "m" : "Pa", kMaxPressure, end);
    c.label = bc->label();
    pressure_bcs_.push_back(std::move(c));
  }
  for (auto* bc : sim.boundary_conditions("water_flux")) {
    bc->accept_keys(keys("water_flux"));
    const bool face = !bc->on_particles &&
                      std::any_of(bc->node_areas.begin(), bc->node_areas.end(), [](double a) { return a > 0; });
    if (!face) throw bc->node->error("water_flux acts on a grid face: use nodes: {face: ...}");
    flux_bcs_.push_back(
        {bc->nodes, bc->node_areas, TimeFunction::read(bc->node->child("value"), "m/s", kMaxWaterFlux, end), bc->label()});
  }
}

std::vector<double> HydraulicPhysics::boundary_pressures(const PressureCondition& c, double t) const {
  const double v = c.value(t);  // once per condition: a table or expression is not cheap
  std::vector<double> p(c.nodes.size(), v);
  for (std::size_t j = 0; j < c.nodes.size(); ++j) {
    const auto x = kernel_->grid().node_position(c.nodes[j]);
    if (c.hydrostatic) p[j] = hydrostatic_density_ * reference_gravity_ * (v - x[kDim - 1]);  // v: water table
    if (std::isfinite(p[j])) continue;
    std::ostringstream msg;
    msg << "numerical blow-up: pore pressure boundary value " << p[j] << " from the " << c.label << " (x = " << x[0]
        << ", y = " << x[1] << ") at t = " << t << " s, step " << kernel_->step() << " (dt = " << kernel_->dt()
        << " s); check the value's table or expression";
    throw NumericalBlowUp(msg.str());
  }
  return p;
}

/// A pore_pressure condition on particles holds the nodes those particles make up at least half
/// of (by volume), as a temperature condition on particles does: the surface's own nodes,
/// wherever the material has moved it (a drained slope face or ground surface inside the grid).
void HydraulicPhysics::update_pressure_nodes(const std::vector<double>& node_volume) {
  if (!node_volume.empty()) {
    const auto& st = kernel_->transfer().stencil();
    const auto vol = volume_.values();
    for (auto& bc : pressure_bcs_)
      if (!bc.particles.empty()) bc.nodes = nodes_made_up_by(bc.particles, st, vol, node_volume, condition_share_);
  }
  pressure_nodes_.clear();
  for (const auto& bc : pressure_bcs_) pressure_nodes_.insert(pressure_nodes_.end(), bc.nodes.begin(), bc.nodes.end());
  std::sort(pressure_nodes_.begin(), pressure_nodes_.end());
  pressure_nodes_.erase(std::unique(pressure_nodes_.begin(), pressure_nodes_.end()), pressure_nodes_.end());
}

void HydraulicPhysics::set_boundary_pressures(double t) {
  for (const auto& bc : pressure_bcs_) {
    const auto p = boundary_pressures(bc, t);
    for (std::size_t j = 0; j < bc.nodes.size(); ++j) (*p_)[bc.nodes[j]] = p[j];
  }
}

std::vector<Stage> HydraulicPhysics::stages() {
  const auto x = position_.read(), vol = volume_.read(), phi = porosity_.read(), S = saturation_.read(),
             p = pressure_.read(), v = velocity_.read(), v_star = predicted_.read();
  // The nodal pressure is the state while particles stand still: carried between steps.
  // Δp is carried too: it is the next solve's first guess, so a restart needs it to continue bit for bit.
  const auto p_node = node_pressure_.carried_write(), dp = node_increment_.carried_write();
  // The phase change and the thermal expansion need the temperature when a thermal physics has it.
  const auto T = temperature_field_.optional_read();
  // With a moving skeleton (its inertia and nodal velocities): the two-phase fractional step.
  const auto m_s = skeleton_inertia_.optional_read(), vs_star = node_solid_predicted_.optional_read(),
             vs = node_solid_velocity_.optional_read();
  Stage drag_stage{"hydraulic.drag", Phase::PredictMomentum, {node_pressure_.read(), v, m_s},
                   {liquid_drag_.write(), liquid_reaction_.write(), liquid_share_.write()}, [this] { drag(); }};
  drag_stage.skippable = true;  // only a skeleton that moves reads what it writes
  std::vector<FieldRef> pressure_writes{dp};
  if (cavitation_) pressure_writes.push_back(vapour_.write());  // the vapour: state of the pressure solve
  return {{"hydraulic.map_to_grid", Phase::MapToGrid, {x, vol, phi, S, p, T, m_s, node_solid_start_.optional_read()},
           {p_node},
           [this] { map_to_grid(); }},
          std::move(drag_stage),
          {"hydraulic.predict", Phase::PredictMomentum, {node_pressure_.read(), v, vs_star}, {predicted_.write()},
           [this] { predict(); }},
          {"hydraulic.pressure", Phase::Pressure,
           {v_star, node_pressure_.read(), vs_star, node_solid_mobility_.optional_read(),
            node_solid_group_.optional_read(), shear_modulus_.optional_read()},
           pressure_writes,
           [this] { solve_pressure(); }},
          {"hydraulic.correct", Phase::CorrectMomentum,
           {v_star, node_increment_.read(), node_pressure_.read(), vs, vs_star},
           {velocity_.write(), flux_.write(), p_node}, [this] { correct(); }},
          {"hydraulic.map_to_particles", Phase::MapToParticles, {node_pressure_.read(), node_increment_.read()},
           {pressure_.write()}, [this] { map_to_particles(); }}};
}

void HydraulicPhysics::initialize() {
  p_ = &node_pressure_.vector();
  dp_ = &node_increment_.vector();
  temperature_ = temperature_field_.bound();
  coupled_ = skeleton_inertia_.bound();
  moving_ = kernel_->particles_move();
  if (moving_) was_active_.assign(kernel_->grid().node_count(), 0);
  // The projection's G: the skeleton model's (a mechanical physics), else the material's.
  stabilized_ = stabilized_ || (shear_modulus_.bound() && params_.real("stabilization") > 0);
  if (stabilized_) {
    std::size_t cells = 1;
    for (int d = 0; d < kDim; ++d) cells *= static_cast<std::size_t>(kernel_->grid().cells[d]);
    cell_stabilization_.assign(cells, 0.0);
  }
  time_ = kernel_->time();
  update_coefficients();
  project_to_grid();
}

void HydraulicPhysics::begin_step(double time, double dt) {
  time_ = time;
  dt_ = dt;
}

// ---- coefficients and the grid state -----------------------------------------------------------

/// n_l = φ S_l, C_d = n_l² ρ_l g / (K k_r), ξ, η and the storage n_l c_w of every particle.
void HydraulicPhysics::update_coefficients() {
  const auto phi = porosity_.values();
  const auto S = saturation_.values();
  // The models in batches of a material's particles, which the threads share (models are pure
  // functions of their inputs: each batch is evaluated on its own, the same on any thread count).
  constexpr std::size_t kBatch = 512;
  for (const auto& r : kernel_->particle_ranges()) {
    const auto& m = materials_[r.material];
    parallel_chunks(r.size(), kBatch, [&](std::size_t offset, std::size_t count) {
      const std::size_t b = r.begin + offset;
      const std::span<const double> phi_b(phi.data() + b, count), S_b(S.data() + b, count);
      m.absolute->evaluate(phi_b, std::span<double>(k_a_.data() + b, count), std::span<double>(scratch_.data() + b, count));
      if (m.relative)
        m.relative->evaluate(S_b, phi_b, std::span<double>(k_r_.data() + b, count),
                             std::span<double>(scratch_.data() + b, count));
      else
        std::fill_n(k_r_.begin() + std::ptrdiff_t(b), count, 1.0);
    });
  }
  parallel_for(kernel_->particle_count(), [&](std::size_t p) {
    const auto& m = materials_[material_[p]];
    const double rho = m.water_density;
    n_l_[p] = phi[p] * std::clamp(S[p], 0.0, 1.0);
    const double conductivity = std::max(transport_scaling_ * k_a_[p] * k_r_[p], 1e-300);
    drag_[p] = n_l_[p] * n_l_[p] * rho * reference_gravity_ / conductivity;
    const double inertia = mass_scaling_ * (n_l_[p] * rho);
    xi_[p] = two_phase::liquid_response(inertia, drag_[p], dt_).xi;
    storage_[p] = n_l_[p] * m.compressibility;
    // The liquid's own response n_l/(m_l + Δt C_d) (= ξ/ρ_l: the corrector of a rigid skeleton)
    // and its Poisson coefficient η = n_l²/(m_l + Δt C_d), written so that Δt → 0 stays finite;
    // a moving skeleton adds its own response in the matrix (assemble_skeleton).
    mobility_[p] = two_phase::corrector_mobility(INFINITY, inertia, n_l_[p], drag_[p], dt_).liquid;
    eta_[p] = inertia > 0 ? n_l_[p] * n_l_[p] / (inertia + dt_ * drag_[p]) : 0.0;
  });
}

/// P2G of the particles' pressure (volume-weighted): the nodal state at the start, and
/// whenever standing particles were moved by something else (a restart). The grid holds the
/// state from then on.
void HydraulicPhysics::project_to_grid() {
  const auto& st = kernel_->transfer().stencil();
  project_particles(*p_);
  set_boundary_pressures(time_);
  projected_version_ = st.version();
  grid_valid_ = true;
}

/// The particles' pressure projected onto the nodes (volume-weighted), into `into`.
void HydraulicPhysics::project_particles(std::vector<double>& into) const {
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  const auto p = pressure_.values();
  std::vector<double> weight(into.size(), 0.0);
  std::fill(into.begin(), into.end(), 0.0);
  const int K = st.per_particle();
  kernel_->transfer().scatter([&](std::size_t q) {
    const auto* nodes = st.nodes(q);
    const auto* w = st.weights(q);
    for (int k = 0; k < K; ++k) {
      weight[nodes[k]] += w[k] * vol[q];
      into[nodes[k]] += w[k] * vol[q] * p[q];
    }
  });
  parallel_for(into.size(), [&](std::size_t i) { into[i] = weight[i] > 0 ? into[i] / weight[i] : 0.0; });
}

/// Moving particles: the grid keeps the pressure, and the material carries it across the fixed
/// nodes: p_i ← p_i − Δt v_s·∇p at every node the material covered last step (first-order
/// upwind on the lattice, with the skeleton's nodal velocity of the step's start); a node the
/// material newly reaches takes the particles' value. A P2G of the particles every step would
/// smooth the state once per step (the mechanics' steps are small: a large numerical diffusion),
/// and particles that carry it (FLIP) gather noise that deformation shows (measured in a
/// strip-loaded block).
void HydraulicPhysics::advect_grid_pressure() {
  const auto& grid = kernel_->grid();
  const std::size_t nodes = grid.node_count();
  std::vector<double> fresh;  // the particles' value, for nodes the material newly covers
  std::vector<char> active(nodes, 0);
  for (std::size_t i = 0; i < nodes; ++i) active[i] = node_mass_[i] > 0;
  bool any_new = false;
  for (std::size_t i = 0; i < nodes && !any_new; ++i) any_new = active[i] && was_active_[i] == 0;
  if (any_new) {
    fresh.assign(nodes, 0.0);
    project_particles(fresh);
  }
  const auto v = node_solid_start_.bound() ? node_solid_start_.values() : std::span<const double>{};
  std::vector<double> next(*p_);
  parallel_for(nodes, [&](std::size_t i) {
    if (!active[i]) return;
    if (was_active_[i] == 0) {
      next[i] = fresh[i];
      return;
    }
    if (v.empty()) return;
    const auto ijk = grid.node_lattice(i);
    double change = 0;
    for (int d = 0; d < kDim; ++d) {
      const double u = v[i * kDim + d];
      if (u == 0) continue;
      auto neighbour = ijk;
      neighbour[d] = grid.wrap(d, neighbour[d] + (u > 0 ? -1 : 1));  // upwind: where the material comes from
      if (neighbour[d] < -grid.ghost_layers || neighbour[d] > grid.cells[d] + grid.ghost_layers) continue;
      const std::size_t j = grid.node_index(neighbour);
      if (was_active_[j] == 0) continue;
      change -= dt_ * std::abs(u) * ((*p_)[i] - (*p_)[j]) / grid.spacing[d];
    }
    next[i] = (*p_)[i] + change;
  });
  *p_ = std::move(next);
  for (std::size_t i = 0; i < nodes; ++i) was_active_[i] = active[i];
}

/// source_p = [ζ φ ΔS_l − β_m ΔT] / Δt over the step that just ended (Eq. 48's
/// (ζ φ ∂S_l/∂T − β_m) Ṫ in secant form): the particles' S_l and T change at the end of a step,
/// so the pressure solve of step k+1 takes the change made in step k. The volume it removes
/// over a run is exactly ζ φ ΔS_l − β_m ΔT of every particle.
void HydraulicPhysics::update_source() {
  const auto phi = porosity_.values();
  const auto S = saturation_.values();
  const double* T = temperature_ ? temperature_field_.data() : nullptr;
  const auto vol = volume_.values();
  if (!primed_) {
    std::copy(S.begin(), S.end(), S_prev_.begin());
    if (T) std::copy(T, T + kernel_->particle_count(), T_prev_.begin());
    primed_ = true;
  }
  parallel_for(kernel_->particle_count(), [&](std::size_t p) {
    const auto& m = materials_[material_[p]];
    const double s = std::clamp(S[p], 0.0, 1.0), n_c = phi[p] * (1.0 - s);
    const double beta = (1.0 - phi[p]) * m.solid_expansion + phi[p] * s * m.water_expansion +
                        (1.0 - m.zeta) * n_c * m.ice_expansion;
    const double dT = T ? T[p] - T_prev_[p] : 0.0;
    const double zeta = phase_change_source_ ? m.zeta : 0.0;
    source_[p] = (zeta * phi[p] * (s - std::clamp(S_prev_[p], 0.0, 1.0)) - beta * dT) / dt_;
    S_prev_[p] = S[p];
    if (T) T_prev_[p] = T[p];
  });
  source_volume_ += dt_ * reproducible_sum(kernel_->particle_count(), [&](std::size_t p) { return vol[p] * source_[p]; });
}

void HydraulicPhysics::map_to_grid() {
  update_coefficients();
  update_source();
  const auto& st = kernel_->transfer().stencil();
  if (!grid_valid_ || (!moving_ && st.version() != projected_version_)) project_to_grid();
  // The liquid mass marks the nodes the pressure lives on: a node whose pores hold less than
  // kWetFraction liquid (none, or ice all but completely) has no unknown — its row would be
  // scaled like n_l² (1e-300 where an SFCC underflows) and break the Krylov solver. Other
  // physics read the flux at the particles (water_flux), where the pressure equation's
  // quadrature makes it mass-conserving: no nodal velocity is needed.
  constexpr double kWetFraction = 1e-12;
  // Nor does a node the material only grazes: a particle's domain that a rounding-sized move has
  // pushed across a node line overlaps the node's support by a sliver ε and gives it pores ∝ ε²,
  // a row some 1e-16 of the others, whose solved value is noise. The grid pressure's upwind
  // advection then carries that noise into the neighbour the material really covers. Measured
  // (rock freezing, β_s = 0, 5 mm cells): a node inside the borehole with 2e-19 kg of pore water
  // solved to −3e10 Pa, and 1e-9 m/s of skeleton velocity pulled its neighbour by 1e5 Pa a step
  // until the run stopped. Below kGrazeFraction of the largest particle's pores a node is empty.
  constexpr double kGrazeFraction = 1e-9;
  const auto vol = volume_.values();
  const auto phi = porosity_.values();
  std::fill(node_mass_.begin(), node_mass_.end(), 0.0);
  std::vector<double> pore_mass(node_mass_.size(), 0.0);
  const bool on_particles =
      std::any_of(pressure_bcs_.begin(), pressure_bcs_.end(), [](const auto& bc) { return !bc.particles.empty(); });
  std::vector<double> node_volume(on_particles ? node_mass_.size() : 0, 0.0);
  const int K = st.per_particle();
  kernel_->transfer().scatter([&](std::size_t q) {
    const auto* nodes = st.nodes(q);
    const auto* w = st.weights(q);
    const double pores = vol[q] * phi[q] * materials_[material_[q]].water_density;
    for (int k = 0; k < K; ++k) {
      node_mass_[nodes[k]] += w[k] * pores * (n_l_[q] / phi[q]);
      pore_mass[nodes[k]] += w[k] * pores;
      if (on_particles) node_volume[nodes[k]] += w[k] * vol[q];
    }
  });
  if (on_particles) update_pressure_nodes(node_volume);
  const double largest_pores = parallel_max(
      kernel_->particle_count(), [&](std::size_t q) { return vol[q] * phi[q] * materials_[material_[q]].water_density; },
      0.0);
  parallel_for(node_mass_.size(), [&](std::size_t i) {
    if (node_mass_[i] <= kWetFraction * pore_mass[i] || pore_mass[i] < kGrazeFraction * largest_pores) node_mass_[i] = 0.0;
  });
  if (moving_) advect_grid_pressure();
  // Boundary pressures at the step's start (a time function moves them between steps).
  set_boundary_pressures(time_);
}

/// At every particle, v* = (m_l v + Δt (−n_l ∇p(x_p) + n_l ρ_l b)) / (m_l + Δt C_d) — the liquid
/// momentum with implicit drag and the pressure of the step's start (Eq. 43 with the gradient
/// form of Eq. 14), at the material points (docs/architecture.md: why there) — plus, with a
/// moving skeleton, (1 − ξ) v_s*(x_p): what the drag makes the liquid follow (models/two_phase.hpp).
void HydraulicPhysics::predict() {
  const auto& st = kernel_->transfer().stencil();
  const auto v = velocity_.mutable_values();
  auto v_star = predicted_.mutable_values();
  const auto vs = coupled_ ? node_solid_predicted_.values() : std::span<const double>{};
  parallel_for(kernel_->particle_count(), [&](std::size_t q) {
    const auto grad = nodal_gradient_at(st, q, *p_);
    const double weight = n_l_[q] * materials_[material_[q]].water_density, inertia = mass_scaling_ * weight,
                 denominator = inertia + dt_ * drag_[q];
    for (int d = 0; d < kDim; ++d)
      v_star[q * kDim + d] =
          denominator > 0 ? (inertia * v[q * kDim + d] + dt_ * weight * gravity_[d] - dt_ * n_l_[q] * grad[d]) / denominator
                          : 0.0;
    if (!coupled_) return;
    const auto skeleton = kernel_->transfer().vector_at(q, vs);
    for (int d = 0; d < kDim; ++d) v_star[q * kDim + d] += (1.0 - xi_[q]) * skeleton[d];
  });
}

/// What the skeleton's predictor needs of the liquid, per unit volume: the drag stiffness
/// k = C_d ξ, the reaction R = k ṽ − f_l (the liquid's share of the mixture forces, its drag
/// at the free velocity ṽ = v + Δt f_l/m_l) and n_l ξ, the liquid's own share of a pressure
/// gradient (models/two_phase.hpp).
void HydraulicPhysics::drag() {
  const auto& st = kernel_->transfer().stencil();
  const auto v = velocity_.values();
  auto k = liquid_drag_.mutable_values();
  auto R = liquid_reaction_.mutable_values();
  auto share = liquid_share_.mutable_values();
  parallel_for(kernel_->particle_count(), [&](std::size_t q) {
    const auto grad = nodal_gradient_at(st, q, *p_);
    const double weight = n_l_[q] * materials_[material_[q]].water_density, inertia = mass_scaling_ * weight,
                 denominator = inertia + dt_ * drag_[q];
    k[q] = drag_[q] * xi_[q];  // two_phase::liquid_response's k = C_d ξ, with its ξ (update_coefficients)
    share[q] = n_l_[q] * xi_[q];
    for (int d = 0; d < kDim; ++d) {
      const double f = weight * gravity_[d] - n_l_[q] * grad[d];  // f_l
      const double k_free = denominator > 0 ? drag_[q] * (inertia * v[q * kDim + d] + dt_ * f) / denominator : 0.0;
      R[q * kDim + d] = k_free - f;
    }
  });
}

/// v = v* − Δt ξ/ρ_l ∇Δp(x_p) at every particle (Eq. 47); with a moving skeleton the liquid also
/// follows the skeleton's correction through the drag: + (1 − ξ) Δv_s(x_p) (models/two_phase.hpp);
/// p_i += Δp_i; the Darcy flux q = n_l (v − v_s). The pressure solve made Σ_p V_p ∇S_ip · q_p
/// balance storage, sources, the skeleton's volume change and boundary inflow exactly.
void HydraulicPhysics::correct() {
  const auto& st = kernel_->transfer().stencil();
  const auto v_star = predicted_.mutable_values();
  auto v = velocity_.mutable_values();
  auto flux = flux_.mutable_values();
  const auto vs = coupled_ ? node_solid_velocity_.values() : std::span<const double>{};
  const auto vs_star = coupled_ ? node_solid_predicted_.values() : std::span<const double>{};
  parallel_for(kernel_->particle_count(), [&](std::size_t q) {
    const auto grad = nodal_gradient_at(st, q, *dp_);
    if (!coupled_) {
      const double a = dt_ * xi_[q] / (mass_scaling_ * materials_[material_[q]].water_density);
      for (int d = 0; d < kDim; ++d) {
        v[q * kDim + d] = v_star[q * kDim + d] - a * grad[d];
        flux[q * kDim + d] = n_l_[q] * v[q * kDim + d];
      }
      return;
    }
    const auto skeleton = kernel_->transfer().vector_at(q, vs);
    const auto predicted = kernel_->transfer().vector_at(q, vs_star);
    for (int d = 0; d < kDim; ++d) {
      v[q * kDim + d] = v_star[q * kDim + d] + (1.0 - xi_[q]) * (skeleton[d] - predicted[d]) -
                        dt_ * mobility_[q] * grad[d];
      flux[q * kDim + d] = n_l_[q] * (v[q * kDim + d] - skeleton[d]);
    }
    // The volume this step's balance left out, for the next step (ice_weight_, header); none
    // without ice or ζ. A volume, not a rate: the next step may be longer or shorter.
    if (ice_weight_[q] == 0) {
      melt_carried_[q] = 0;
      return;
    }
    const auto stretch_end = kernel_->transfer().gradient_diagonal_at(q, vs);
    const auto stretch_predicted = kernel_->transfer().gradient_diagonal_at(q, vs_star);
    double correction = 0;
    for (int d = 0; d < kDim; ++d) correction += stretch_end[d] - stretch_predicted[d];
    melt_carried_[q] = -ice_weight_[q] * correction * dt_;
  });
  parallel_for(p_->size(), [&](std::size_t i) { (*p_)[i] += (*dp_)[i]; });
  account_boundary_inflow();
}

/// Particle pressure from the nodes (the grid holds the state while particles stand still).
void HydraulicPhysics::map_to_particles() {
  const auto& st = kernel_->transfer().stencil();
  auto p = pressure_.mutable_values();
  parallel_for(p.size(), [&](std::size_t a) { p[a] = nodal_value_at(st, a, *p_); });
}

// ---- checkpoints and counters ----------------------------------------------------------------------

std::vector<PersistentArray> HydraulicPhysics::persistent_state() {
  saved_scalars_ = {double(solves_), double(iterations_total_), double(iterations_max_), residual_max_};
  saved_scalars_.push_back(double(preconditioner_updates_));
  saved_scalars_.insert(saved_scalars_.end(), {source_volume_, boundary_inflow_, primed_ ? 1.0 : 0.0, removed_water_});
  saved_scalars_.insert(saved_scalars_.end(), {system_ ? 1.0 : 0.0, preconditioner_built_ ? 1.0 : 0.0,
                                               refresh_due_ ? 1.0 : 0.0, double(iterations_after_refresh_)});
  saved_scalars_.insert(saved_scalars_.end(), {cavitated_volume_, double(cavitated_nodes_max_), unresolved_volume_});
  saved_groups_ = {double(graph_groups_.size())};
  for (const auto& group : graph_groups_) {
    saved_groups_.push_back(double(group.size()));
    saved_groups_.insert(saved_groups_.end(), group.begin(), group.end());
  }
  saved_source_ = system_ ? system_->preconditioner_source() : PreconditionerSource{};
  return {{"scalars", &saved_scalars_},          {"step_iterations", &step_iterations_},
          {"step_residuals", &step_residuals_},  {"saturation_at_step_start", &S_prev_},
          {"skeleton_volume_carried", &melt_carried_},
          {"nodes_with_material", &was_active_},
          {"temperature_at_step_start", &T_prev_},
          {"pressure_graph_plate_rows", &saved_groups_},
          {"preconditioner_built_from", &saved_source_.built},
          {"preconditioner_refreshed_from", &saved_source_.refreshed}};
}

void HydraulicPhysics::restored() {
  const auto& s = saved_scalars_;
  // 13: written before the cavitation limit existed (its counters start at zero).
  if (s.size() != 16 && s.size() != 13)
    throw std::runtime_error("hydraulic: checkpoint holds " + std::to_string(s.size()) + " scalars, expected 16");
  cavitated_volume_ = s.size() > 13 ? s[13] : 0.0;
  cavitated_nodes_max_ = s.size() > 13 ? long(s[14]) : 0;
  unresolved_volume_ = s.size() > 13 ? s[15] : 0.0;
  // The pressure system as it was: assemble() builds it with the saved plate rows and rebuilds
  // the preconditioner from the values it was made from; the next solve starts from the carried Δp.
  restore_system_ = s[9] != 0;
  preconditioner_built_ = s[10] != 0;
  refresh_due_ = s[11] != 0;
  iterations_after_refresh_ = long(s[12]);
  graph_groups_.clear();
  if (!saved_groups_.empty()) {
    std::size_t at = 1;
    for (std::size_t g = 0; g < std::size_t(saved_groups_[0]); ++g) {
      const std::size_t size = std::size_t(saved_groups_.at(at++));
      graph_groups_.emplace_back();
      for (std::size_t k = 0; k < size; ++k) graph_groups_.back().push_back(std::size_t(saved_groups_.at(at++)));
    }
  }
  removed_water_ = s[8];
  preconditioner_updates_ = long(s[4]);
  source_volume_ = s[5];
  boundary_inflow_ = s[6];
  primed_ = s[7] != 0;
  solves_ = long(s[0]);
  iterations_total_ = long(s[1]);
  iterations_max_ = long(s[2]);
  residual_max_ = s[3];
  // The nodal state came back with the kernel's carried node fields; it belongs to this stencil.
  projected_version_ = kernel_->transfer().version();
  grid_valid_ = true;
  if (!restore_system_) std::fill(dp_->begin(), dp_->end(), 0.0);  // no solve yet: no first guess
}

/// Writing a checkpoint leaves the solver as it was (the checkpoint holds what rebuilds it).
void HydraulicPhysics::checkpoint_written() {
  saved_source_ = {};  // the copies persistent_state() made
  saved_groups_.clear();
}

std::vector<std::pair<std::string, double>> HydraulicPhysics::statistics() const {
  return {{"hydraulic.pressure_solves", double(solves_)},
          {"hydraulic.linear_iterations_total", double(iterations_total_)},
          {"hydraulic.linear_iterations_max", double(iterations_max_)},
          {"hydraulic.linear_iterations_mean", solves_ ? double(iterations_total_) / double(solves_) : 0.0},
          {"hydraulic.relative_residual_max", residual_max_},
          {"hydraulic.preconditioner_updates", double(preconditioner_updates_)},
          {"hydraulic.solve_seconds", solve_seconds_},
          {"hydraulic.preconditioner_seconds", preconditioner_seconds_},
          {"hydraulic.source_volume", source_volume_},
          {"hydraulic.boundary_inflow_volume", boundary_inflow_},
          {"hydraulic.water_removed_volume", removed_water_},
          {"hydraulic.cavitated_volume", cavitated_volume_},
          {"hydraulic.cavitated_nodes_max", double(cavitated_nodes_max_)},
          {"hydraulic.cavitation_unresolved_volume", unresolved_volume_}};
}

void HydraulicPhysics::removing_particles(const ParticleRemoval& removal) {
  if (!removal.restoring) {
    const auto vol = volume_.values();
    for (std::size_t p = 0; p < removal.leaving.size(); ++p)
      if (removal.leaving[p]) removed_water_ += vol[p] * n_l_[p];  // liquid water [m³ per m]
  }
  for (auto* v : per_particle_arrays()) removal.compact(*v);
  material_ = material_.first(removal.remaining);  // the kernel compacts its storage in place
}

FROSTMPM_REGISTER(Physics, HydraulicPhysics)
FROSTMPM_REGISTER_BOUNDARY_TYPES(HydraulicPhysics)

}  // namespace frostmpm::hydraulic

FROSTMPM_PLUGIN("frostmpm-hydraulic", "0.1.0")
