// The thermal physics: parameters, set-up, boundaries, the grid state and the particle update.
// The two time schemes are in explicit_step.cpp and implicit_step.cpp; the design in
// thermal_physics.hpp.
#include "thermal_physics.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm::thermal {

ParamSchema ThermalPhysics::schema() {
  ParamSchema s;
  s.choice("scheme", {"explicit", "implicit"}, "time integration: explicit (paper) or backward Euler")
      .defaults_to("explicit");
  s.choice("conductivity_average", {"arithmetic", "geometric"}, "mixing rule for κ_m").defaults_to("arithmetic");
  s.choice("latent_heat_density", {"ice", "water"}, "density multiplying L_f (paper: ice; Kurylyk/INTERFROST: water)")
      .defaults_to("ice");
  s.choice("property_temperature", {"pic", "flip"}, "temperature that feeds κ_m (paper: pic)").defaults_to("pic");
  s.real("flip_fraction", "-",
         "particle update, as a blend of heat contents: 1 = FLIP (Eq. 64), 0 = PIC (Eq. 65); the fraction "
         "of each particle's sub-grid deviation from the grid field kept per step")
      .defaults_to(1.0).at_least(0).at_most(1);
  s.real("subgrid_relaxation", "-",
         "sub-grid exchange: particle deviations from the grid field relax over this many cell "
         "diffusion times h^2/alpha, energy-conservatively; 0 = off (pure FLIP). Use ~10 when "
         "initial fields jump inside a cell")
      .defaults_to(0.0).at_least(0);
  s.real("cfl", "-", "explicit: fraction of the diffusion stability limit used as Δt").defaults_to(0.5).above(0).at_most(1);
  s.real("advection_cfl", "-",
         "with a water flux: fraction of the convective term's stability limit 2α/u² used as Δt (both schemes)")
      .defaults_to(0.9)
      .above(0)
      .at_most(1);
  s.real("nonlinear_tolerance", "K",
         "implicit: Newton stops when every node's energy residual is worth less than this much "
         "sensible heat")
      .defaults_to(1e-6).above(0);
  s.integer("max_nonlinear_iterations", "implicit: Newton iterations before the step is retried in two halves")
      .defaults_to(25L).at_least(2);
  s.integer("max_step_halvings", "implicit: how often a failing step may be halved before the run stops")
      .defaults_to(12L).at_least(0).at_most(40);
  s.choice("preconditioner", {"jacobi", "ilu", "multigrid", "none"}, "implicit: preconditioner for CG")
      .defaults_to("jacobi");
  s.real("linear_tolerance", "-", "implicit: relative residual of each Newton step's linear solve")
      .defaults_to(1e-10).above(0);
  return s;
}

ThermalPhysics::ThermalPhysics(const ParamSet& p) : params_(p) {
  implicit_ = p.string("scheme") == "implicit";
  flip_fraction_ = p.real("flip_fraction");
  pic_properties_ = p.string("property_temperature") == "pic";
  cfl_ = p.real("cfl");
  advection_cfl_ = p.real("advection_cfl");
  subgrid_relaxation_ = p.real("subgrid_relaxation");
  nonlinear_tolerance_ = p.real("nonlinear_tolerance");
  max_nonlinear_iterations_ = p.integer("max_nonlinear_iterations");
  max_step_halvings_ = p.integer("max_step_halvings");
}

void ThermalPhysics::setup(Kernel<kDim>& sim) {
  kernel_ = &sim;
  transport_scaling_ = sim.time_params().real("transport_scaling");
  sim.declare_state_field("temperature", "degC", 1, 0.0, /*max_magnitude=*/1e4);
  sim.declare_state_field("porosity", "1", 1, 0.0);
  sim.declare_field("temperature_pic", "degC");
  sim.declare_field("liquid_saturation", "1", 1, 1.0);
  sim.declare_field("heat_deviation", "J/m^3");  // heat content minus the grid field's, per volume

  const auto average = params_.string("conductivity_average") == "geometric" ? ConductivityAverage::Geometric
                                                                            : ConductivityAverage::Arithmetic;
  const bool water = params_.string("latent_heat_density") == "water";
  std::vector<const EnthalpyTable*> tables;
  for (const auto& m : sim.materials()) {
    constants_.push_back(phase_constants(m.params, average, water));
    const auto sfcc = m.models.at("sfcc").create<SfccModel>(sim.registry());
    try {
      tables_.push_back(std::make_unique<EnthalpyTable>(*sfcc, constants_.back(), EnthalpyTable::Options{}));
    } catch (const std::runtime_error& e) {
      throw InputError(m.models.at("sfcc").where, e.what());
    }
    tables.push_back(tables_.back().get());
  }
  sim.fill_from_materials("porosity", "porosity");
  material_ = sim.transfer().materials();
  read_boundaries(sim);
  if (implicit_ && sim.fixed_dt() <= 0)
    throw sim.time_params().error("dt", "physics.thermal: the implicit scheme needs a fixed step: set time.dt (seconds)");

  const std::size_t nodes = sim.grid().node_count();
  for (auto* v : {&node_volume_, &node_heat_, &node_force_, &node_pending_, &dirichlet_target_})
    v->assign(nodes, 0.0);
  node_pore_heat_.assign(tables.size(), std::vector<double>(nodes, 0.0));
  dirichlet_.assign(nodes, 0);
  nodal_.configure(tables, nodes);
  const std::size_t n = sim.particle_count();
  conductivity_.assign(n, 0.0);
  energy_.assign(n, 0.0);
  hint_.resize(n);
  for (std::size_t p = 0; p < n; ++p) hint_[p] = tables_[material_[p]]->freezing_interval();
}

