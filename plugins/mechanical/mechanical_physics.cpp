// The mechanical physics: parameters, fields, the stress update and the particle update. The
// design is in mechanical_physics.hpp; boundary conditions in boundary_conditions.cpp.
#include "mechanical_physics.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <type_traits>

#include "frostmpm/io/log.hpp"
#include "frostmpm/models/pore_space.hpp"
#include "frostmpm/models/tensor3.hpp"
#include "frostmpm/shape/shape_function.hpp"
#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm::mechanical {

namespace {

/// update_stress()'s kinematics in plane strain — the strain increment, F ← (I + L Δt) F, the
/// volume ratio det(I + L Δt) and the Jaumann rotation of the start stress — as the generic
/// 3×3 arithmetic computes them, bit for bit, without its terms that plane strain makes zero:
/// an addend ±0 leaves a sum unchanged unless the sum so far is −0, and a sum is −0 only when
/// both its operands are, so every sum left shorter here starts from a literal +0 or from a
/// value checked not to be −0. The out-of-plane entries of F must be exactly +0 (and F_zz 1),
/// as the generic update keeps them in 2-D, and L finite (a non-finite L gives NaNs whose
/// placement the generic code decides); otherwise it returns false without writing anything,
/// and the generic code runs. F is row-major 3×3, the stresses 6 Voigt values.
[[gnu::always_inline]] inline bool plane_strain_kinematics(const std::array<std::array<double, 2>, 2>& L, double dt,
                                                           double* F, double* de, double& J_ratio, bool jaumann,
                                                           const double* start, double* rotated) {
  constexpr auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  constexpr std::uint64_t kMinusZero = std::uint64_t{1} << 63;
  if (bits(F[2]) != 0 || bits(F[5]) != 0 || bits(F[6]) != 0 || bits(F[7]) != 0 || F[8] != 1.0) return false;
  if (bits(F[0]) == kMinusZero || bits(F[1]) == kMinusZero || bits(F[3]) == kMinusZero || bits(F[4]) == kMinusZero)
    return false;
  const double l00 = L[0][0], l01 = L[0][1], l10 = L[1][0], l11 = L[1][1];
  if (!(std::isfinite(l00) && std::isfinite(l01) && std::isfinite(l10) && std::isfinite(l11))) return false;
  const double dl00 = dt * l00, dl01 = dt * l01, dl10 = dt * l10, dl11 = dt * l11;
  // (I + L Δt): the generic (a == b ? 1 : 0) + Δt l_ab; its out-of-plane entries are +0 and 1.
  const double i0 = 1.0 + dl00, i1 = 0.0 + dl01, i3 = 0.0 + dl10, i4 = 1.0 + dl11;
  if (!(std::isfinite(i0) && std::isfinite(i1) && std::isfinite(i3) && std::isfinite(i4))) return false;
  // Δε = sym(L) Δt in Voigt order; sym_01 = sym_10 (addition commutes).
  const double sym00 = 0.5 * (l00 + l00) * dt, sym11 = 0.5 * (l11 + l11) * dt, sym01 = 0.5 * (l01 + l10) * dt;
  const double zero = 0.5 * (0.0 + 0.0) * dt;  // sym_22, sym_12, ... as the generic code makes them
  de[0] = sym00;
  de[1] = sym11;
  de[2] = zero;
  de[3] = 0.5 * (zero + zero);
  de[4] = 0.5 * (zero + zero);
  de[5] = 0.5 * (sym01 + sym01);
  // F ← (I + L Δt) F: F_ab + Σ_c Δt l_ac F_cb, the c = 2 term (+0 · F_2b, F_2b = +0) left out.
  const double F00 = F[0], F01 = F[1], F10 = F[3], F11 = F[4];
  F[0] = (F00 + dl00 * F00) + dl01 * F10;
  F[1] = (F01 + dl00 * F01) + dl01 * F11;
  F[3] = (F10 + dl10 * F00) + dl11 * F10;
  F[4] = (F11 + dl10 * F01) + dl11 * F11;
  // det(I + L Δt) by the generic cofactor expansion with its +0 entries and the 1 taken out.
  J_ratio = i0 * i4 - i1 * i3;
  // Jaumann: σ + Δt (Wσ − σW), W_01 = ½(l_01 − l_10), W_10 = ½(l_10 − l_01), the rest ±0.
  std::copy(start, start + 6, rotated);
  if (jaumann) {
    const double W01 = 0.5 * (l01 - l10), W10 = 0.5 * (l10 - l01);
    const double S00 = start[0], S11 = start[1], S22 = start[2], S12 = start[3], S02 = start[4], S01 = start[5];
    const double S10 = S01, S21 = S12, S20 = S02;
    const double out00 = S00 + dt * ((0.0 + W01 * S10) - (0.0 + S01 * W10));
    const double out01 = S01 + dt * ((0.0 + W01 * S11) - (0.0 + S00 * W01));
    const double out02 = S02 + dt * ((0.0 + W01 * S12) - 0.0);
    const double out10 = S10 + dt * ((0.0 + W10 * S00) - (0.0 + S11 * W10));
    const double out11 = S11 + dt * ((0.0 + W10 * S01) - (0.0 + S10 * W01));
    const double out12 = S12 + dt * ((0.0 + W10 * S02) - 0.0);
    const double out20 = S20 + dt * (0.0 - (0.0 + S21 * W10));
    const double out21 = S21 + dt * (0.0 - (0.0 + S20 * W01));
    const double out22 = S22 + dt * (0.0 - 0.0);
    rotated[0] = out00;
    rotated[1] = out11;
    rotated[2] = out22;
    rotated[3] = 0.5 * (out12 + out21);
    rotated[4] = 0.5 * (out02 + out20);
    rotated[5] = 0.5 * (out01 + out10);
  }
  return true;
}

}  // namespace

template <int Dim>
ParamSchema MechanicalPhysics<Dim>::schema() {
  ParamSchema s;
  s.real("flip_fraction", "-",
         "particle velocity update: 1 = FLIP (paper Algorithm 1), 0 = PIC (damps), between: a blend")
      .defaults_to(1.0)
      .at_least(0)
      .at_most(1);
  s.real("cfl", "-", "fraction of the stable step h / (c_p + |v|), c_p the P-wave speed of the skeleton")
      .defaults_to(0.5)
      .above(0)
      .at_most(1);
  s.real("local_damping", "-",
         "Cundall's local damping α: each nodal force component is reduced by α |f| in the direction of "
         "the node's velocity (quasi-static runs: 0.05–0.8; 0 = none, dynamics)")
      .defaults_to(0.0)
      .at_least(0)
      .below(1);
  s.real("minimum_node_mass", "-",
         "a node's inertia in the skeleton's momentum balance and pressure correction is at least this fraction "
         "of the mass of the heaviest material point whose domain reaches it: a node a particle only grazes "
         "(a heaving or sliding surface) takes the bounded kick that reaches the particles, not one ∝ 1/overlap "
         "(0: the lumped mass alone)")
      .defaults_to(0.1)
      .at_least(0)
      .at_most(1);
  s.choice("position_update", {"symplectic", "trapezoidal"},
           "symplectic: x += Δt v^k (the velocity the stress update used; second order); trapezoidal: "
           "x += Δt (v^k + ½ Δv), the paper's Algorithm 1 step 21 (first order with its stress update)")
      .defaults_to("symplectic");
  s.choice("volumetric_strain", {"particle", "cell_average"},
           "the volumetric strain increment the constitutive model sees: each particle's own, or the "
           "volume-weighted mean over the particles in its grid cell (cell_average: a remedy for the volumetric "
           "locking of nearly incompressible or isochoric plastic flow, Mast et al. 2012, with the nodal forces "
           "taking the cell's mean stress as B-bar does and the particle's volume change following the cell's mean "
           "as F-bar does; the deviatoric part stays its own)")
      .defaults_to("particle");
  s.choice("objective_rate", {"jaumann", "none"},
           "stress rate: Jaumann (objective, large rotations) or none (small-strain comparison)")
      .defaults_to("jaumann");
  s.choice("initial_stress", {"none", "geostatic"},
           "geostatic: σ′_v from the weight of the material above each particle (minus the pore pressure), "
           "σ′_h = σ′_zz = K0 σ′_v with the material's k0, and with gravity tilted along the layer the shear "
           "that balances it (an infinite slope); gravity must point down (−y)")
      .defaults_to("none");
  return s;
}

