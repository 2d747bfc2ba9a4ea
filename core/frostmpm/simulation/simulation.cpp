#include "frostmpm/simulation/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <set>
#include <sstream>

#include "frostmpm/config/units.hpp"
#include "frostmpm/io/log.hpp"
#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/io/particle_field_writer.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/simulation/interrupt.hpp"
#include "frostmpm/simulation/run_budget.hpp"

namespace frostmpm {

namespace {

using Clock = std::chrono::steady_clock;

/// Checkpoint group of the nodal fields the kernel carries between steps (no physics key
/// starts with an underscore).
constexpr const char* kCarriedNodeFields = "_carried_node_fields";
/// Checkpoint group of the probes' running extremes (`over_time`).
constexpr const char* kProbeState = "_probes";

/// The deformation gradient a mechanics physics keeps (3×3, row-major); when the scene has it,
/// the kernel derives particle volumes and GIMP domains from it.
constexpr const char* kDeformationGradient = "deformation_gradient";
constexpr const char* kInitialVolume = "volume_initial";
constexpr const char* kInitialHalfSize = "half_size_initial";

/// "  t = 3.42 h of 50 h (6.8 %)  step 120  dt = 102 s  ETA 31 s": simulated times in the unit
/// that reads best, the step in s (what time.dt and the stability limits speak of).
std::string progress_line(double time, double end, long step, double dt, double eta_seconds) {
  std::ostringstream line;
  line << "  t = " << units::readable_duration(time) << " of " << units::readable_duration(end) << " ("
       << std::fixed << std::setprecision(1) << 100.0 * time / end << " %)  step " << step << "  dt = "
       << std::defaultfloat << std::setprecision(3) << dt << " s  ETA " << units::readable_duration(eta_seconds, 2);
  return line.str();
}

double determinant3(const double* F) {
  return F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
}

}  // namespace

Simulation::Simulation(const Registry& registry, const ConfigNode& root) : registry_(registry) {
  resolved_ = YAML::Node(YAML::NodeType::Map);
  read_grid(root.child("grid"));
  read_time(root.child("time"));
  {
    const auto gravity = root.optional_child("gravity");
    read_gravity(gravity ? &*gravity : nullptr);
  }
  read_physics(root.child("physics"));
  read_materials(root.child("materials"));
  read_regions(root.child("regions"));
  const auto bcs = root.optional_child("boundary_conditions");
  if (bcs) read_boundary_conditions(*bcs);
  for (auto& physics : physics_) physics->setup(*this);
  for (auto& bc : bcs_) bc.node->finish({});  // physics read their keys; anything left is unknown
  // Copied once the physics have read the values: those given with units are then numbers in
  // the declared units (ConfigNode::as_real).
  resolved_["boundary_conditions"] = bcs ? YAML::Clone(bcs->raw()) : YAML::Node(YAML::NodeType::Sequence);
  resolve_step();
  warn_unused_keys();
  apply_initial_values();
  read_output(root.child("output"));
  {
    Probes::Sources sources;
    sources.grid = &grid_;
    sources.particles = &particles_;
    sources.transfer = &transfer_;
    for (const auto& bc : bcs_) {
      const Physics& owner = owner_of(bc);
      const bool has_reaction = owner.reaction(bc).has_value();
      if (has_reaction && std::find(sources.reaction_types.begin(), sources.reaction_types.end(), bc.type) ==
                              sources.reaction_types.end())
        sources.reaction_types.push_back(bc.type);
      if (!bc.name.empty())
        sources.boundaries.push_back({bc.name, bc.label(), has_reaction, owner.rigid_body(bc).has_value()});
    }
    sources.reaction = [this](const std::string& name) { return reaction(name); };
    sources.rigid_body = [this](const std::string& name) { return rigid_body(name); };
    const auto probes = root.optional_child("probes");
    probes_.read(probes ? &*probes : nullptr, std::move(sources));
    resolved_["probes"] = probes_.resolved();
  }
  const auto checkpoint = root.optional_child("checkpoint");
  read_checkpoint(checkpoint ? *checkpoint : ConfigNode(YAML::Node(YAML::NodeType::Map), root.file(), "checkpoint"));
  initialize_state();
  check_boundary_reach();
}

/// A condition on nodes acts through the material its nodes carry: on a face the material does
/// not reach (a grid taller than the soil, as is usual in MPM) it would change nothing and the
/// run would "finish" with no thaw. Refused for every physics' conditions, moving or not: a
/// condition does not follow the material surface, so one that starts off the material is a
/// mistake in the scene. `check` reports every condition's reach.
void Simulation::check_boundary_reach() {
  std::vector<std::uint8_t> reached(grid_.node_count(), 0);
  const auto& stencil = transfer_.stencil();
  const int K = stencil.per_particle();
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const auto* nodes = stencil.nodes(p);
    const auto* w = stencil.weights(p);
    for (int k = 0; k < K; ++k)
      if (w[k] > 0) reached[nodes[k]] = 1;
  }
  std::ostringstream report;
  for (const auto& bc : bcs_) {
    if (bc.on_particles) continue;
    const auto count = std::count_if(bc.nodes.begin(), bc.nodes.end(), [&](std::size_t n) { return reached[n] != 0; });
    report << bc.label() << ": " << count << " of " << bc.nodes.size() << " nodes carry material\n";
    if (count > 0) continue;
    // The material's extent, for the message: the union of the particle domains.
    const auto pos = particles_.field("position"), half = particles_.field("half_size");
    std::array<double, kDim> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t p = 0; p < particles_.size(); ++p)
      for (int d = 0; d < kDim; ++d) {
        lo[d] = std::min(lo[d], pos[p * kDim + d] - half[p * kDim + d]);
        hi[d] = std::max(hi[d], pos[p * kDim + d] + half[p * kDim + d]);
      }
    throw bc.node->error(bc.label() + " acts on " + std::to_string(bc.nodes.size()) +
                         " node(s), none of which the material reaches (it spans x in [" + number_text(lo[0], 6) +
                         ", " + number_text(hi[0], 6) + "], y in [" + number_text(lo[1], 6) + ", " +
                         number_text(hi[1], 6) + "] m), so it would change nothing; put it where the material is (a "
                         "face the material touches, or nodes: {box: ...} at its surface)");
  }
  boundary_report_ = report.str();
}