std::vector<Stage> ThermalPhysics::stages() {
  // What other physics may use: the nodal temperature (node field 'temperature', after the
  // solve the end-of-step value) and the particle fields. The nodal heat content and the
  // step's work arrays stay private.
  const auto T = temperature_.read(), d = deviation_.read(), phi = porosity_.read(), vol = volume_.read(),
             x = position_.read();
  return {{"thermal.map_to_grid", Phase::MapToGrid, {x, vol, phi, T, d}, {node_temperature_.write()},
           [this] { map_to_grid(); }},
          // The convective term ρ_l c_l q·∇T, when some physics provides the Darcy flux q.
          {"thermal.solve", Phase::Energy, {node_temperature_.read(), water_flux_.optional_read()},
           {node_temperature_.write()}, [this] { implicit_ ? solve_implicit() : solve_explicit(); }},
          {"thermal.map_to_particles", Phase::MapToParticles,
           {node_temperature_.read(), x, vol, phi, T, d, solid_velocity_.optional_read()},
           {temperature_.write(), deviation_.write(), temperature_pic_.write(), saturation_.write()},
           [this] { map_to_particles(); }}};
}

namespace {
// Boundary values beyond these are typos or overflow, refused at setup (°C and W/m²).
constexpr double kMaxTemperature = 1e4, kMaxHeatFlux = 1e9;
}  // namespace

std::vector<BoundaryType> ThermalPhysics::boundary_type_docs() {
  std::vector<BoundaryType> types(3);
  types[0].name = "temperature";
  types[0].doc = "a prescribed temperature (Eq. 20) on faces, node boxes or particles; on particles it holds them and the "
                 "nodes they make up at least half of, following the material as it moves";
  time_function_key(types[0].keys, "value", "degC", "the temperature", kMaxTemperature);
  types[1].name = "heat_flux";
  types[1].doc = "heat flowing into the domain (Eq. 23) through a face, or through the surface particles stand for";
  time_function_key(types[1].keys, "value", "W/m^2", "the flux into the domain", kMaxHeatFlux);
  types[1].keys.real("area", "m^2", "on particles only: the surface they stand for (per m in 2-D), shared by volume")
      .optional("a face's own area").above(0).at_most(1e6);
  types[2].name = "convective";
  types[2].doc = "h (T_a − T) into the domain (Eq. 24) through a face, or through the surface particles stand for";
  types[2].keys.real("h", "W/(m^2 K)", "heat transfer coefficient").above(0);
  time_function_key(types[2].keys, "ambient", "degC", "the ambient temperature T_a", kMaxTemperature);
  types[2].keys.real("area", "m^2", "on particles only: the surface they stand for (per m in 2-D), shared by volume")
      .optional("a face's own area").above(0).at_most(1e6);
  return types;
}