template <int Dim>
MechanicalPhysics<Dim>::MechanicalPhysics(const ParamSet& p) : params_(p) {
  flip_ = p.real("flip_fraction");
  cfl_ = p.real("cfl");
  damping_ = p.real("local_damping");
  minimum_node_mass_ = p.real("minimum_node_mass");
  jaumann_ = p.string("objective_rate") == "jaumann";
  trapezoidal_ = p.string("position_update") == "trapezoidal";
  geostatic_ = p.string("initial_stress") == "geostatic";
  cell_average_ = p.string("volumetric_strain") == "cell_average";
  position_ = FieldHandle::particle("position", Dim, FieldKind::Vector);
  half_size_ = FieldHandle::particle("half_size", Dim, FieldKind::Vector);
  volume_ = FieldHandle::particle("volume");
  porosity_ = FieldHandle::particle("porosity");
  velocity_ = FieldHandle::particle("solid_velocity", Dim, FieldKind::Vector);
  displacement_ = FieldHandle::particle("displacement", Dim, FieldKind::Vector);
  stress_ = FieldHandle::particle("stress", 6, FieldKind::SymmetricTensor);
  stress_start_ = FieldHandle::particle(ParticleStore::history_name("stress"), 6, FieldKind::SymmetricTensor);
  strain_ = FieldHandle::particle("strain", 6, FieldKind::SymmetricTensor);
  grain_thermal_strain_ = FieldHandle::particle("thermal_strain");
  deformation_ = FieldHandle::particle("deformation_gradient", 9, FieldKind::Tensor);
  inertia_ = FieldHandle::particle("skeleton_inertia");
  shear_ = FieldHandle::particle("shear_modulus");
  temperature_ = FieldHandle::particle("temperature");
  saturation_ = FieldHandle::particle("liquid_saturation");
  pore_pressure_ = FieldHandle::particle("pore_pressure");
  liquid_drag_ = FieldHandle::particle("liquid_drag");
  liquid_reaction_ = FieldHandle::particle("liquid_reaction", Dim, FieldKind::Vector);
  liquid_share_ = FieldHandle::particle("liquid_pressure_share");
  node_velocity_ = FieldHandle::node("solid_velocity", Dim);
  node_predicted_ = FieldHandle::node("solid_velocity_predicted", Dim);
  node_increment_ = FieldHandle::node("pressure_increment");
  node_pressure_ = FieldHandle::node("pore_pressure");
  node_mobility_ = FieldHandle::node("solid_mobility", Dim);
  node_group_ = FieldHandle::node("solid_group");
}

template <int Dim>
ParamSchema MechanicalPhysics<Dim>::material_schema() const {
  ParamSchema s;
  declare_pore_space_keys(s);
  declare_solid_density(s);
  declare_solid_thermal_expansion(s);
  s.real("k0", "-", "coefficient of earth pressure at rest K0 = σ′_h/σ′_v of a geostatic initial stress")
      .defaults_to(0.5)
      .above(0)
      .at_most(5);
  return s;
}

template <int Dim>
void MechanicalPhysics<Dim>::setup(Kernel<Dim>& kernel) {
  kernel_ = &kernel;
  mass_scaling_ = kernel.time_params().real("mass_scaling");
  kernel.declare_state_field("porosity", "1", 1, 0.0);
  kernel.declare_state_field("solid_velocity", "m/s", Dim, 0.0, /*max_magnitude=*/1e4, FieldKind::Vector);
  kernel.declare_field("displacement", "m", Dim, 0.0, FieldKind::Vector);
  kernel.declare_history("stress", "Pa", 6, 0.0, FieldKind::SymmetricTensor);
  kernel.declare_field("strain", "1", 6, 0.0, FieldKind::SymmetricTensor);
  // strain − thermal_strain·I is the strain the stress answers to (what the paper's code writes as
  // its strain); it stays 0 without a thermal physics or a thermal expansion.
  kernel.declare_field("thermal_strain", "1", 1, 0.0);
  kernel.declare_field("deformation_gradient", "1", 9, 0.0, FieldKind::Tensor);
  kernel.declare_field("skeleton_inertia", "kg/m^3");  // the skeleton's (mass-scaled) density
  kernel.declare_field("shear_modulus", "Pa");
  kernel.fill_from_materials("porosity", "porosity");

  for (const auto& m : kernel.materials()) {
    MaterialData data;
    const ModelSection& section = m.models.at("mechanical_model");
    data.model = section.create<MechanicalModel>(kernel.registry());
    data.model_name = section.entry->name;
    data.solid_density = m.params.real("solid_density");
    data.water_density = m.params.real("water_density");
    data.ice_density = m.params.real("ice_density");
    data.expansion = m.params.real("solid_thermal_expansion");
    data.k0 = m.params.real("k0");
    for (const auto& variable : data.model->internal_variables()) {
      auto it = std::find_if(variable_list_.begin(), variable_list_.end(),
                             [&](const InternalVariable& v) { return v.name == variable.name; });
      if (it == variable_list_.end()) {
        if (kernel.has_particle_field(variable.name))
          throw InputError(section.where, "mechanical model '" + data.model_name + "' names an internal variable '" +
                                              variable.name + "', which is already a particle field of this scene");
        variable_list_.push_back(variable);
        it = variable_list_.end() - 1;
      } else if (it->unit != variable.unit) {
        throw InputError(section.where, "mechanical model '" + data.model_name + "' gives its internal variable '" +
                                            variable.name + "' the unit '" + variable.unit + "', another material's model '" +
                                            it->unit + "'");
      }
      data.variables.push_back(static_cast<std::size_t>(it - variable_list_.begin()));
    }
    materials_.push_back(std::move(data));
  }
  variables_.reserve(variable_list_.size());
  variables_start_.reserve(variable_list_.size());
  for (const auto& [name, unit] : variable_list_) {
    kernel.declare_history(name, unit, 1, 0.0, FieldKind::Scalar);
    variables_.push_back(FieldHandle::particle(name));
    variables_start_.push_back(FieldHandle::particle(ParticleStore::history_name(name)));
  }
  warn_of_locking(kernel);
  if (geostatic_) {
    const auto g = kernel.gravity();
    if (!(g[Dim - 1] < 0))
      throw params_.error("initial_stress",
                          "a geostatic initial stress needs gravity with a downward (−y) component, e.g. [0, -9.81]");
  }
  read_boundaries(kernel);

  const std::size_t n = kernel.particle_count(), nodes = kernel.grid().node_count();
  strain_increment_.assign(6 * n, 0.0);
  if (cell_average_) {
    thermal_strain_.assign(n, 0.0);
    volume_ratio_.assign(n, 1.0);
  }
  rotated_.assign(6 * n, 0.0);
  wave_modulus_.assign(n, 0.0);
  previous_T_.assign(n, 0.0);
  failed_.assign(n, 0);
  for (auto* v : {&mass_, &drag_, &weight_, &nodal_inertia_}) v->assign(nodes, 0.0);
  for (auto* v : {&force_, &momentum_, &start_velocity_, &mapped_velocity_}) v->assign(nodes * Dim, 0.0);
}

/// Plastic flow at ψ = 0 keeps the volume, and linear/GIMP cells cannot follow it particle by
/// particle: the default (each particle's own volumetric strain) then over-predicts strength by
/// tens of per cent, or holds a slope that should flow. A scene that chose it keeps it silently.
template <int Dim>
void MechanicalPhysics<Dim>::warn_of_locking(const Kernel<Dim>& kernel) const {
  if (cell_average_ || params_.given("volumetric_strain")) return;
  for (std::size_t i = 0; i < materials_.size(); ++i) {
    if (!materials_[i].model->yield_function({}, {}, {})) continue;  // no yield surface: elastic
    log::warning(params_.where("volumetric_strain").describe() + ": material '" + kernel.materials()[i].name +
                 "' is plastic ('" + materials_[i].model_name +
                 "'), and each particle's own volumetric strain (volumetric_strain: particle, the default) locks "
                 "plastic flow that keeps its volume: footings read too strong, slopes creep that should flow "
                 "(user guide, volumetric locking); set volumetric_strain: cell_average, or particle to keep it");
    return;
  }
}