Simulation::~Simulation() = default;

RunInterrupted::RunInterrupted(int signal_number, double at_time, long at_step)
    : std::runtime_error("interrupted by signal " + std::to_string(signal_number)),
      signal(signal_number),
      time(at_time),
      step(at_step) {}

// ---- Kernel<2> ------------------------------------------------------------------------------------

std::vector<BoundaryCondition*> Simulation::boundary_conditions(const std::string& type) {
  std::vector<BoundaryCondition*> out;
  for (auto& bc : bcs_)
    if (bc.type == type) out.push_back(&bc);
  return out;
}

void Simulation::declare_state_field(const std::string& name, const std::string& unit, int components,
                                     double default_value, double max_magnitude, FieldKind kind) {
  state_bounds_[name] = max_magnitude;
  particles_.declare(name, unit, components, default_value, kind);
  state_defaults_[name] = default_value;
}

void Simulation::declare_field(const std::string& name, const std::string& unit, int components, double initial,
                               FieldKind kind) {
  particles_.declare(name, unit, components, initial, kind);
}

void Simulation::declare_history(const std::string& name, const std::string& unit, int components, double initial,
                                 FieldKind kind) {
  particles_.declare_history(name, unit, components, initial, kind);
}

void Simulation::fill_from_materials(const std::string& field, const std::string& parameter) {
  auto values = particles_.field(field);
  for (const auto& r : particles_.ranges())
    std::fill(values.begin() + r.begin, values.begin() + r.end, materials_[r.material].params.real(parameter));
}

std::string Simulation::describe_particle(std::size_t p) const {
  const auto pos = particles_.field("position");
  std::ostringstream out;
  out << "particle " << p << " at (" << pos[p * kDim] << ", " << pos[p * kDim + 1] << ")";
  if (particles_.has("particle_id")) out << " (particle_id " << particles_.field("particle_id")[p] << ")";
  const auto& ranges = particles_.ranges();  // one per region, kept when particles are removed
  for (std::size_t k = 0; k < ranges.size(); ++k)
    if (p >= ranges[k].begin && p < ranges[k].end)
      out << " in regions." << k << " (material '" << materials_[ranges[k].material].name << "')";
  return out.str();
}