void ThermalPhysics::read_boundaries(Kernel<kDim>& sim) {
  const auto types = boundary_type_docs();
  const auto keys = [&](const char* type) { return boundary_type(types, type).keys.names(); };
  const double end = sim.end_time();
  for (auto* bc : sim.boundary_conditions("temperature")) {
    bc->accept_keys(keys("temperature"));
    TimeFunction value = TimeFunction::read(bc->node->child("value"), "degC", kMaxTemperature, end);
    if (bc->on_particles) particle_T_.push_back({bc->particles, value, bc->label()});
    else fixed_T_.push_back({bc->nodes, bc->node_areas, value, 0, bc->label()});
  }
  // A surface condition acts on a grid face, or on particles standing for a surface inside the
  // grid (a borehole's wall): `area` is that surface [m², per m in 2-D], shared among the
  // particles in proportion to their volume and handed to the nodes through their weights.
  auto surface = [&](const BoundaryCondition* bc, std::vector<NodeCondition>& list) {
    if (bc->on_particles) {
      const ConfigNode area = bc->node->child("area");
      const double value = area.as_real("m^2");
      if (!(value > 0) || value > 1e6)
        throw area.error("the surface the particles stand for must be positive (m², per m in 2-D), got " + area.as_string());
      particle_surfaces_.push_back({bc->particles, value, &list, list.size()});
      return;
    }
    if (bc->node->has("area")) throw bc->node->child("area").error("area belongs to a condition on particles; a face has its own");
    if (!std::any_of(bc->node_areas.begin(), bc->node_areas.end(), [](double a) { return a > 0; }))
      throw bc->node->error(bc->type + " acts on a grid face or on particles: use nodes: {face: ...} or particles: SHAPE with area:");
  };
  for (auto* bc : sim.boundary_conditions("heat_flux")) {
    bc->accept_keys(keys("heat_flux"));
    surface(bc, flux_);
    flux_.push_back(
        {bc->nodes, bc->node_areas, TimeFunction::read(bc->node->child("value"), "W/m^2", kMaxHeatFlux, end), 0.0, bc->label()});
  }
  for (auto* bc : sim.boundary_conditions("convective")) {
    bc->accept_keys(keys("convective"));
    surface(bc, convective_);
    const ConfigNode h = bc->node->child("h");
    const double coefficient = h.as_real("W/(m^2 K)");
    if (!(coefficient > 0)) throw h.error("heat transfer coefficient h must be positive (W/m^2/K)");
    convective_.push_back(
        {bc->nodes, bc->node_areas, TimeFunction::read(bc->node->child("ambient"), "degC", kMaxTemperature, end), coefficient, bc->label()});
  }
}

/// The nodes and areas of surface conditions on particles, from the particles' volumes and
/// weights: A_i = Σ_p S_ip A V_p / Σ_q V_q. Once per stencil (the particles moved or not).
void ThermalPhysics::update_particle_surfaces() {
  const auto& st = kernel_->transfer().stencil();
  if (particle_surfaces_.empty() || surfaces_version_ == st.version()) return;
  surfaces_version_ = st.version();
  const auto vol = volume_.values();
  const int K = st.per_particle();
  std::vector<double> area(kernel_->grid().node_count(), 0.0);
  for (const auto& s : particle_surfaces_) {
    double total = 0;
    for (std::size_t p : s.particles) total += vol[p];
    if (!(total > 0)) {  // every particle of the surface left the grid
      (*s.list)[s.index].nodes.clear();
      (*s.list)[s.index].areas.clear();
      continue;
    }
    for (std::size_t p : s.particles)
      for (int k = 0; k < K; ++k) area[st.nodes(p)[k]] += st.weights(p)[k] * s.area * vol[p] / total;
    auto& c = (*s.list)[s.index];
    c.nodes.clear();
    c.areas.clear();
    for (std::size_t i = 0; i < area.size(); ++i)
      if (area[i] > 0) {
        c.nodes.push_back(i);
        c.areas.push_back(area[i]);
        area[i] = 0;
      }
  }
}

double ThermalPhysics::value_at(const TimeFunction& f, const std::string& label, std::array<double, kDim> place,
                                double t) const {
  const double v = f(t);
  if (std::isfinite(v)) return v;
  std::ostringstream msg;
  msg << "numerical blow-up: temperature boundary value " << v << " from the " << label << " (x = " << place[0]
      << ", y = " << place[1] << ") at t = " << t << " s, step " << kernel_->step() << " (dt = " << kernel_->dt()
      << " s); check the value's table or expression";
  throw NumericalBlowUp(msg.str());
}

double ThermalPhysics::value_at(const NodeCondition& c, double t) const {
  return value_at(c.value, c.label, c.nodes.empty() ? std::array<double, kDim>{} : kernel_->grid().node_position(c.nodes[0]), t);
}

double ThermalPhysics::value_at(const ParticleCondition& c, double t) const {
  std::array<double, kDim> place{};
  if (!c.particles.empty())
    for (int d = 0; d < kDim; ++d) place[d] = position_.values()[c.particles[0] * kDim + d];
  return value_at(c.value, c.label, place, t);
}

// ---- particles ---------------------------------------------------------------------------------

/// κ_p at the property temperature.
void ThermalPhysics::evaluate_particle_properties(std::size_t p, double phi, double T_property) {
  const auto& table = *tables_[material_[p]];
  const int h = table.locate(T_property, hint_[p]);
  conductivity_[p] = transport_scaling_ *
                     constants_[material_[p]].conductivity(phi, std::clamp(table.saturation(T_property, h), 0.0, 1.0));
}

double ThermalPhysics::particle_heat(std::size_t p, std::span<const double> T, std::span<const double> phi,
                                     std::span<const double> vol) const {
  int h = hint_[p];
  return vol[p] * tables_[material_[p]]->heat(sensible(p, phi[p]), phi[p], T[p], h);
}