template <int Dim>
std::vector<Stage> MechanicalPhysics<Dim>::stages() {
  std::vector<FieldRef> start_reads = {position_.read(),          volume_.read(),     porosity_.read(), half_size_.read(),
                                       velocity_.read(),          stress_start_.read(), deformation_.read(),
                                       temperature_.optional_read(), saturation_.optional_read(),
                                       pore_pressure_.optional_read()};
  std::vector<FieldRef> start_writes = {node_velocity_.write(), stress_.write(),   strain_.write(),
                                        grain_thermal_strain_.write(), deformation_.write(), porosity_.write(),
                                        inertia_.write(),       shear_.write()};
  for (auto& h : variables_start_) start_reads.push_back(h.read());
  for (auto& h : variables_) start_writes.push_back(h.write());
  return {
      {"mechanical.map_to_grid", Phase::MapToGrid, start_reads, start_writes, [this] { map_to_grid(); }},
      {"mechanical.predict",
       Phase::PredictMomentum,
       {node_velocity_.read(), stress_.read(), half_size_.read(), node_pressure_.optional_read(), liquid_drag_.optional_read(),
        liquid_reaction_.optional_read(), volume_.read(), porosity_.read(), saturation_.optional_read()},
       {node_predicted_.write(), node_mobility_.write(), node_group_.write()},
       [this] { predict(); }},
      {"mechanical.correct",
       Phase::CorrectMomentum,
       {node_predicted_.read(), node_increment_.optional_read(), liquid_share_.optional_read(), volume_.read()},
       {node_velocity_.write()},
       [this] { correct(); }},
      {"mechanical.map_to_particles",
       Phase::MapToParticles,
       {node_velocity_.read(), velocity_.read(), position_.read(), displacement_.read(), stress_.read(), shear_.read(),
        volume_.read(), inertia_.read()},
       {velocity_.write(), position_.write(), displacement_.write()},
       [this] { map_to_particles(); }},
  };
}

template <int Dim>
typename MechanicalPhysics<Dim>::DensityView MechanicalPhysics<Dim>::density_view() const {
  return {materials_.data(),
          kernel_->transfer().materials().data(),
          porosity_.values().data(),
          saturation_.bound() ? saturation_.values().data() : nullptr,
          particle_mass_.empty() ? nullptr : particle_mass_.data(),
          volume_.values().data()};
}

template <int Dim>
[[gnu::always_inline]] inline void MechanicalPhysics<Dim>::DensityView::operator()(std::size_t p, double& rho_m,
                                                                                   double& skeleton,
                                                                                   double& n_l) const {
  const auto& m = materials[material[p]];
  const double phi = porosity[p];
  const double S = saturation ? std::clamp(saturation[p], 0.0, 1.0) : 1.0;
  n_l = phi * S;
  skeleton = (1.0 - phi) * m.solid_density + phi * (1.0 - S) * m.ice_density;
  rho_m = skeleton + n_l * m.water_density;
  // Without pore-water flow the mixture is one phase whose mass each particle keeps (a
  // total-stress analysis): the density follows the volume.
  if (particle_mass) rho_m = skeleton = particle_mass[p] / volume[p];
}

template <int Dim>
void MechanicalPhysics<Dim>::densities(std::size_t p, double& rho_m, double& skeleton, double& n_l) const {
  density_view()(p, rho_m, skeleton, n_l);
}

template <int Dim>
void MechanicalPhysics<Dim>::initialize() {
  step_limit_valid_ = false;
  // F = I; the particles' moduli from the models' bounds until the first stress update.
  auto F = deformation_.mutable_values();
  const std::size_t n = kernel_->particle_count();
  for (std::size_t p = 0; p < n; ++p)
    for (int i = 0; i < 9; ++i) F[9 * p + i] = (i % 4 == 0) ? 1.0 : 0.0;
  for (std::size_t p = 0; p < n; ++p)
    wave_modulus_[p] = materials_[kernel_->transfer().material(p)].model->max_p_wave_modulus();
  for (std::size_t v = 0; v < variables_.size(); ++v) {
    auto values = variables_[v].mutable_values();
    for (std::size_t p = 0; p < n; ++p) {
      const auto& m = materials_[kernel_->transfer().material(p)];
      const auto it = std::find(m.variables.begin(), m.variables.end(), v);
      values[p] = it == m.variables.end() ? 0.0 : m.model->initial_state()[std::size_t(it - m.variables.begin())];
    }
  }
  particle_mass_.clear();
  if (!liquid_drag_.bound()) {
    std::vector<double> mass(n);
    const auto V = volume_.values();
    for (std::size_t p = 0; p < n; ++p) {
      double rho_m, skeleton, n_l;
      densities(p, rho_m, skeleton, n_l);
      mass[p] = rho_m * V[p];
    }
    particle_mass_ = std::move(mass);
  }
  if (geostatic_) set_geostatic_stress();
  auto inertia = inertia_.mutable_values();
  for (std::size_t p = 0; p < n; ++p) {
    double rho_m, skeleton, n_l;
    densities(p, rho_m, skeleton, n_l);
    inertia[p] = mass_scaling_ * (liquid_drag_.bound() ? skeleton : rho_m);
  }
}

/// σ′_v(p) = −|g| (Σ over the particles above p in its column of ρ_m Δz + ½ ρ_m Δz of p) + p_l,
/// σ′_h = σ′_zz = K0 σ′_v: the weight of the material above, with the pore pressure taken off
/// (σ = σ′ − p_l I). Δz is a particle's height, twice its GIMP half-width. Gravity with a
/// component g_x along the layer (an infinite slope in its own frame, gravity tilted by the slope
/// angle) adds the shear that balances it, σ_xy = g_x (Σ ρ_m Δz + ½ ρ_m Δz of p).
template <int Dim>
void MechanicalPhysics<Dim>::set_geostatic_stress() {
  const auto x = position_.values();
  const auto half = half_size_.values();
  const std::size_t n = kernel_->particle_count();
  const auto gravity = kernel_->gravity();
  const double g = -gravity[Dim - 1];
  const auto& grid = kernel_->grid();
  // Columns: particles with the same horizontal coordinates (the lattice they were made on).
  std::map<std::vector<long>, std::vector<std::size_t>> columns;
  for (std::size_t p = 0; p < n; ++p) {
    std::vector<long> key;
    for (int d = 0; d + 1 < Dim; ++d) key.push_back(std::lround((x[p * Dim + d] - grid.origin[d]) / (1e-6 * grid.spacing[d])));
    columns[key].push_back(p);
  }
  const auto pl = pore_pressure_.bound() ? pore_pressure_.values() : std::span<const double>{};
  auto sigma = stress_.mutable_values();
  for (auto& [_, members] : columns) {
    std::sort(members.begin(), members.end(),
              [&](std::size_t a, std::size_t b) { return x[a * Dim + Dim - 1] > x[b * Dim + Dim - 1]; });
    double above = 0;  // weight per horizontal area of the particles above [Pa]
    for (std::size_t p : members) {
      double rho_m, skeleton, n_l;
      densities(p, rho_m, skeleton, n_l);
      const double dz = 2.0 * half[p * Dim + Dim - 1];
      const double column = above + 0.5 * rho_m * dz;  // mass per horizontal area above p's centre
      const double vertical = -g * column + (pl.empty() ? 0.0 : pl[p]);
      above += rho_m * dz;
      const double k0 = materials_[kernel_->transfer().material(p)].k0;
      double* s = sigma.data() + 6 * p;
      std::fill(s, s + 6, 0.0);
      for (int d = 0; d < 3; ++d) s[d] = k0 * vertical;
      s[Dim - 1] = vertical;
      for (int d = 0; d + 1 < Dim; ++d) s[tensor3::kVoigt[d][Dim - 1]] = gravity[d] * column;
    }
  }
}