const Physics& Simulation::owner_of(const BoundaryCondition& bc) const {
  const std::string& owner = bc_owner_.at(bc.type);
  for (std::size_t i = 0; i < physics_.size(); ++i)
    if (physics_keys_[i] == owner) return *physics_[i];
  throw std::logic_error("boundary condition type '" + bc.type + "' has no physics");
}

const BoundaryCondition& Simulation::named_condition(const std::string& name) const {
  for (const auto& bc : bcs_)
    if (bc.name == name) return bc;
  throw std::logic_error("no boundary condition is named '" + name + "'");  // probes check names when read
}

std::array<double, 3> Simulation::reaction(const std::string& name) const {
  const BoundaryCondition& bc = named_condition(name);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return owner_of(bc).reaction(bc).value_or(std::array<double, 3>{nan, nan, nan});
}

Physics::RigidBodyMotion Simulation::rigid_body(const std::string& name) const {
  const BoundaryCondition& bc = named_condition(name);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return owner_of(bc).rigid_body(bc).value_or(Physics::RigidBodyMotion{nan, nan, nan});
}

// ---- the resolved step ----------------------------------------------------------------------------

void Simulation::resolve_step() {
  std::vector<StepPlan::Declared> declared;
  for (std::size_t i = 0; i < physics_.size(); ++i)
    for (auto& stage : physics_[i]->stages()) declared.push_back({std::move(stage), physics_keys_[i], physics_where_[i]});
  plan_ = StepPlan::resolve(std::move(declared), particles_.field_names());
  for (const auto& f : plan_.new_particle_fields()) particles_.declare(f.name, f.unit, f.components, 0.0, f.kind);
  for (const auto& f : plan_.node_fields()) node_fields_.allocate(f.name, f.components, grid_.node_count());
  // Particles move when a stage writes their positions: the kernel then keeps their geometry.
  for (const auto& stage : plan_.stages())
    for (const auto& f : stage.writes)
      if (f.location == FieldLocation::Particle && f.name == "position") moving_ = true;
  if (moving_) {
    particles_.declare(kInitialVolume, particles_.unit("volume"));
    particles_.declare(kInitialHalfSize, "m", kDim, 0.0, FieldKind::Vector);
    const auto V = particles_.field("volume"), half = particles_.field("half_size");
    auto V0 = particles_.field(kInitialVolume), half0 = particles_.field(kInitialHalfSize);
    std::copy(V.begin(), V.end(), V0.begin());
    std::copy(half.begin(), half.end(), half0.begin());
  }
  bind_handles();
}

void Simulation::warn_unused_keys() const {
  // Weight and inertia enter momentum balances only: without a stage predicting momentum, gravity
  // and mass scaling change nothing, which the user should know rather than believe otherwise.
  const auto& stages = plan_.stages();
  if (std::any_of(stages.begin(), stages.end(), [](const Stage& s) { return s.phase == Phase::PredictMomentum; }))
    return;
  const std::string why = "has no effect: no physics of this scene solves a momentum balance (no stage in "
                          "phase predict_momentum)";
  if (gravity_where_ && std::any_of(gravity_.begin(), gravity_.end(), [](double g) { return g != 0; }))
    log::warning(gravity_where_->describe() + ": " + why);
  if (time_params_.real("mass_scaling") != 1.0)
    log::warning(time_params_.where("mass_scaling").describe() + ": " + why);
}

void Simulation::bind_handles() {
  for (auto& stage : plan_.stages()) {
    for (const auto* list : {&stage.reads, &stage.writes})
      for (const auto& f : *list) {
        if (!f.handle) continue;
        std::vector<double>* column = f.location == FieldLocation::Node ? &node_fields_.values(f.name)
                                                                        : &particles_.column(f.name);
        f.handle->bind(column, list == &stage.writes);
      }
  }
}

std::vector<PersistentArray> Simulation::carried_node_fields() {
  std::vector<PersistentArray> arrays;
  for (const auto& f : plan_.node_fields())
    if (f.carried) arrays.push_back({f.name, &node_fields_.values(f.name)});
  return arrays;
}