double ThermalPhysics::particle_heat_total() const {
  const auto T = temperature_.values();
  const auto phi = porosity_.values();
  const auto vol = volume_.values();
  return reproducible_sum(kernel_->particle_count(), [&](std::size_t p) { return particle_heat(p, T, phi, vol); });
}

void ThermalPhysics::removing_particles(const ParticleRemoval& removal) {
  if (!removal.restoring && initialized_) {
    // The heat the leaving particles carry: stored + removed = entered stays closed.
    const auto T = temperature_.values();
    const auto phi = porosity_.values();
    const auto vol = volume_.values();
    double heat = 0;
    for (std::size_t p = 0; p < removal.leaving.size(); ++p)
      if (removal.leaving[p]) heat += particle_heat(p, T, phi, vol);
    removed_heat_ += heat;
    if (heat_after_step_valid_) heat_after_step_ -= heat;  // not a change by deformation
  }
  removal.compact(conductivity_);
  removal.compact(energy_);
  removal.compact(hint_);
  for (auto& c : particle_T_) removal.remap(c.particles);
  for (auto& s : particle_surfaces_) removal.remap(s.particles);
  surfaces_version_ = ~std::uint64_t{0};
  material_ = material_.first(removal.remaining);  // the kernel compacts its storage in place
}

void ThermalPhysics::initialize() {
  node_T_ = &node_temperature_.vector();
  advection_ = water_flux_.bound();
  if (advection_) advection_force_.assign(node_T_->size(), 0.0);
  auto T = temperature_.mutable_values();
  auto T_pic = temperature_pic_.mutable_values();
  auto S = saturation_.mutable_values();
  const auto phi = porosity_.values();
  apply_particle_dirichlet(kernel_->time(), /*count_heat=*/false);
  // Before any step the PIC temperature is the initial temperature.
  std::copy(T.begin(), T.end(), T_pic.begin());
  parallel_for(kernel_->particle_count(), [&](std::size_t p) {
    const auto& table = *tables_[material_[p]];
    hint_[p] = table.locate(T[p], hint_[p]);
    S[p] = table.saturation(T[p], hint_[p]);
    evaluate_particle_properties(p, phi[p], T[p]);
  });
  update_step_limits();
  project_to_grid(/*with_heat=*/true);
  initial_heat_ = particle_heat_total();
  initialized_ = true;
}

void ThermalPhysics::begin_step(double time, double dt) {
  if (!initialized_) initialize();
  time_ = time;
  dt_ = dt;
}

double ThermalPhysics::stable_time_step() const {
  if (!initialized_) const_cast<ThermalPhysics*>(this)->initialize();
  // The convective term is explicit (the flux of the step's start) in both schemes: with
  // central differences it is stable while Δt ≤ 2α/u², u = ρ_l c_l |q| / C (von Neumann, with
  // the diffusion explicit or implicit), whatever the cell size.
  double dt = std::numeric_limits<double>::infinity();
  if (advection_) {
    const auto q = water_flux_.values();
    const auto phi = porosity_.values();
    dt = advection_cfl_ * parallel_min(
                    conductivity_.size(),
                    [&](std::size_t p) {
                      double q2 = 0;
                      for (int d = 0; d < kDim; ++d) q2 += q[p * kDim + d] * q[p * kDim + d];
                      const double Cw = constants_[material_[p]].water_capacity;
                      return q2 > 0 ? 2.0 * conductivity_[p] * sensible_capacity(p, phi[p]) / (Cw * Cw * q2)
                                    : std::numeric_limits<double>::infinity();
                    },
                    std::numeric_limits<double>::infinity());
  }
  if (implicit_) return dt;
  const double h = kernel_->grid().min_spacing();
  dt = std::min(dt, cfl_ * h * h / (2.0 * kDim * max_diffusivity_));
  // A convective face is a spring h·A on the node: keep Δt below C V_i/(h A_i) ≈ C (Δx/2)/h.
  for (const auto& bc : convective_) dt = std::min(dt, cfl_ * min_capacity_ * 0.5 * h / bc.coefficient);
  return dt;
}

// ---- grid state --------------------------------------------------------------------------------