template <int Dim>
void MechanicalPhysics<Dim>::begin_step(double time, double dt) {
  time_ = time;
  dt_ = dt;
  place_footings();
}

template <int Dim>
double MechanicalPhysics<Dim>::stable_time_step() const {
  // A footing crosses less than a cell per step, as the material does.
  if (step_limit_valid_) return cfl_ * std::min(step_limit_, footing_limit_);
  // The same limit as map_to_particles takes.
  const double h = kernel_->grid().min_spacing();
  const auto v = velocity_.values();
  const auto inertia = inertia_.values();
  const std::size_t n = kernel_->particle_count();
  const double limit = parallel_min(
      n,
      [&](std::size_t p) {
        double speed2 = 0;
        for (int d = 0; d < Dim; ++d) speed2 += v[p * Dim + d] * v[p * Dim + d];
        const double c = inertia[p] > 0 ? std::sqrt(wave_modulus_[p] / inertia[p]) : 0.0;
        const double speed = c + std::sqrt(speed2);
        return speed > 0 ? h / speed : std::numeric_limits<double>::infinity();
      },
      std::numeric_limits<double>::infinity());
  return cfl_ * std::min(limit, footing_limit_);
}

// ---- the step --------------------------------------------------------------------------------------

template <int Dim>
void MechanicalPhysics<Dim>::map_to_grid() {
  step_limit_valid_ = false;  // the step changes the moduli, the inertia and the velocities
  const auto& transfer = kernel_->transfer();
  const auto& st = transfer.stencil();
  const auto vol = volume_.values();
  const auto v = velocity_.values();
  const auto inertia = inertia_.values();
  std::fill(mass_.begin(), mass_.end(), 0.0);
  std::fill(momentum_.begin(), momentum_.end(), 0.0);
  // The floor under the inertia (predict()) scatters first: minimum_node_mass × the heaviest
  // particle whose domain reaches the node; the node loop below raises it to the node's mass.
  std::fill(nodal_inertia_.begin(), nodal_inertia_.end(), 0.0);
  double* mass = mass_.data();
  double* momentum = momentum_.data();
  double* inertia_floor = nodal_inertia_.data();
  const double mu = minimum_node_mass_;
  for_support<Dim>(st.per_particle(), [&](auto K) {
    transfer.scatter([&](std::size_t p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      const double m = vol[p] * inertia[p];
      std::array<double, Dim> vp;
      for (int d = 0; d < Dim; ++d) vp[d] = v[p * Dim + d];
      double m_k[kMaxSupport], p_k[kMaxSupport * Dim];  // contributions first, as in predict()
      for (int k = 0; k < K; ++k) {
        const double wm = w[k] * m;
        m_k[k] = wm;
        for (int d = 0; d < Dim; ++d) p_k[k * Dim + d] = wm * vp[d];
      }
      for (int k = 0; k < K; ++k) {
        mass[nodes[k]] += m_k[k];
        // Branch-free: whether a weight is zero follows the particle's place in its cell.
        inertia_floor[nodes[k]] = std::max(inertia_floor[nodes[k]], w[k] > 0 ? mu * m : 0.0);
        for (int d = 0; d < Dim; ++d) momentum[nodes[k] * Dim + d] += p_k[k * Dim + d];
      }
    });
  });
  auto& vn = node_velocity_.vector();
  parallel_for(mass_.size(), [&](std::size_t i) {
    for (int d = 0; d < Dim; ++d) vn[i * Dim + d] = mass_[i] > 0 ? momentum_[i * Dim + d] / mass_[i] : 0.0;
    nodal_inertia_[i] = std::max(mass_[i], nodal_inertia_[i]);
  });
  tie_plates(vn, time_, 0.0, false);
  constrain(vn, time_, 0.0);
  std::copy(vn.begin(), vn.end(), start_velocity_.begin());
  update_stress();
}