// ---- geometry and the step ------------------------------------------------------------------------

long Simulation::locate_particles() {
  if (grid_.any_periodic()) {
    // A particle that crossed a periodic seam re-enters at the other side.
    auto x = particles_.field("position");
    parallel_for(particles_.size(), [&](std::size_t p) {
      for (int d = 0; d < kDim; ++d) x[p * kDim + d] = grid_.wrap_position(d, x[p * kDim + d]);
    });
  }
  return transfer_.update(grid_, particles_.field("position"), particles_.field("half_size"));
}

void Simulation::update_stencil() {
  long outside = locate_particles();
  if (outside >= 0 && leaving_ == LeavingPolicy::Remove) {
    // The stencil of a particle outside the grid has every weight zero (inside: they sum to 1).
    const auto& st = transfer_.stencil();
    const int K = st.per_particle();
    std::vector<std::uint8_t> leaving(particles_.size(), 0);
    for (std::size_t p = 0; p < leaving.size(); ++p) {
      const double* w = st.weights(p);
      leaving[p] = std::all_of(w, w + K, [](double x) { return x == 0.0; }) ? 1 : 0;
    }
    remove_particles(leaving, /*restoring=*/false);
    outside = transfer_.update(grid_, particles_.field("position"), particles_.field("half_size"));
  }
  if (outside < 0) return;
  const auto p = static_cast<std::size_t>(outside);
  std::ostringstream msg;
  msg << "numerical blow-up: " << describe_particle(p)
      << " has left the grid (its shape-function support reaches past the grid's edge) at t = " << time_
      << " s, step " << step_ << " (dt = " << dt_ << " s); enlarge the grid, let such particles go "
      << "(grid.particles_leaving: remove), or the loads drive it too far" << suspects(p);
  throw NumericalBlowUp(msg.str());
}

void Simulation::remove_particles(std::span<const std::uint8_t> leaving, bool restoring) {
  ParticleRemoval removal(leaving);
  removal.restoring = restoring;
  if (removal.remaining == 0) {
    std::ostringstream msg;
    msg << "numerical blow-up: every particle has left the grid at t = " << time_ << " s, step " << step_
        << " (dt = " << dt_ << " s)";
    throw NumericalBlowUp(msg.str());
  }
  probes_.remove_particles(removal, time_);
  for (auto& physics : physics_) physics->removing_particles(removal);
  for (auto& bc : bcs_) removal.remap(bc.particles);
  transfer_.remove_particles(removal);
  particles_.remove(removal);
  positions_changed_ = true;
}

/// Particle volumes V = V0 det F and GIMP half-widths l_d = l0_d √(F Fᵀ)_dd: the axis-aligned
/// extent of the deformed particle domain (exact for an initially round domain; a rigid rotation
/// keeps it, a stretch along an axis scales it). Held below half a cell so the support stays
/// three nodes wide.
void Simulation::update_geometry() {
  if (!particles_.has(kDeformationGradient)) return;
  const auto F = particles_.field(kDeformationGradient);
  const auto V0 = particles_.field(kInitialVolume), half0 = particles_.field(kInitialHalfSize);
  auto V = particles_.field("volume"), half = particles_.field("half_size");
  long clamped = 0;
#pragma omp parallel for schedule(static) reduction(+ : clamped) if (V.size() >= kParallelMinimum)
  for (std::size_t p = 0; p < V.size(); ++p) {
    const double* f = F.data() + 9 * p;
    V[p] = V0[p] * determinant3(f);
    for (int d = 0; d < kDim; ++d) {
      const double stretch = std::sqrt(f[3 * d] * f[3 * d] + f[3 * d + 1] * f[3 * d + 1] + f[3 * d + 2] * f[3 * d + 2]);
      const double limit = 0.5 * grid_.spacing[d] * (1 - 1e-9);
      double l = half0[p * kDim + d] * stretch;
      if (l > limit) {
        l = limit;
        ++clamped;
      }
      half[p * kDim + d] = l;
    }
  }
  clamped_domains_ += clamped;
}