/// P2G of the nodal volume and heat-function coefficients (a_i, b_im) and, with `with_heat`,
/// of the particles' heat contents: the grid state is then re-derived from the particles, and
/// every particle's deviation from it recomputed.
void ThermalPhysics::project_to_grid(bool with_heat) {
  const auto& st = kernel_->transfer().stencil();
  const std::size_t n = kernel_->particle_count();
  const auto T = temperature_.values();
  const auto phi = porosity_.values();
  const auto vol = volume_.values();
  if (with_heat)
    parallel_for(n, [&](std::size_t p) {
      energy_[p] = tables_[material_[p]]->heat(sensible(p, phi[p]), phi[p], T[p], hint_[p]);
    });
  std::fill(node_volume_.begin(), node_volume_.end(), 0.0);
  std::fill(nodal_.sensible.begin(), nodal_.sensible.end(), 0.0);
  for (auto& b : nodal_.pore) std::fill(b.begin(), b.end(), 0.0);
  if (with_heat) std::fill(node_heat_.begin(), node_heat_.end(), 0.0);
  const int K = st.per_particle();
  kernel_->transfer().scatter([&](std::size_t p) {
    const auto* nodes = st.nodes(p);
    const auto* w = st.weights(p);
    const double a = vol[p] * sensible(p, phi[p]), b = vol[p] * phi[p], e = vol[p] * energy_[p];
    auto& pore = nodal_.pore[material_[p]];
    for (int k = 0; k < K; ++k) {
      node_volume_[nodes[k]] += vol[p] * w[k];
      nodal_.sensible[nodes[k]] += a * w[k];
      pore[nodes[k]] += b * w[k];
      if (with_heat) node_heat_[nodes[k]] += e * w[k];
    }
  });
  parallel_for(node_volume_.size(), [&](std::size_t i) {
    const double V = node_volume_[i];
    if (V <= 0) {
      nodal_.material[i] = NodalHeat::kEmpty;
      node_heat_[i] = (*node_T_)[i] = 0;
      return;
    }
    nodal_.sensible[i] /= V;
    for (auto& b : nodal_.pore) b[i] /= V;
    if (with_heat) node_heat_[i] /= V;
    nodal_.classify(i);
  });
  grid_stencil_version_ = st.version();
  if (!with_heat) return;
  invert_nodes();
  update_node_pore_heat();
  // d_p = H_p(T_p) − Σ_i S_ip H_p(T_i): what the grid field cannot represent.
  auto d = deviation_.mutable_values();
  parallel_for(n, [&](std::size_t p) {
    const auto* nodes = st.nodes(p);
    const auto* w = st.weights(p);
    const auto& G = node_pore_heat_[material_[p]];
    double T_mean = 0, G_mean = 0;
    for (int k = 0; k < K; ++k) {
      T_mean += w[k] * (*node_T_)[nodes[k]];
      G_mean += w[k] * G[nodes[k]];
    }
    const double deviation = energy_[p] - (sensible(p, phi[p]) * T_mean + phi[p] * G_mean);
    // A deviation at the round-off of the projection is none: it goes to the grid now (exactly),
    // so that particles in smooth regions carry d = 0 and shed nothing step after step.
    const bool noise = std::abs(deviation) <= 1e-9 * (std::abs(energy_[p]) + sensible(p, phi[p]));
    d[p] = noise ? 0.0 : deviation;
    energy_[p] = noise ? vol[p] * deviation : 0.0;
  });
  shed_to_grid();
  grid_valid_ = true;
  previous_substep_ = 0;  // no history for the implicit first guess
}

void ThermalPhysics::invert_nodes() {
  parallel_for(node_heat_.size(), [&](std::size_t i) {
    if (node_volume_[i] > 0) (*node_T_)[i] = nodal_.invert(i, node_heat_[i], (*node_T_)[i]);
  });
}

void ThermalPhysics::update_node_pore_heat() {
  parallel_for((*node_T_).size(), [&](std::size_t i) {
    for (std::size_t m = 0; m < node_pore_heat_.size(); ++m)
      node_pore_heat_[m][i] = nodal_.pore[m][i] > 0 ? nodal_.pore_heat(m, i, (*node_T_)[i]) : 0.0;
  });
}

/// Dirichlet nodes take their value at `time`; the heat that takes enters through the boundary.
void ThermalPhysics::apply_dirichlet_nodes(double time) {
  double added = 0;
  auto hold = [&](const std::vector<std::size_t>& nodes, double value) {
    for (std::size_t i : nodes) {
      if (node_volume_[i] <= 0) continue;
      dirichlet_[i] = 1;
      const double e = nodal_.heat(i, value);
      added += node_volume_[i] * (e - node_heat_[i]);
      node_heat_[i] = e;
      (*node_T_)[i] = value;
    }
  };
  for (const auto& bc : fixed_T_) hold(bc.nodes, value_at(bc, time));
  for (const auto& bc : particle_T_) hold(bc.nodes, value_at(bc, time));
  boundary_heat_ += added;
}

void ThermalPhysics::set_dirichlet_targets(double time) {
  for (const auto& bc : fixed_T_) {
    const double value = value_at(bc, time);
    for (std::size_t i : bc.nodes) dirichlet_target_[i] = value;
  }
  for (const auto& bc : particle_T_) {
    const double value = value_at(bc, time);
    for (std::size_t i : bc.nodes) dirichlet_target_[i] = value;
  }
}