/// At every particle: the velocity gradient of v^k, the strain increment, the Jaumann rotation
/// and the constitutive model; F, porosity and the skeleton's inertia follow.
template <int Dim>
void MechanicalPhysics<Dim>::update_stress() {
  const auto& transfer = kernel_->transfer();
  const auto& vn = node_velocity_.vector();
  const std::size_t n = kernel_->particle_count();
  auto F = deformation_.mutable_values();
  auto phi = porosity_.mutable_values();
  auto strain = strain_.mutable_values();
  const auto sigma_start = stress_start_.values();
  const bool thermal = temperature_.bound();
  const auto T = thermal ? temperature_.values() : std::span<const double>{};
  if (thermal && !primed_) {
    std::copy(T.begin(), T.end(), previous_T_.begin());
    primed_ = true;
  }
  // The skeleton's inertia follows the new porosity (and the volume of the step's start).
  auto inertia = inertia_.mutable_values();
  const DensityView density = density_view();
  const bool two_phase = liquid_drag_.bound();
  const auto grain_strain = thermal ? grain_thermal_strain_.mutable_values() : std::span<double>{};
  long invalid = -1;
  // The step's volume ratio J and the grains' expansion 1 + β_s ΔT give the new porosity from the
  // conserved solid volume, and the porosity the skeleton's inertia.
  auto close_volume = [&](std::size_t p, double J_ratio, double grain_expansion) {
    const double new_phi = 1.0 - (1.0 - phi[p]) * grain_expansion / J_ratio;
    if (!(new_phi > 0.0 && new_phi < 1.0) || !(J_ratio > 0)) {
#pragma omp critical
      invalid = invalid < 0 ? long(p) : std::min(invalid, long(p));
      return;
    }
    phi[p] = new_phi;
    double rho_m, skeleton, n_l;
    density(p, rho_m, skeleton, n_l);
    inertia[p] = mass_scaling_ * (two_phase ? skeleton : rho_m);
  };
  // Kinematics of particle p: Δε (less the grains' thermal strain) into de, the rotated start
  // stress into rotated; F, the total strain and the grains' thermal strain updated.
  struct Kinematics {
    double J_ratio;          ///< the step's volume ratio det(I + L Δt)
    double thermal_strain;   ///< β_s ΔT / 3
    double grain_expansion;  ///< 1 + β_s ΔT
  };
  auto kinematics = [&](auto support, std::size_t p, double* de, double* rotated) {
    const auto L = transfer.vector_gradient_at(p, vn, support);
    const auto& m = materials_[transfer.material(p)];
    // Thermal strain of the grains: β_s ΔT / 3 on each normal component (β_s is volumetric).
    const double dT = thermal ? T[p] - previous_T_[p] : 0.0;
    const double thermal_strain = thermal ? m.expansion * dT / 3.0 : m.expansion * 0.0;  // its signed zero as before
    // Kinematics: Δε, F ← (I + L Δt) F, the volume ratio and the rotated start stress.
    double J_ratio = 0;
    bool done = false;
    if constexpr (Dim == 2)
      done = plane_strain_kinematics(L, dt_, F.data() + 9 * p, de, J_ratio, jaumann_, sigma_start.data() + 6 * p,
                                     rotated);
    if (!done) {
      tensor3::Mat l{}, W{};
      for (int a = 0; a < Dim; ++a)
        for (int b = 0; b < Dim; ++b) l[a][b] = L[a][b];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) W[a][b] = 0.5 * (l[a][b] - l[b][a]);
      tensor3::Mat sym{};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) sym[a][b] = 0.5 * (l[a][b] + l[b][a]) * dt_;
      tensor3::from_matrix(sym, de);
      double f[9];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          double s = F[9 * p + 3 * a + b];
          for (int c = 0; c < 3; ++c) s += dt_ * l[a][c] * F[9 * p + 3 * c + b];
          f[3 * a + b] = s;
        }
      double increment[9];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) increment[3 * a + b] = (a == b ? 1.0 : 0.0) + dt_ * l[a][b];
      J_ratio = increment[0] * (increment[4] * increment[8] - increment[5] * increment[7]) -
                increment[1] * (increment[3] * increment[8] - increment[5] * increment[6]) +
                increment[2] * (increment[3] * increment[7] - increment[4] * increment[6]);
      std::copy(f, f + 9, F.data() + 9 * p);
      std::copy(sigma_start.data() + 6 * p, sigma_start.data() + 6 * p + 6, rotated);
      if (jaumann_) tensor3::jaumann_rotate(W, dt_, rotated);
    }
    for (int i = 0; i < 6; ++i) strain[6 * p + i] += de[i];
    for (int i = 0; i < 3; ++i) de[i] -= thermal_strain;
    if (thermal) {
      grain_strain[p] += thermal_strain;
      previous_T_[p] = T[p];
    }
    return Kinematics{J_ratio, thermal_strain, 1.0 + m.expansion * dT};
  };

  // The constitutive model on one chunk [b, b + k) of material m's particles, from the strain
  // increments and rotated start stresses at de and rotated; the model's inputs and its internal
  // variables gathered for the chunk alone.
  auto sigma = stress_.mutable_values();
  const auto S = saturation_.bound() ? saturation_.values() : std::span<const double>{};
  const auto pl = pore_pressure_.bound() ? pore_pressure_.values() : std::span<const double>{};
  const auto shear = shear_.mutable_values();
  auto integrate_chunk = [&](const MaterialData& m, std::size_t b, std::size_t k, const double* de, const double* rotated) {
    const std::size_t nv = m.variables.size();
    std::vector<double> state_in(k * nv, 0.0), state_out(k * nv, 0.0), ice;
    for (std::size_t v = 0; v < nv; ++v) {
      const auto start = variables_start_[m.variables[v]].values();
      for (std::size_t i = 0; i < k; ++i) state_in[i * nv + v] = start[b + i];
    }
    if (!S.empty()) {
      ice.resize(k);
      for (std::size_t i = 0; i < k; ++i) ice[i] = 1.0 - std::clamp(S[b + i], 0.0, 1.0);
    }
    StressUpdateInput in;
    in.strain_increment = {de, 6 * k};
    in.stress_start = {rotated, 6 * k};
    in.state_start = state_in;
    if (thermal) in.temperature = T.subspan(b, k);
    if (!ice.empty()) in.ice_saturation = ice;
    if (!pl.empty()) in.pore_pressure = pl.subspan(b, k);
    in.dt = dt_;
    StressUpdateOutput out;
    out.stress = sigma.subspan(6 * b, 6 * k);
    out.state = state_out;
    out.failed = {failed_.data() + b, k};
    out.p_wave_modulus = {wave_modulus_.data() + b, k};
    out.shear_modulus = shear.subspan(b, k);
    m.model->integrate(in, out);
    for (std::size_t v = 0; v < nv; ++v) {
      auto values = variables_[m.variables[v]].mutable_values();
      for (std::size_t i = 0; i < k; ++i) values[b + i] = state_out[i * nv + v];
    }
  };
  auto check_volumes = [&] {
    if (invalid < 0) return;
    std::ostringstream msg;
    msg << "numerical blow-up: the skeleton at " << kernel_->describe_particle(std::size_t(invalid))
        << " was compressed or stretched beyond its solid volume (porosity would leave (0, 1)) at t = " << time_
        << " s, step " << kernel_->step() << " (dt = " << dt_ << " s); the step may be too large or the loads too high";
    throw NumericalBlowUp(msg.str());
  };

  // Chunks of 512 particles of one material, which the threads share (every point is integrated
  // on its own, so the chunks change no result); small enough that a 4k-particle scene fills two threads.
  constexpr std::size_t kChunk = 512;
  std::fill(failed_.begin(), failed_.end(), 0);
  if (cell_average_) {
    // The volumetric strain of each cell's mean first, then the models.
    for_support<Dim>(transfer.stencil().per_particle(), [&](auto support) {
      parallel_for(n, [&](std::size_t p) {
        const Kinematics step = kinematics(support, p, strain_increment_.data() + 6 * p, rotated_.data() + 6 * p);
        thermal_strain_[p] = step.thermal_strain;  // the volume follows its cell's mean below (F-bar)
        volume_ratio_[p] = step.J_ratio;
      });
    });
    average_volumetric_strain();
    average_volume_ratio(F, close_volume);
    check_volumes();
    for (const auto& r : kernel_->particle_ranges())
      parallel_chunks(r.size(), kChunk, [&](std::size_t offset, std::size_t k) {
        const std::size_t b = r.begin + offset;
        integrate_chunk(materials_[r.material], b, k, strain_increment_.data() + 6 * b, rotated_.data() + 6 * b);
      });
  } else {
    // Kinematics and model chunk by chunk: the strain increments and rotated stresses stay in
    // the chunk's own buffers (in cache) between the two.
    for_support<Dim>(transfer.stencil().per_particle(), [&](auto support) {
      for (const auto& r : kernel_->particle_ranges()) {
        const auto& m = materials_[r.material];
        parallel_chunks(r.size(), kChunk, [&](std::size_t offset, std::size_t k) {
          const std::size_t b = r.begin + offset;
          // Written whole below before they are read: no zeroing (120k particles: 11 MB a step).
          const auto de = std::make_unique_for_overwrite<double[]>(6 * k);
          const auto rotated = std::make_unique_for_overwrite<double[]>(6 * k);
          for (std::size_t i = 0; i < k; ++i) {
            const std::size_t p = b + i;
            const Kinematics step = kinematics(support, p, de.get() + 6 * i, rotated.get() + 6 * i);
            close_volume(p, step.J_ratio, step.grain_expansion);
          }
          integrate_chunk(m, b, k, de.get(), rotated.get());
        });
      }
    });
    check_volumes();
  }
  if (const auto first = std::find_if(failed_.begin(), failed_.end(), [](std::uint8_t f) { return f != 0; });
      first != failed_.end())
    report_failure(std::size_t(first - failed_.begin()));
}

/// The volume-weighted mean of value(p) over the particles of each grid cell, into cell_mean_,
/// with the cells and their volumes of the step (cell_of_, cell_volume_: average_volumetric_strain).
/// The sums run in particle order on one thread: the same whatever the thread count.
template <int Dim>
template <class Value>
void MechanicalPhysics<Dim>::average_over_cells(Value value) {
  const auto vol = volume_.values();
  cell_mean_.assign(cell_volume_.size(), 0.0);
  for (std::size_t p = 0; p < cell_of_.size(); ++p) cell_mean_[cell_of_[p]] += vol[p] * value(p);
  for (std::size_t c = 0; c < cell_mean_.size(); ++c)
    if (cell_volume_[c] > 0) cell_mean_[c] /= cell_volume_[c];
}

/// The volumetric part of every particle's strain increment replaced by the volume-weighted mean
/// of the kinematic volumetric increments in its grid cell (its own thermal strain still taken
/// off): linear and GIMP shape functions give each cell too few independent volume changes for
/// isochoric flow, and the mean over the cell relaxes that constraint as a B-bar element does.
/// predict() closes the B-bar form with the cell's mean stress in the nodal forces.
template <int Dim>
void MechanicalPhysics<Dim>::average_volumetric_strain() {
  // The particles' cells and the cells' volumes, for the step (predict() uses them too: nothing
  // moves between the two).
  const auto& grid = kernel_->grid();
  const auto x = position_.values();
  const auto vol = volume_.values();
  const std::size_t n = kernel_->particle_count();
  cell_of_.resize(n);
  parallel_for(n, [&](std::size_t p) { cell_of_[p] = grid.cell_of(x.data() + p * Dim); });
  cell_volume_.assign(grid.cell_count(), 0.0);
  for (std::size_t p = 0; p < n; ++p) cell_volume_[cell_of_[p]] += vol[p];
  average_over_cells([&](std::size_t p) {
    const double* de = strain_increment_.data() + 6 * p;
    return de[0] + de[1] + de[2] + 3.0 * thermal_strain_[p];
  });
  parallel_for(n, [&](std::size_t p) {
    double* de = strain_increment_.data() + 6 * p;
    const double mean = cell_mean_[cell_of_[p]] - 3.0 * thermal_strain_[p];
    const double shift = (mean - (de[0] + de[1] + de[2])) / 3.0;
    for (int i = 0; i < 3; ++i) de[i] += shift;
  });
}