void Simulation::advance(double dt) {
  auto timed = [&](const std::string& name, const std::function<void()>& fn) {
    const auto start = Clock::now();
    fn();
    stats_.stage_seconds[name] += std::chrono::duration<double>(Clock::now() - start).count();
  };
  if (positions_changed_) {
    timed("kernel.stencil", [&] {
      if (moving_) update_geometry();
      update_stencil();
    });
    positions_changed_ = false;
  }
  dt_ = dt;  // after the stencil: a particle that left the grid is reported with the step that moved it
  timed("kernel.begin_step", [&] {  // the history copy (stress_start ← stress, ...)
    particles_.begin_step();
    for (auto& physics : physics_) physics->begin_step(time_, dt);
  });
  for (auto& stage : plan_.stages()) timed(stage.name, stage.run);
  time_ += dt;
  ++step_;
  positions_changed_ = moving_;
  stats_.steps++;
  stats_.dt_sum += dt;
  stats_.dt_min = stats_.steps == 1 ? dt : std::min(stats_.dt_min, dt);
  stats_.dt_max = std::max(stats_.dt_max, dt);
}

namespace {

/// True when every value is finite: x · 0 is NaN exactly when x is ±inf or NaN, and a NaN
/// survives any sum (so the order of the vectorised sum does not matter).
bool all_finite(std::span<const double> values) {
  double nan_if_not = 0;
  const std::size_t n = values.size();
  const double* v = values.data();
#pragma omp parallel for simd schedule(static) reduction(+ : nan_if_not) if (n >= kParallelMinimum)
  for (std::size_t i = 0; i < n; ++i) nan_if_not += v[i] * 0.0;
  return nan_if_not == 0;
}

}  // namespace

void Simulation::check_finite() const {
  for (const auto& name : particles_.field_names()) {
    // State fields and fields with history (stress): what the next step starts from.
    if (!state_defaults_.count(name) && !particles_.has(ParticleStore::history_name(name))) continue;
    const auto column = particles_.field(name);
    if (all_finite(column)) continue;  // the common case, in one vectorised pass
    const int c = particles_.components(name);
    // The first non-finite entry (a parallel scan; the smallest index, whatever the threads).
    const double first = parallel_min(
        column.size(), [&](std::size_t i) { return std::isfinite(column[i]) ? HUGE_VAL : double(i); }, HUGE_VAL);
    if (first == HUGE_VAL) continue;
    const auto i = static_cast<std::size_t>(first);
    const std::size_t p = i / c;
    std::ostringstream msg;
    msg << "numerical blow-up: " << name << " = " << column[i] << " at " << describe_particle(p) << " at t = " << time_
        << " s, step " << step_ << " (dt = " << dt_ << " s)" << suspects(p);
    throw NumericalBlowUp(msg.str());
  }
}

std::string Simulation::suspects(std::size_t /*particle*/) const {
  std::vector<std::string> bcs;
  for (std::size_t i = 0; i < bcs_.size(); ++i) bcs.push_back(bcs_[i].label());
  return bcs.empty() ? std::string() : "; check the region's values and those of " + join(bcs);
}

double Simulation::plan_step(const LoopState& loop) const {
  const double eps = 1e-9 * end_time_;
  double dt = fixed_dt_ > 0 ? fixed_dt_ : std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < physics_.size(); ++i) {
    const double limit = physics_[i]->stable_time_step();
    // A fixed step above a physics' stability limit is cut to it; say so once.
    if (fixed_dt_ > 0 && limit < fixed_dt_ * (1 - 1e-12) && !warned_dt_cut_) {
      std::ostringstream message;
      message << "time.dt = " << fixed_dt_ << " s exceeds the stability limit of physics '" << physics_keys_[i]
              << "' (" << limit << " s at t = " << time_
              << " s); the run takes the smaller step (an implicit scheme takes any step)";
      log::warning(message.str());
      warned_dt_cut_ = true;
    }
    dt = std::min(dt, limit);
  }
  if (max_dt_ > 0) dt = std::min(dt, max_dt_);
  if (!std::isfinite(dt)) dt = end_time_ - time_;
  // Land exactly on the nearest output, metrics or end time in equal steps: the fewest steps of at
  // most dt that reach it, each gap / n. A full-length run ended by one short step to the target
  // modulates Δt with the output period, and the explicit skeleton's kick–drift pair then pumps
  // elastic modes at that period: a free block flying at 0.25 m/s with metrics every 0.002 s
  // (55 steps of 3.55e-5 s and two of 2.4e-5 s) grew rounding noise tenfold every 0.1 s, to
  // 2e-3 m/s by 1.6 s; in equal steps it stays at 1e-13 m/s.
  double gap = std::numeric_limits<double>::infinity();
  for (double target : {loop.next_output, metrics_every_ > 0 ? std::min(loop.next_metrics, end_time_) : end_time_,
                        end_time_})
    if (target - time_ > eps) gap = std::min(gap, target - time_);
  if (std::isfinite(gap)) {
    if (dt >= gap - eps) return gap;
    dt = gap / std::ceil(gap / dt - 1e-9);
  }
  return dt;
}