void ThermalPhysics::map_to_grid() {
  const auto& st = kernel_->transfer().stencil();
  // A deforming skeleton changes each particle's volume and porosity between steps: at its
  // temperature its heat changes by the pores' water it expelled or drew in (sensible and
  // latent) and the grains' expansion. That is heat the material carried, not an error of
  // the thermal step: it is counted apart so that the balance still checks the step.
  if (kernel_->particles_move()) {
    const double now = particle_heat_total();
    if (heat_after_step_valid_) deformation_heat_ += now - heat_after_step_;
  }
  // Particles moved (or nothing is carried yet, or particle temperature conditions reset some
  // particles): the grid state is re-derived from the particles.
  if (!grid_valid_ || st.version() != grid_stencil_version_ || !particle_T_.empty()) project_to_grid(true);
  if (!particle_T_.empty()) update_condition_nodes();
  // Deviation the particles shed last step joins the grid field now.
  if (std::any_of(node_pending_.begin(), node_pending_.end(), [](double e) { return e != 0; })) {
    parallel_for(node_heat_.size(), [&](std::size_t i) {
      if (node_volume_[i] > 0 && node_pending_[i] != 0) {
        node_heat_[i] += node_pending_[i] / node_volume_[i];
        (*node_T_)[i] = nodal_.invert(i, node_heat_[i], (*node_T_)[i]);
      }
    });
    std::fill(node_pending_.begin(), node_pending_.end(), 0.0);
  }
  update_particle_surfaces();
  std::fill(dirichlet_.begin(), dirichlet_.end(), 0);
  apply_dirichlet_nodes(time_);
  set_dirichlet_targets(time_ + dt_);
}

// ---- particle update ---------------------------------------------------------------------------

void ThermalPhysics::map_to_particles() {
  const auto& st = kernel_->transfer().stencil();
  const std::size_t n = kernel_->particle_count();
  const int K = st.per_particle();
  auto T = temperature_.mutable_values();
  auto T_pic = temperature_pic_.mutable_values();
  auto S = saturation_.mutable_values();
  auto d = deviation_.mutable_values();
  const auto phi = porosity_.values();
  const auto vol = volume_.values();
  update_node_pore_heat();
  // How much of its deviation a particle keeps: the FLIP fraction, times the sub-grid
  // relaxation over this step.
  double keep = flip_fraction_;
  if (subgrid_relaxation_ > 0) {
    const double h = kernel_->grid().min_spacing();
    keep *= std::exp(-dt_ * max_diffusivity_ / (subgrid_relaxation_ * h * h));
  }
  long clipped = 0, shedding = 0;
  double max_diffusivity = 0, min_capacity = std::numeric_limits<double>::infinity();
  const auto v_skeleton = solid_velocity_.bound() ? solid_velocity_.values() : std::span<const double>{};
  const double h_min = kernel_->grid().min_spacing();
#pragma omp parallel for schedule(static) reduction(+ : clipped, shedding) reduction(max : max_diffusivity) \
    reduction(min : min_capacity) if (n >= kParallelMinimum)
  for (std::size_t p = 0; p < n; ++p) {
    const auto* nodes = st.nodes(p);
    const auto* w = st.weights(p);
    const auto& G = node_pore_heat_[material_[p]];
    const auto& table = *tables_[material_[p]];
    double T_mean = 0, G_mean = 0, lo = T[p], hi = T[p];
    for (int k = 0; k < K; ++k) {
      const double Ti = (*node_T_)[nodes[k]];
      T_mean += w[k] * Ti;
      G_mean += w[k] * G[nodes[k]];
      if (w[k] > 0) {
        lo = std::min(lo, Ti);
        hi = std::max(hi, Ti);
      }
    }
    const double a = sensible(p, phi[p]);
    const double grid_heat = a * T_mean + phi[p] * G_mean;  // PIC heat content Σ_i S_ip H_p(T_i)
    // Material that moves across the grid: a deviation belongs to the particle's place among the
    // nodes, so it is forgotten in proportion to the distance moved, Σ_i S_ip |v_i| Δt / h (all of
    // it after a cell): numerical diffusion ∝ |v| h whatever the step, and no FLIP noise.
    double moved = 0;
    if (!v_skeleton.empty()) {
      const auto v = kernel_->transfer().vector_at(p, v_skeleton);
      double speed2 = 0;
      for (int e = 0; e < kDim; ++e) speed2 += v[e] * v[e];
      moved = std::min(1.0, dt_ * std::sqrt(speed2) / h_min);
    }
    const double deviation = keep * (1.0 - moved) * d[p];
    double T_new = table.invert(a, phi[p], grid_heat + deviation, hint_[p]);
    // Maximum principle: no new extreme beyond the old value and the nodes' new values. The
    // deviation the clip removes is handed to the grid below, so energy stays exact.
    double kept = deviation;
    const double slack = 1e-12 * (1.0 + std::abs(T_new));  // round-off of the inversion is not an extreme
    if (T_new < lo - slack || T_new > hi + slack) {
      T_new = std::clamp(T_new, lo, hi);
      kept = table.heat(a, phi[p], T_new, hint_[p]) - grid_heat;
      ++clipped;
    }
    energy_[p] = vol[p] * (d[p] - kept);  // deviation given back to the grid
    shedding += energy_[p] != 0;
    d[p] = kept;
    T[p] = T_new;
    T_pic[p] = T_mean;
    hint_[p] = table.locate(T_new, hint_[p]);
    S[p] = table.saturation(T_new, hint_[p]);
    evaluate_particle_properties(p, phi[p], pic_properties_ ? T_mean : T_new);
    const double capacity = sensible_capacity(p, phi[p]);
    max_diffusivity = std::max(max_diffusivity, conductivity_[p] / capacity);
    min_capacity = std::min(min_capacity, capacity);
  }
  clipped_ += clipped;
  if (shedding > 0) shed_to_grid();
  max_diffusivity_ = max_diffusivity;
  min_capacity_ = min_capacity;
  if (!particle_T_.empty()) {
    apply_particle_dirichlet(time_ + dt_, /*count_heat=*/true);
    update_step_limits();
  }
  if (kernel_->particles_move()) {
    heat_after_step_ = particle_heat_total();
    heat_after_step_valid_ = true;
  }
}