/// F-bar: every particle's volume ratio of the step replaced by the volume-weighted mean over
/// its grid cell, J̄, and its F scaled by (J̄/J)^(1/Dim) in the plane of motion, so that det F —
/// the particle's volume and porosity — follows the same cell mean as its volumetric strain.
/// Without it the cell's total volume change is right but its particles' own volumes stay free
/// to form a checkerboard, which drained soft soil lets run away. The cell's volume is kept.
template <int Dim>
template <class CloseVolume>
void MechanicalPhysics<Dim>::average_volume_ratio(std::span<double> F, CloseVolume close_volume) {
  average_over_cells([&](std::size_t p) { return volume_ratio_[p]; });
  const std::size_t n = volume_ratio_.size();
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
  for (std::size_t p = 0; p < n; ++p) {
    const double J = volume_ratio_[p], J_bar = cell_mean_[cell_of_[p]];
    if (J > 0 && J_bar > 0) {
      const double scale = std::pow(J_bar / J, 1.0 / Dim);
      for (int a = 0; a < Dim; ++a)
        for (int b = 0; b < Dim; ++b) F[9 * p + 3 * a + b] *= scale;
    }
    close_volume(p, J > 0 ? J_bar : J, 1.0 + 3.0 * thermal_strain_[p]);
  }
}

template <int Dim>
void MechanicalPhysics<Dim>::report_failure(std::size_t p) const {
  const auto& m = materials_[kernel_->transfer().material(p)];
  std::ostringstream msg;
  msg << "numerical blow-up: mechanical model '" << m.model_name << "' could not integrate the stress at "
      << kernel_->describe_particle(p) << " at t = " << time_ << " s, step " << kernel_->step() << " (dt = " << dt_
      << " s); a smaller time step or other model parameters may help";
  throw NumericalBlowUp(msg.str());
}

/// Nodal forces and the predictor v* = (m v + Δt f) / (m + Δt D) (paper Eq. 43, the skeleton's
/// part with the liquid's implicit drag when a hydraulic physics runs, models/two_phase.hpp).
template <int Dim>
void MechanicalPhysics<Dim>::predict() {
  const auto& transfer = kernel_->transfer();
  const auto& st = transfer.stencil();
  const auto vol = volume_.values();
  auto sigma = stress_.values();
  const bool two_phase = liquid_drag_.bound();
  // The pore pressure of the step's start, as the liquid sees it: the nodal field.
  const auto pl = node_pressure_.bound() ? node_pressure_.values() : std::span<const double>{};
  const auto k = two_phase ? liquid_drag_.values() : std::span<const double>{};
  const auto R = two_phase ? liquid_reaction_.values() : std::span<const double>{};
  const auto g = kernel_->gravity();
  const int K = st.per_particle();
  std::fill(force_.begin(), force_.end(), 0.0);
  std::fill(drag_.begin(), drag_.end(), 0.0);
  std::fill(weight_.begin(), weight_.end(), 0.0);
  const DensityView density = density_view();
  double* force = force_.data();
  double* weight = weight_.data();
  double* drag = drag_.data();
  // B-bar's other half: the strains saw the cell's mean volumetric increment, so the forces see
  // the cell's mean stress (Σ V B̄ᵀσ). Without it the stress works on volume changes it never
  // saw: where plastic dilation (ψ > 0) makes the pressures within a cell differ, that spurious
  // power grows until particles are thrown out of the surface beside a footing.
  if (cell_average_) {
    const auto mean_stress = [&](std::size_t p) { return (sigma[6 * p] + sigma[6 * p + 1] + sigma[6 * p + 2]) / 3.0; };
    average_over_cells(mean_stress);
    force_stress_.assign(sigma.begin(), sigma.end());
    parallel_for(cell_of_.size(), [&](std::size_t p) {
      const double shift = cell_mean_[cell_of_[p]] - mean_stress(p);
      for (int i = 0; i < 3; ++i) force_stress_[6 * p + i] += shift;
    });
    sigma = force_stress_;
  }
  // One loop per combination of the liquid's reaction and the pore pressure, so that neither is
  // tested per node.
  auto scatter_forces = [&](auto support, auto with_liquid, auto with_pressure) {
    constexpr bool liquid = decltype(with_liquid)::value, pressure = decltype(with_pressure)::value;
    transfer.scatter([&](std::size_t p) {
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      const auto* grad = st.gradients(p);
      double rho_m, skeleton, n_l;
      density(p, rho_m, skeleton, n_l);
      // Total stress σ′ − p I, tension positive.
      double total[6];
      for (int i = 0; i < 6; ++i) total[i] = sigma[6 * p + i];
      if constexpr (pressure) {
        const double p_l = transfer.value_at(p, pl);
        for (int i = 0; i < 3; ++i) total[i] -= p_l;
      }
      const double V = vol[p];
      // The contributions first, then the additions into the nodes (each node's in the same
      // order): the arithmetic is not held up by stores that might alias its inputs.
      double f_a[kMaxSupport * Dim], weight_a[kMaxSupport], drag_a[kMaxSupport];
      for (int a = 0; a < support; ++a) {
        for (int d = 0; d < Dim; ++d) {
          double internal = 0;
          for (int e = 0; e < Dim; ++e) internal += total[tensor3::kVoigt[d][e]] * grad[a * Dim + e];
          double f = -V * internal + w[a] * V * rho_m * g[d];
          if constexpr (liquid) f += w[a] * V * R[p * Dim + d];
          f_a[a * Dim + d] = f;
        }
        weight_a[a] = w[a] * V * rho_m;
        if constexpr (liquid) drag_a[a] = w[a] * V * k[p];
      }
      for (int a = 0; a < support; ++a) {
        const std::size_t i = nodes[a];
        for (int d = 0; d < Dim; ++d) force[i * Dim + d] += f_a[a * Dim + d];
        weight[i] += weight_a[a];
        if constexpr (liquid) drag[i] += drag_a[a];
      }
    });
  };
  using yes = std::true_type;
  using no = std::false_type;
  for_support<Dim>(K, [&](auto support) {
    if (two_phase)
      pl.empty() ? scatter_forces(support, yes{}, no{}) : scatter_forces(support, yes{}, yes{});
    else
      pl.empty() ? scatter_forces(support, no{}, no{}) : scatter_forces(support, no{}, yes{});
  });
  const auto half = half_size_.values();
  for (auto& c : traction_bcs_) {
    c.applied = {};
    for (int d = 0; d < Dim; ++d) {
      const double t = c.value[d](time_);
      if (t == 0) continue;
      for (std::size_t j = 0; j < c.nodes.size(); ++j) {
        if (mass_[c.nodes[j]] <= 0) continue;  // past the material: nothing to push
        force_[c.nodes[j] * Dim + d] += t * c.areas[j];
        c.applied[d] += t * c.areas[j];
      }
      // On particles: each outer face, the particle's extent across the normal, through its weights.
      for (std::size_t p : c.particles) {
        double area = 1;
        for (int e = 0; e < Dim; ++e)
          if (e != c.normal_axis) area *= 2.0 * half[p * Dim + e];
        const auto* nodes = st.nodes(p);
        const auto* w = st.weights(p);
        for (int a = 0; a < K; ++a) force_[nodes[a] * Dim + d] += w[a] * t * area;
        c.applied[d] += t * area;
      }
    }
  }
  const auto& vn = node_velocity_.vector();
  auto& v_star = node_predicted_.vector();
  // A node that a particle's domain only grazes (a surface crossing a node row) has a mass ∝ ε²
  // of the overlap ε but a force ∝ ε. With its lumped mass its kick ∝ 1/ε is unbounded: a dry
  // step goes unstable there, and with pore water the kick counts in the pressure's volume
  // balance while the G2P–P2G round trip gives the node back only its weight S ∝ ε² of it — the
  // pressure answers a volume change that never happens. Its inertia is therefore at least
  // minimum_node_mass × the heaviest particle that reaches it (nodal_inertia_, map_to_grid();
  // docs/architecture.md, grazing nodes).
  parallel_for(mass_.size(), [&](std::size_t i) {
    const double m = nodal_inertia_[i];
    for (int d = 0; d < Dim; ++d)
      v_star[i * Dim + d] = m > 0 ? (m * vn[i * Dim + d] + dt_ * force_[i * Dim + d]) / (m + dt_ * drag_[i]) : 0.0;
  });
  for (auto& c : velocity_bcs_) c.reaction = {};
  for (auto& c : friction_bcs_) c.reaction = {};
  tie_plates(v_star, time_, dt_, true);
  // Cundall's local damping: a force against the motion, a fraction α of the unbalanced force —
  // the net force of the step (internal, body, traction, plate load and drag), m Δv*/Δt. Only on
  // free components: a held one takes its prescribed value, and its reaction must be the real
  // unbalanced force (damped, a footing read 1 + α times the stress under it); a plate moves as one.
  if (damping_ > 0)
    parallel_for(mass_.size(), [&](std::size_t i) {
      for (int d = 0; d < Dim; ++d) {
        if (constraint_owner_[i * Dim + d] != -1) continue;
        const double v = vn[i * Dim + d], change = v_star[i * Dim + d] - v;
        if (v != 0) v_star[i * Dim + d] = v + change - damping_ * std::abs(change) * (v > 0 ? 1.0 : -1.0);
      }
    });
  constrain(v_star, time_ + dt_, 1.0);
  // What a pressure increment can do to each nodal component, for the pore pressure's projection:
  // 1/(m + Δt D), none where a velocity condition holds it; the nodes of a rigid plate move as
  // one body (solid_group: 1 + plate·Dim + axis) of mobility 1/Σ(m + Δt D).
  auto mobility = node_mobility_.mutable_values();
  auto group = node_group_.mutable_values();
  parallel_for(mass_.size(), [&](std::size_t i) {
    const double m = nodal_inertia_[i] + dt_ * drag_[i];
    group[i] = 0;
    for (int d = 0; d < Dim; ++d)
      mobility[i * Dim + d] = mass_[i] > 0 && constraint_owner_[i * Dim + d] == -1 ? 1.0 / m : 0.0;
  });
  for (std::size_t k = 0; k < plates_.size(); ++k) {
    const auto& c = plates_[k];
    double inertia = 0;
    for (std::size_t i : c.nodes) inertia += mass_[i] > 0 ? mass_[i] + dt_ * drag_[i] : 0.0;
    for (std::size_t i : c.nodes) {
      if (mass_[i] <= 0) continue;
      mobility[i * Dim + c.axis] = inertia > 0 ? 1.0 / inertia : 0.0;
      group[i] = double(1 + k * Dim + std::size_t(c.axis));
    }
  }
}