void Simulation::check_step_budget() const {
  // The physics' limits are known once they are initialised; a fixed step was checked in
  // read_time. (A limit may grow during the run; the step at t = 0 is the estimate.)
  for (std::size_t i = 0; i < physics_.size(); ++i) {
    double limit = physics_[i]->stable_time_step();
    if (max_dt_ > 0) limit = std::min(limit, max_dt_);
    if (fixed_dt_ > 0 && fixed_dt_ < limit) continue;
    check_count(time_params_, "end", (end_time_ - time_) / limit, max_steps_, "steps",
                "the stable step of physics '" + physics_keys_[i] + "' (" + number_text(limit, 3) + " s at t = " +
                    number_text(time_, 6) + " s) with time.end");
  }
}

void Simulation::save_checkpoint(const std::string& dir, LoopState& loop, const SceneSource& scene) {
  const auto start = Clock::now();
  loop.time = time_;
  loop.step = step_;
  loop.dt = dt_;
  loop.statistics = stats_;
  loop.restarts = restarts_;
  CheckpointWriter checkpoint(dir);
  checkpoint.write(scene);
  checkpoint.write(loop);
  checkpoint.write(particles_);
  for (std::size_t i = 0; i < physics_.size(); ++i)
    checkpoint.write_physics(physics_keys_[i], physics_[i]->persistent_state());
  if (const auto carried = carried_node_fields(); !carried.empty())
    checkpoint.write_physics(kCarriedNodeFields, carried);
  if (const auto extremes = probes_.persistent_state(); !extremes.empty())
    checkpoint.write_physics(kProbeState, extremes);
  checkpoint.commit();
  for (auto& physics : physics_) physics->checkpoint_written();
  stats_.stage_seconds["kernel.checkpoint"] += std::chrono::duration<double>(Clock::now() - start).count();
}

LoopState Simulation::restore_checkpoint(const std::string& dir) {
  const CheckpointReader checkpoint(dir);
  // A run that removed particles: drop the same ones from the scene's particles first.
  bool removed = false;
  if (particles_.has("particle_id"))
    if (const auto ids = checkpoint.particle_field("particle_id"); ids && ids->size() < particles_.size()) {
      std::vector<std::uint8_t> leaving(particles_.size(), 1);
      for (double id : *ids)
        if (id >= 0 && id < double(leaving.size())) leaving[static_cast<std::size_t>(id)] = 0;
      remove_particles(leaving, /*restoring=*/true);
      removed = true;
    }
  checkpoint.read(particles_);
  for (std::size_t i = 0; i < physics_.size(); ++i)
    checkpoint.read_physics(physics_keys_[i], physics_[i]->persistent_state());
  if (const auto carried = carried_node_fields(); !carried.empty())
    checkpoint.read_physics(kCarriedNodeFields, carried);
  if (const auto extremes = probes_.persistent_state(); !extremes.empty())
    checkpoint.read_physics(kProbeState, extremes);
  if (removed) {
    // Stencils for the particles that remain, before the physics rebuild their state. Particles
    // the last step moved off the grid stay: the first step removes them and counts what they
    // carry, as the uninterrupted run did (removing them here would count it before the
    // physics' counters are restored, and lose it).
    locate_particles();
    positions_changed_ = moving_;
  }
  LoopState loop = checkpoint.loop();
  time_ = loop.time;
  step_ = loop.step;
  dt_ = loop.dt;
  stats_ = loop.statistics;
  restarts_ = loop.restarts + 1;
  for (auto& physics : physics_) physics->restored();
  return loop;
}