/// The explicit step's bounds: the largest diffusivity κ/C (sensible capacity, the smaller of
/// thawed and frozen) and the smallest capacity.
void ThermalPhysics::update_step_limits() {
  const auto phi = porosity_.values();
  const std::size_t n = phi.size();
  max_diffusivity_ = parallel_max(
      n, [&](std::size_t p) { return conductivity_[p] / sensible_capacity(p, phi[p]); }, 0.0);
  min_capacity_ = parallel_min(
      n, [&](std::size_t p) { return sensible_capacity(p, phi[p]); }, std::numeric_limits<double>::infinity());
}

/// Deviation the particles shed this step (the blend, the sub-grid relaxation, the clip) goes
/// to their nodes, weighted by the shape functions, and joins the grid field at the next step
/// (so this step's particle values stay consistent with the nodal temperatures they came
/// from): E = Σ V_i e_i + Σ_i pending_i + Σ V_p d_p is conserved exactly.
void ThermalPhysics::shed_to_grid() {
  const auto& st = kernel_->transfer().stencil();
  const int K = st.per_particle();
  kernel_->transfer().scatter([&](std::size_t p) {
    if (energy_[p] == 0) return;
    const auto* nodes = st.nodes(p);
    const auto* w = st.weights(p);
    for (int k = 0; k < K; ++k) node_pending_[nodes[k]] += w[k] * energy_[p];
  });
}

/// A particle temperature condition holds, besides its particles, the nodes those particles make
/// up at least half of (by volume): the surface's own nodes, wherever the material has moved it.
/// Resetting the particles alone is not enough: the reset heat enters their nodes at each
/// projection, and a neighbour's sub-grid deviation, measured against those nodes, sees only
/// their loss during the step — it kept a frozen layer at −10 °C under a 10 °C surface layer while
/// the heat passed under it to the layers below. Held nodes change by nothing during the step.
void ThermalPhysics::update_condition_nodes() {
  const auto& st = kernel_->transfer().stencil();
  const auto vol = volume_.values();
  for (auto& bc : particle_T_) bc.nodes = nodes_made_up_by(bc.particles, st, vol, node_volume_, condition_share_);
}

/// Particle temperature conditions: the particles are reset to the value (the grid is
/// re-derived from the particles at the next step); the heat that takes counts as boundary heat.
void ThermalPhysics::apply_particle_dirichlet(double time, bool count_heat) {
  auto T = temperature_.mutable_values();
  auto T_pic = temperature_pic_.mutable_values();
  auto S = saturation_.mutable_values();
  const auto phi = porosity_.values();
  const auto vol = volume_.values();
  for (const auto& bc : particle_T_) {
    const double value = value_at(bc, time);
    for (std::size_t p : bc.particles) {
      const auto& table = *tables_[material_[p]];
      const double a = sensible(p, phi[p]);
      if (count_heat)
        boundary_heat_ += vol[p] * (table.heat(a, phi[p], value, hint_[p]) - table.heat(a, phi[p], T[p], hint_[p]));
      T[p] = T_pic[p] = value;
      hint_[p] = table.locate(value, hint_[p]);
      S[p] = table.saturation(value, hint_[p]);
    }
  }
}

// ---- checkpoints and statistics ----------------------------------------------------------------