/// The skeleton's part of the pressure correction (paper Eqs. 44–47, the implicit drag as in the
/// predictor, models/two_phase.hpp): the mixture's pressure force in the weak form of the total
/// stress, ∫ Δp ∇S_j, as the predictor applies p^k — so that an undrained surface carries its
/// load — plus what the liquid hands on through the drag, ∫ n_l ξ S_j ∇Δp:
///   (m_j + Δt D_j) Δv_j = Δt Σ_p V_p [Δp(x_p) ∇S_jp + (n_l ξ)_p S_jp ∇Δp(x_p)].
/// Where ∇Δp is smooth and the boundary drained this is −(1 − n_l ξ) ∇Δp, the corrected ξ_s.
template <int Dim>
void MechanicalPhysics<Dim>::correct() {
  auto& v = node_velocity_.vector();
  const auto& v_star = node_predicted_.vector();
  if (!node_increment_.bound()) {
    std::copy(v_star.begin(), v_star.end(), v.begin());
    return;
  }
  const auto& transfer = kernel_->transfer();
  const auto& st = transfer.stencil();
  const auto vol = volume_.values();
  const auto share = liquid_share_.bound() ? liquid_share_.values() : std::span<const double>{};
  const auto dp = node_increment_.values();
  const int K = st.per_particle();
  std::fill(force_.begin(), force_.end(), 0.0);
  transfer.scatter([&](std::size_t p) {
    const double value = transfer.value_at(p, dp);
    const auto grad = transfer.gradient_at(p, dp);
    const double liquid = share.empty() ? 0.0 : share[p];
    const auto* nodes = st.nodes(p);
    const auto* w = st.weights(p);
    const auto* g = st.gradients(p);
    for (int b = 0; b < K; ++b)
      for (int d = 0; d < Dim; ++d)
        force_[nodes[b] * Dim + d] += vol[p] * (value * g[b * Dim + d] + liquid * w[b] * grad[d]);
  });
  parallel_for(mass_.size(), [&](std::size_t i) {
    const double m = nodal_inertia_[i] + dt_ * drag_[i];
    for (int d = 0; d < Dim; ++d)
      v[i * Dim + d] = v_star[i * Dim + d] + (mass_[i] > 0 ? dt_ * force_[i * Dim + d] / m : 0.0);
  });
  tie_plates(v, time_, 0.0, true);
  constrain(v, time_ + dt_, 1.0);
}

/// The elastic energy per volume an isotropic material with P-wave modulus M and shear modulus
/// G stores at σ′: p²/(2K) + s:s/(4G), K = M − 4G/3 (0 where the moduli are not known).
template <int Dim>
[[gnu::always_inline]] inline double MechanicalPhysics<Dim>::elastic_energy_density(const double* s, double M, double G) {
  const double K = M - 4.0 * G / 3.0;
  if (!(K > 0 && G > 0)) return 0.0;
  const double mean = (s[0] + s[1] + s[2]) / 3.0;
  double deviatoric = 0;
  for (int i = 0; i < 3; ++i) deviatoric += (s[i] - mean) * (s[i] - mean);
  for (int i = 3; i < 6; ++i) deviatoric += 2.0 * s[i] * s[i];
  return mean * mean / (2.0 * K) + deviatoric / (4.0 * G);
}