namespace {

/// fields.h5 of the run being restarted, cut back to the frames its checkpoint knows.
ParticleFieldWriter reopen_fields(const OutputDir& out, long frames) {
  if (!std::filesystem::exists(out.file("fields.h5"))) {
    log::warning(out.file("fields.h5") + " is missing; a new one holds the frames after the checkpoint");
    return ParticleFieldWriter(out.path(), kDim);
  }
  try {
    return ParticleFieldWriter::reopen(out.path(), kDim, static_cast<std::size_t>(frames));
  } catch (const std::runtime_error& e) {
    throw InputError(std::string(e.what()) + "; move fields.h5 away to continue without the earlier frames");
  }
}

/// metrics.csv of the run being restarted, cut back to the rows its checkpoint knows (rewritten
/// atomically), open for appending.
CheckedFile reopen_metrics(const OutputDir& out, const std::string& header, long rows) {
  const std::string path = out.file("metrics.csv");
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line) || line != header)
    throw InputError(path + ": missing, or its header is not the scene's '" + header + "'");
  std::string kept = header + "\n";
  long found = 0;
  // Only complete lines count: a kill can leave the last one cut short.
  while (found < rows && std::getline(in, line) && !in.eof()) {
    kept += line + "\n";
    ++found;
  }
  if (found < rows)
    throw InputError(path + ": holds " + std::to_string(found) + " complete rows, the checkpoint expects " +
                     std::to_string(rows));
  in.close();
  out.write_text("metrics.csv", kept);
  return CheckedFile(path, /*append=*/true);
}

}  // namespace

void Simulation::initialize_state() {
  // The stencil is needed by the first probe evaluation; it stays valid until particles move
  // (a physics may key cached grid state to its version).
  update_stencil();
  positions_changed_ = false;
  // On a restart too: whatever a physics derives from the initial state is set up as in a new
  // run, and the checkpoint then overwrites every field and persistent array.
  for (auto& physics : physics_) physics->initialize();
  check_step_budget();
}