std::vector<PersistentArray> ThermalPhysics::persistent_state() {
  saved_scalars_ = {double(grid_valid_), double(halvings_), previous_substep_, initial_heat_, boundary_heat_, double(nonlinear_total_),
                    double(nonlinear_max_), double(linear_total_), double(rejected_substeps_), double(substeps_),
                    double(clipped_), smallest_substep_, max_diffusivity_, min_capacity_, double(initialized_),
                    advected_heat_, deformation_heat_, heat_after_step_, double(heat_after_step_valid_), removed_heat_};
  return {{"node_heat", &node_heat_},
          {"node_temperature", node_T_},
          {"node_temperature_before", &node_T_before_},
          {"node_pending_heat", &node_pending_},
          {"scalars", &saved_scalars_}};
}

void ThermalPhysics::restored() {
  const auto& s = saved_scalars_;
  if (s.size() != 20) throw std::runtime_error("thermal: checkpoint holds " + std::to_string(s.size()) + " scalars, expected 20");
  removed_heat_ = s[19];
  advected_heat_ = s[15];
  deformation_heat_ = s[16];
  heat_after_step_ = s[17];
  heat_after_step_valid_ = s[18] != 0;
  grid_valid_ = s[0] != 0;
  halvings_ = long(s[1]);
  previous_substep_ = s[2];
  initial_heat_ = s[3];
  boundary_heat_ = s[4];
  nonlinear_total_ = long(s[5]);
  nonlinear_max_ = long(s[6]);
  linear_total_ = long(s[7]);
  rejected_substeps_ = long(s[8]);
  substeps_ = long(s[9]);
  clipped_ = long(s[10]);
  smallest_substep_ = s[11];
  max_diffusivity_ = s[12];
  min_capacity_ = s[13];
  initialized_ = s[14] != 0;
  // Derived state: κ_p from the particle fields, the grid's coefficients and temperatures from
  // the carried nodal heat.
  const auto T = temperature_.values();
  const auto T_pic = temperature_pic_.values();
  const auto phi = porosity_.values();
  parallel_for(kernel_->particle_count(), [&](std::size_t p) {
    hint_[p] = tables_[material_[p]]->locate(T[p], hint_[p]);
    evaluate_particle_properties(p, phi[p], pic_properties_ ? T_pic[p] : T[p]);
  });
  if (grid_valid_) {  // the grid's coefficients again; its state exactly as saved
    const std::vector<double> heat = node_heat_, temperature = (*node_T_);
    project_to_grid(/*with_heat=*/false);
    node_heat_ = heat;
    (*node_T_) = temperature;
  }
}

std::vector<std::pair<std::string, double>> ThermalPhysics::statistics() const {
  // Heat in the particles plus heat in transit (shed by particles, not yet in the grid field).
  const double pending = reproducible_sum(node_pending_.size(), [&](std::size_t i) { return node_pending_[i]; });
  const double stored = initialized_ ? particle_heat_total() + pending - initial_heat_ : 0.0;
  const double error = stored + removed_heat_ - boundary_heat_ - deformation_heat_;
  const double scale = std::max({std::abs(stored), std::abs(boundary_heat_), 1e-300});
  std::vector<std::pair<std::string, double>> out = {
      {"thermal.energy_boundary_in_J", boundary_heat_},
      {"thermal.energy_stored_change_J", stored},
      {"thermal.energy_balance_error_J", error},
      {"thermal.energy_balance_error_relative", std::abs(error) / scale},
      {"thermal.energy_in_transit_J", pending},
      {"thermal.energy_advected_in_J", advected_heat_},
      {"thermal.energy_deformation_J", deformation_heat_},
      {"thermal.energy_removed_J", removed_heat_},
      {"thermal.max_principle_clips", double(clipped_)}};
  if (implicit_) {
    out.insert(out.end(), {{"thermal.nonlinear_iterations_total", double(nonlinear_total_)},
                           {"thermal.nonlinear_iterations_max", double(nonlinear_max_)},
                           {"thermal.linear_iterations_total", double(linear_total_)},
                           {"thermal.substeps_total", double(substeps_)},
                           {"thermal.rejected_substeps", double(rejected_substeps_)},
                           {"thermal.smallest_substep_s", std::isfinite(smallest_substep_) ? smallest_substep_ : 0.0}});
  }
  std::size_t knots = 0;
  for (const auto& t : tables_) knots = std::max<std::size_t>(knots, std::size_t(t->intervals()));
  out.push_back({"thermal.enthalpy_table_intervals_max", double(knots)});
  return out;
}

FROSTMPM_REGISTER(Physics, ThermalPhysics)
FROSTMPM_REGISTER_BOUNDARY_TYPES(ThermalPhysics)

}  // namespace frostmpm::thermal

FROSTMPM_PLUGIN("frostmpm-thermal", "0.2.0")