/// v_p ← flip (v_p + Σ S Δv_i) + (1 − flip) Σ S v_i, Δv_i = v_i^{k+1} − v_i^k, and the position
/// from the grid's velocities (so that material points move as the deformation gradient says;
/// a FLIP particle velocity the grid does not see would move them without straining them —
/// measured: a settled column kept creeping, 0.4 % over 2 s):
///   symplectic   x_p += Δt Σ_i S_ip v_i^k — the velocity the stress update strained the particle
///                with (stress first, then momentum, then this: symplectic Euler, second order);
///   trapezoidal  x_p += Δt Σ_i S_ip (v_i^k + ½ Δv_i), Algorithm 1 step 21. With the stress taken
///                from v^k it moves particles half a step ahead of their stress: a first-order
///                phase error (vibrating bar: the half period stays 0.19 % short from 0.625 m down,
///                against 0.007 % and second order with the symplectic update).
template <int Dim>
void MechanicalPhysics<Dim>::map_to_particles() {
  const auto& transfer = kernel_->transfer();
  const auto& st = transfer.stencil();
  const auto& v_new = node_velocity_.vector();
  auto v = velocity_.mutable_values();
  auto x = position_.mutable_values();
  auto u = displacement_.mutable_values();
  const auto vol = volume_.values();
  const auto inertia = inertia_.values();
  const int K = st.per_particle();
  const std::size_t n = kernel_->particle_count();
  // The velocity mapped at the start (before the conditions acted, so that a prescribed
  // velocity reaches the particles), once per node.
  double* mapped = mapped_velocity_.data();
  parallel_for(mass_.size(), [&](std::size_t i) {
    for (int d = 0; d < Dim; ++d) mapped[i * Dim + d] = mass_[i] > 0 ? momentum_[i * Dim + d] / mass_[i] : 0.0;
  });
  const double* start = start_velocity_.data();
  const double* vi = v_new.data();
  const double h = kernel_->grid().min_spacing();
  const auto sigma = stress_.values();
  const auto shear = shear_.values();
  // The stable step h / max(c + |v|): the fastest signal, divided into h once (rounded division
  // is monotone, so this is min_p h / (c + |v|)_p to the bit).
  // The energies are an ordered chunk reduction, so that they (run.json's counters) do not depend
  // on the thread count, as an OpenMP reduction's would.
  struct StepSums {
    double kinetic = 0, elastic = 0, fastest = 0;
  };
  StepSums sums;
  auto update = [&](auto support, auto with_trapezoid) {
    constexpr bool trapezoid = decltype(with_trapezoid)::value;
    auto particle = [&](std::size_t p, StepSums& acc) {
      acc.elastic += vol[p] * elastic_energy_density(sigma.data() + 6 * p, wave_modulus_[p], shear[p]);
      const auto* nodes = st.nodes(p);
      const auto* w = st.weights(p);
      std::array<double, Dim> dv{}, pic{}, move{};
      for (int a = 0; a < support; ++a) {
        const std::size_t i = nodes[a];
        for (int d = 0; d < Dim; ++d) {
          // FLIP increment from the mapped velocity.
          dv[d] += w[a] * (vi[i * Dim + d] - mapped[i * Dim + d]);
          pic[d] += w[a] * vi[i * Dim + d];
          if constexpr (trapezoid)
            move[d] += w[a] * (0.5 * (start[i * Dim + d] + vi[i * Dim + d]));
          else
            move[d] += w[a] * start[i * Dim + d];
        }
      }
      double speed2 = 0;
      for (int d = 0; d < Dim; ++d) {
        const double step = dt_ * move[d];
        x[p * Dim + d] += step;
        u[p * Dim + d] += step;
        v[p * Dim + d] = flip_ * (v[p * Dim + d] + dv[d]) + (1.0 - flip_) * pic[d];
        speed2 += v[p * Dim + d] * v[p * Dim + d];
      }
      acc.kinetic += 0.5 * vol[p] * inertia[p] * speed2;
      // The stable step of the state left (stable_time_step()'s limit, the same expression).
      const double c = inertia[p] > 0 ? std::sqrt(wave_modulus_[p] / inertia[p]) : 0.0;
      acc.fastest = std::max(acc.fastest, c + std::sqrt(speed2));
    };
    sums = ordered_chunk_reduce(n, StepSums{}, particle, [](StepSums total, const StepSums& chunk) {
      total.kinetic += chunk.kinetic;
      total.elastic += chunk.elastic;
      total.fastest = std::max(total.fastest, chunk.fastest);
      return total;
    });
  };
  for_support<Dim>(K, [&](auto support) {
    trapezoidal_ ? update(support, std::true_type{}) : update(support, std::false_type{});
  });
  step_limit_ = sums.fastest > 0 ? h / sums.fastest : std::numeric_limits<double>::infinity();
  step_limit_valid_ = true;
  // Each footing moves as its nodes moved the material under it this step.
  for (auto& f : footings_) {
    const TimeFunction& speed = *velocity_bcs_[f.velocity].value[f.axis];
    f.displacement += dt_ * (trapezoidal_ ? 0.5 * (speed(time_) + speed(time_ + dt_)) : speed(time_));
  }
  // The kinetic energy with the inertia the step used (mass scaling included: that is what must
  // stay small against the work for a scaled run to be quasi-static).
  kinetic_energy_ = sums.kinetic;
  elastic_energy_ = sums.elastic;
  // The work of gravity, tractions and plate loads over the step, with the step's mean velocity
  // at each node the force acts on.
  const auto g = kernel_->gravity();
  auto mean_velocity = [&](std::size_t i, int d) { return 0.5 * (mapped[i * Dim + d] + v_new[i * Dim + d]); };
  double work = 0;
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    if (weight_[i] == 0) continue;
    for (int d = 0; d < Dim; ++d) work += dt_ * weight_[i] * g[d] * mean_velocity(i, d);
  }
  const auto half = half_size_.values();
  for (const auto& c : traction_bcs_)
    for (int d = 0; d < Dim; ++d) {
      const double t = c.value[d](time_);
      if (t == 0) continue;
      for (std::size_t j = 0; j < c.nodes.size(); ++j)
        if (mass_[c.nodes[j]] > 0) work += dt_ * t * c.areas[j] * mean_velocity(c.nodes[j], d);
      for (std::size_t p : c.particles) {
        double area = 1;
        for (int e = 0; e < Dim; ++e)
          if (e != c.normal_axis) area *= 2.0 * half[p * Dim + e];
        for (int a = 0; a < K; ++a) work += dt_ * t * area * st.weights(p)[a] * mean_velocity(st.nodes(p)[a], d);
      }
    }
  for (const auto& c : plates_) {
    double speed = 0, mass = 0;  // the plate's normal velocity: one for all its nodes
    for (std::size_t i : c.nodes)
      if (mass_[i] > 0) speed += mass_[i] * mean_velocity(i, c.axis), mass += mass_[i];
    if (mass > 0) work += dt_ * c.applied[std::size_t(c.axis)] * speed / mass;
  }
  external_work_ += work;
  // Against the larger of the work done and the elastic energy stored: loads, or what heat and
  // frost strain the skeleton with (no external work there). Sudden loads make the ratio large
  // in the first steps whatever the scaling: it is watched from a tenth of the run on.
  const double scale = std::max(std::abs(external_work_), elastic_energy_);
  if (scale > 0 && time_ + dt_ >= 0.1 * kernel_->end_time())
    kinetic_to_work_max_ = std::max(kinetic_to_work_max_, kinetic_energy_ / scale);
}

// ---- checkpoints and statistics ------------------------------------------------------------------

template <int Dim>
std::vector<PersistentArray> MechanicalPhysics<Dim>::persistent_state() {
  saved_scalars_ = {primed_ ? 1.0 : 0.0, kinetic_energy_, external_work_, kinetic_to_work_max_, elastic_energy_, removed_mass_};
  for (const auto& f : footings_) saved_scalars_.push_back(f.displacement);
  return {{"scalars", &saved_scalars_},
          {"temperature_of_last_update", &previous_T_},
          {"wave_modulus", &wave_modulus_},
          {"particle_mass", &particle_mass_}};
}

template <int Dim>
void MechanicalPhysics<Dim>::restored() {
  step_limit_valid_ = false;
  const auto& s = saved_scalars_;
  const std::size_t expected = 6 + footings_.size();
  if (s.size() != expected)
    throw std::runtime_error("mechanical: checkpoint holds " + std::to_string(s.size()) + " scalars, expected " +
                             std::to_string(expected));
  for (std::size_t k = 0; k < footings_.size(); ++k) footings_[k].displacement = s[6 + k];
  removed_mass_ = s[5];
  elastic_energy_ = s[4];
  primed_ = s[0] != 0;
  kinetic_energy_ = s[1];
  external_work_ = s[2];
  kinetic_to_work_max_ = s[3];
}

template <int Dim>
std::vector<std::pair<std::string, double>> MechanicalPhysics<Dim>::statistics() const {
  return {{"mechanical.kinetic_energy_J", kinetic_energy_ / mass_scaling_},
          {"mechanical.kinetic_energy_scaled_J", kinetic_energy_},
          {"mechanical.external_work_J", external_work_},
          {"mechanical.kinetic_to_work_max", kinetic_to_work_max_},
          {"mechanical.elastic_energy_J", elastic_energy_},
          {"mechanical.kinetic_to_work_final",
           std::max(std::abs(external_work_), elastic_energy_) > 0
               ? kinetic_energy_ / std::max(std::abs(external_work_), elastic_energy_)
               : 0.0},
          {"mechanical.mass_removed_kg", removed_mass_}};
}

template <int Dim>
void MechanicalPhysics<Dim>::removing_particles(const ParticleRemoval& removal) {
  if (!removal.restoring) {
    const auto vol = volume_.values();
    for (std::size_t p = 0; p < removal.leaving.size(); ++p) {
      if (!removal.leaving[p]) continue;
      double rho_m, skeleton, n_l;
      densities(p, rho_m, skeleton, n_l);
      removed_mass_ += rho_m * vol[p];  // [kg per m of thickness in 2-D]
    }
  }
  for (auto* v : {&strain_increment_, &rotated_, &wave_modulus_, &previous_T_, &particle_mass_, &thermal_strain_,
                  &volume_ratio_})
    removal.compact(*v);
  removal.compact(failed_);
  for (auto& c : traction_bcs_) removal.remap(c.particles);
  step_limit_valid_ = false;
}

template class MechanicalPhysics<2>;
template class MechanicalPhysics<3>;

}  // namespace frostmpm::mechanical