void Simulation::run(const OutputDir& out, const RunOptions& options) {
  // The constructor built the initial state (initialize_state).
  LoopState loop;
  const double eps = 1e-9 * end_time_;
  if (options.restart) {
    loop = restore_checkpoint(out.path());
    // Moving particles: the stencil of the restored positions and domains, as the step after
    // the checkpoint would have made it.
    positions_changed_ = moving_;
    if (time_ >= end_time_ - eps)
      throw InputError(out.path() + ": the run " + (loop.next_dt == 0 ? "finished" : "was checkpointed") + " at t = " +
                       number_text(time_) + " s and time.end is " + number_text(end_time_) +
                       " s; to extend it, give a later end: run --restart " + out.path() + " --set time.end=SECONDS");
    if (loop.next_dt == 0) {  // the checkpoint of a finished run: go on as if time.end had been later
      const auto next_multiple = [&](double every) { return (std::floor(time_ / every + 1e-9) + 1) * every; };
      loop.next_output = output_every_ > 0 ? std::min(next_multiple(output_every_), end_time_) : end_time_;
      if (metrics_every_ > 0 && loop.next_metrics <= time_ + eps) loop.next_metrics = next_multiple(metrics_every_);
      loop.next_dt = plan_step(loop);
    }
  } else {
    remove_checkpoint(out.path());  // an earlier run's checkpoint would not match these outputs
    loop.next_output = output_every_ > 0 ? std::min(output_every_, end_time_) : end_time_;
    loop.next_metrics = metrics_every_ > 0 ? metrics_every_ : 0;
  }
  const std::string header = probes_.header();
  ParticleFieldWriter writer =
      options.restart ? reopen_fields(out, loop.frames) : ParticleFieldWriter(out.path(), kDim);
  CheckedFile metrics = options.restart ? reopen_metrics(out, header, loop.metrics_rows)
                                        : CheckedFile(out.file("metrics.csv"), /*append=*/false);
  if (!options.restart) metrics.write(header + '\n');
  loop.frames = static_cast<long>(writer.frames());

  auto write_frame = [&] {
    std::vector<FieldView> views;
    for (const auto& name : output_fields_)
      views.push_back({name, particles_.field(name).data(), particles_.components(name), particles_.unit(name)});
    writer.write(time_, step_, particles_.size(), particles_.field("position").data(), views);
  };
  auto write_metrics = [&] {
    std::ostringstream row;
    row << std::setprecision(12) << time_ << ',' << step_ << ',' << dt_;
    for (double v : probes_.record()) row << ',' << v;
    row << '\n';
    metrics.write(row.str(), at_step(step_, time_));  // a whole row or an error, never half a row
  };

  if (!options.restart) {
    write_frame();
    write_metrics();
    ++loop.frames;
    ++loop.metrics_rows;
    if (time_ < end_time_ - eps) loop.next_dt = plan_step(loop);
  }
  const auto wall_start = Clock::now();
  const double time_start = time_;
  auto last_print = wall_start, last_checkpoint = wall_start;
  // The step loop's work outside advance(), timed as stages too: run.json's stages then add up
  // to the whole step loop but for metrics and frames (checkpoints are kernel.checkpoint).
  auto timed = [&](const char* name, auto&& fn) {
    const auto start = Clock::now();
    fn();
    stats_.stage_seconds[name] += std::chrono::duration<double>(Clock::now() - start).count();
  };
  while (time_ < end_time_ - eps) {
    advance(loop.next_dt);
    timed("kernel.check_finite", [&] { check_finite(); });
    const bool metrics_due = metrics_every_ <= 0 || time_ >= loop.next_metrics - eps || time_ >= end_time_ - eps;
    if (metrics_due) {
      write_metrics();
      ++loop.metrics_rows;
      while (metrics_every_ > 0 && loop.next_metrics <= time_ + eps) loop.next_metrics += metrics_every_;
    }
    const bool frame_due = time_ >= loop.next_output - eps;
    if (frame_due) {
      write_frame();
      ++loop.frames;
      loop.next_output = output_every_ > 0 ? std::min(loop.next_output + output_every_, end_time_) : end_time_;
      if (loop.next_output <= time_ + eps) loop.next_output = end_time_ + 1;
    }
    if (options.progress && log::enabled(log::Level::info) &&
        std::chrono::duration<double>(Clock::now() - last_print).count() > 2.0) {
      last_print = Clock::now();
      const double wall = std::chrono::duration<double>(last_print - wall_start).count();
      const double eta = wall * (end_time_ - time_) / std::max(time_ - time_start, 1e-300);
      log::info(progress_line(time_, end_time_, step_, dt_, eta));
    }
    if (time_ >= end_time_ - eps) break;

    // A stop request gets readable outputs of this moment; a restart drops them again (they
    // are not part of the schedule), so the loop counters above leave them out.
    const int signal = interrupt_signal();
    if (signal && !metrics_due) write_metrics();
    if (signal && !frame_due) write_frame();
    // The next step is chosen before a checkpoint is written, exactly as without one, and
    // saved with it: a restart continues with the same step and asks no physics for it.
    timed("kernel.plan_step", [&] { loop.next_dt = plan_step(loop); });
    const bool checkpoint_due =
        (checkpoint_every_steps_ > 0 && step_ % checkpoint_every_steps_ == 0) ||
        (checkpoint_every_minutes_ > 0 &&
         std::chrono::duration<double>(Clock::now() - last_checkpoint).count() >= 60 * checkpoint_every_minutes_);
    if (signal || checkpoint_due) {
      save_checkpoint(out.path(), loop, options.scene);
      last_checkpoint = Clock::now();
    }
    if (signal) throw RunInterrupted(signal, time_, step_);
  }
  if (checkpoint_at_end_) {
    loop.next_dt = 0;  // marks the checkpoint of a finished run: a restart extends it with a later time.end
    save_checkpoint(out.path(), loop, options.scene);
  } else {
    remove_checkpoint(out.path());  // nothing left to resume
  }
}

}  // namespace frostmpm
