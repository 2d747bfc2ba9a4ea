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

#include "frostmpm/io/log.hpp"
#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/io/particle_field_writer.hpp"
#include "frostmpm/simulation/interrupt.hpp"
#include "frostmpm/simulation/run_budget.hpp"
#include "frostmpm/scene/region.hpp"

namespace frostmpm {

namespace {

std::array<double, kDim> read_point(const ConfigNode& node) {
  const auto v = node.as_reals();
  if (v.size() != kDim) throw node.error("expected a point with " + std::to_string(kDim) + " coordinates");
  return {v[0], v[1]};
}

using Clock = std::chrono::steady_clock;

/// Checkpoint group of the nodal fields the kernel carries between steps (no physics key
/// starts with an underscore).
constexpr const char* kCarriedNodeFields = "_carried_node_fields";

}  // namespace

// ------------------------------------------------------------------------------------------
// Probes: what metrics.csv records over time.

struct Simulation::Probe {
  std::string name, type, field;
  std::vector<std::string> fields;
  std::array<double, kDim> point{}, from{}, to{};
  double value = 0;
};

struct Simulation::RegionInit {
  ParticleRange range;
  std::vector<std::pair<std::string, double>> values;
  std::unique_ptr<ConfigNode> node;  ///< `initial:` section, checked once fields exist
};

std::vector<std::string> Simulation::sections() {
  return {"grid", "time", "physics", "materials", "regions", "boundary_conditions", "output", "probes", "checkpoint"};
}

Simulation::Simulation(const Registry& registry, const ConfigNode& root) : registry_(registry) {
  resolved_ = YAML::Node(YAML::NodeType::Map);
  read_grid(root.child("grid"));
  read_time(root.child("time"));
  read_physics(root.child("physics"));
  read_materials(root.child("materials"));
  read_regions(root.child("regions"));
  if (auto bcs = root.optional_child("boundary_conditions")) read_boundary_conditions(*bcs);
  else resolved_["boundary_conditions"] = YAML::Node(YAML::NodeType::Sequence);
  for (auto& physics : physics_) physics->setup(*this);
  for (auto& bc : bcs_) bc.node->finish({});  // physics read their keys; anything left is unknown
  resolve_step();
  apply_initial_values();
  read_output(root.child("output"));
  const auto probes = root.optional_child("probes");
  read_probes(probes ? &*probes : nullptr);
  const auto checkpoint = root.optional_child("checkpoint");
  read_checkpoint(checkpoint ? *checkpoint : ConfigNode(YAML::Node(YAML::NodeType::Map), root.file(), "checkpoint"));
}

Simulation::~Simulation() = default;

RunInterrupted::RunInterrupted(int signal_number, double at_time, long at_step)
    : std::runtime_error("interrupted by signal " + std::to_string(signal_number)),
      signal(signal_number),
      time(at_time),
      step(at_step) {}

void Simulation::read_grid(const ConfigNode& node) {
  ParamSchema s;
  s.reals("origin", "m", "lower-left corner of the grid").size(kDim).defaults_to(std::vector<double>(kDim, 0.0));
  // At most 1e8 per axis: an int, and the 50-million-node cap below still applies.
  s.reals("cells", "-", "number of cells along each axis").size(kDim).at_least(1).at_most(1e8);
  // Bounded so that cell volumes and particle volumes stay normal doubles (1e-300 m gave NaN).
  s.reals("cell_size", "m", "cell size: one value (square cells) or one per axis").at_least(1e-6).at_most(1e6);
  s.choice("shape_function", shape_kind_names(), "MPM shape functions").defaults_to("gimp");
  s.integer("particles_per_cell", "particles per cell along each axis").defaults_to(2L).at_least(1).at_most(8);
  const ParamSet p = parse_params(s, node);
  const auto& cells = p.reals("cells");
  const auto& h = p.reals("cell_size");
  if (h.size() != 1 && h.size() != kDim)
    throw p.error("cell_size", "give one cell size or one per axis (" + std::to_string(kDim) + ")");
  for (int d = 0; d < kDim; ++d) {
    if (cells[d] != std::floor(cells[d])) throw p.error("cells", "cell counts must be whole numbers");
    grid_.origin[d] = p.reals("origin")[d];
    grid_.cells[d] = static_cast<int>(cells[d]);
    grid_.spacing[d] = h.size() == 1 ? h[0] : h[d];
  }
  if (grid_.node_count() > 50'000'000) throw p.error("cells", "grid too large (over 50 million nodes)");
  // The particle lattice is allocated before any region is known: estimate it first.
  const double lattice = double(grid_.cells[0]) * double(grid_.cells[1]) * std::pow(double(p.integer("particles_per_cell")), kDim);
  const double bytes = lattice * kBytesPerParticle, installed = double(physical_memory_bytes());
  if (installed > 0 && bytes > installed)
    throw p.error("particles_per_cell", "cells × particles_per_cell^" + std::to_string(kDim) + " = " +
                                            number_text(lattice, 3) + " particles need about " + bytes_text(bytes) +
                                            " of memory, more than the " + bytes_text(installed) +
                                            " installed; use fewer cells or particles per cell");
  shape_ = parse_shape_kind(p.string("shape_function"));
  grid_.ghost_layers = ghost_layers(shape_);
  stencil_.configure(shape_);
  resolved_["grid"] = p.to_yaml();
}

void Simulation::read_time(const ConfigNode& node) {
  ParamSchema s;
  s.real("end", "s", "simulated end time").above(0);
  s.real("dt", "s", "fixed time step; 0 = automatic from the physics' stability limits").defaults_to(0.0).at_least(0);
  s.real("dt_max", "s", "upper bound on an automatic step; 0 = none").defaults_to(0.0).at_least(0);
  s.integer("max_steps", "most steps, metrics rows or field frames a run may take; a scene needing more is refused")
      .defaults_to(kDefaultMaxSteps).at_least(1);
  const ParamSet p = parse_params(s, node);
  end_time_ = p.real("end");
  fixed_dt_ = p.real("dt");
  max_dt_ = p.real("dt_max");
  max_steps_ = p.integer("max_steps");
  if (fixed_dt_ > 0)
    check_count(p, "dt", end_time_ / fixed_dt_, max_steps_, "steps", "time.end / time.dt");
  time_params_ = p;
  resolved_["time"] = p.to_yaml();
}

void Simulation::read_physics(const ConfigNode& node) {
  if (!node.is_map() || node.keys().empty())
    throw node.error("list the physics to run, e.g. {thermal: {scheme: explicit}}; registered: " +
                     join(registry_.names(Physics::kKind)));
  YAML::Node resolved(YAML::NodeType::Map);
  for (const auto& key : node.keys()) {
    const ConfigNode section = node.child(key);
    const RegistryEntry& entry = registry_.get(Physics::kKind, key, section.where());
    const ParamSet params = parse_params(entry.schema, section);
    physics_.push_back(registry_.create<Physics>(key, params, section.where()));
    physics_keys_.push_back(key);
    physics_where_.push_back(section.where());
    resolved[key] = params.to_yaml();
  }
  resolved_["physics"] = resolved;
}

void Simulation::read_materials(const ConfigNode& node) {
  // One merged schema: a key several physics read (e.g. porosity) is validated once.
  ParamSchema merged;
  std::vector<ModelSlot> slots;
  for (const auto& physics : physics_) {
    const ParamSchema schema = physics->material_schema();
    for (const auto& spec : schema.params())
      if (!merged.find(spec.name)) {
        auto& added = merged.real(spec.name, spec.unit, spec.doc);
        added = spec;
      }
    for (const auto& slot : physics->material_models())
      if (std::none_of(slots.begin(), slots.end(), [&](const ModelSlot& s) { return s.key == slot.key; }))
        slots.push_back(slot);
  }
  std::vector<std::string> slot_keys;
  for (const auto& slot : slots) slot_keys.push_back(slot.key);
  if (!node.is_map() || node.keys().empty()) throw node.error("define at least one material: {name: {...}}");
  YAML::Node resolved(YAML::NodeType::Map);
  for (const auto& name : node.keys()) {
    const ConfigNode section = node.child(name);
    Material material;
    material.name = name;
    material.params = parse_params(merged, section, slot_keys);
    YAML::Node out = material.params.to_yaml();
    for (const auto& slot : slots) {
      if (!section.has(slot.key)) {
        if (slot.required)
          throw section.error("missing required model section '" + slot.key + "' ({model: ...}); registered " +
                              slot.kind + " models: " + join(registry_.names(slot.kind)));
        continue;
      }
      auto model = read_model_section(registry_, slot.kind, section.child(slot.key));
      out[slot.key] = model.resolved();
      material.models.emplace(slot.key, std::move(model));
    }
    resolved[name] = out;
    materials_.push_back(std::move(material));
  }
  resolved_["materials"] = resolved;
  material_schema_ = merged;
}

void Simulation::read_regions(const ConfigNode& node) {
  struct Parsed {
    RegionShape shape;
    int material = 0;
    std::unique_ptr<ConfigNode> initial;
    SourceLocation where;
  };
  std::vector<Parsed> regions;
  YAML::Node resolved(YAML::NodeType::Sequence);
  std::vector<std::string> material_names;
  for (const auto& m : materials_) material_names.push_back(m.name);
  for (const auto& item : node.elements()) {
    Parsed r;
    r.where = item.where();
    r.shape = read_region_shape(item.child("shape"));
    const ConfigNode mat = item.child("material");
    const std::string name = mat.as_string();
    const auto it = std::find(material_names.begin(), material_names.end(), name);
    if (it == material_names.end())
      throw mat.error("unknown material '" + name + "'; defined: " + join(material_names));
    r.material = static_cast<int>(it - material_names.begin());
    if (auto init = item.optional_child("initial")) r.initial = std::make_unique<ConfigNode>(*init);
    item.finish({"shape", "material", "initial"});
    YAML::Node out;
    out["shape"] = r.shape.resolved;
    out["material"] = name;
    if (r.initial) out["initial"] = YAML::Clone(r.initial->raw());
    resolved.push_back(out);
    regions.push_back(std::move(r));
  }
  if (regions.empty()) throw node.error("define at least one region");

  // Each lattice point belongs to the last region containing it: write the background first,
  // then inclusions on top.
  const int ppc = static_cast<int>(resolved_["grid"]["particles_per_cell"].as<long>());
  std::vector<std::vector<std::array<double, kDim>>> points(regions.size());
  RegionShape everything{"all", [](const std::array<double, 2>&) { return true; }, {}};
  for (const auto& x : sample_region(grid_, everything, ppc))
    for (std::size_t r = regions.size(); r-- > 0;)
      if (regions[r].shape.contains(x)) {
        points[r].push_back(x);
        break;
      }
  particles_.declare("position", kDim);
  particles_.declare("volume", 1);
  particles_.declare("half_size", kDim);
  const double volume = grid_.cell_volume() / std::pow(ppc, kDim);
  const auto lo = grid_.origin, hi = grid_.upper();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    // A region without particles was a silent no-op: wholly outside the grid, or covered.
    if (points[r].empty())
      throw InputError(regions[r].where, "region " + std::to_string(r) + " contains no particles: its shape lies "
                       "outside the grid [" + number_text(lo[0]) + ", " + number_text(hi[0]) + "] × [" +
                       number_text(lo[1]) + ", " + number_text(hi[1]) + "] m or under later regions");
    const ParticleRange range = particles_.append(points[r].size(), regions[r].material);
    auto pos = particles_.field("position");
    auto vol = particles_.field("volume");
    auto half = particles_.field("half_size");
    for (std::size_t i = 0; i < points[r].size(); ++i) {
      const std::size_t p = range.begin + i;
      for (int d = 0; d < kDim; ++d) {
        pos[p * kDim + d] = points[r][i][d];
        half[p * kDim + d] = 0.5 * grid_.spacing[d] / ppc;
      }
      vol[p] = volume;
    }
    region_inits_.push_back(RegionInit{range, {}, std::move(regions[r].initial)});
  }
  if (particles_.size() == 0) throw node.error("the regions contain no particles inside the grid");
  resolved_["regions"] = resolved;
}

void Simulation::read_boundary_conditions(const ConfigNode& node) {
  std::map<std::string, std::string> owner;
  for (std::size_t i = 0; i < physics_.size(); ++i)
    for (const auto& type : physics_[i]->boundary_types()) owner[type] = physics_keys_[i];
  std::vector<std::string> types;
  for (const auto& [t, _] : owner) types.push_back(t);
  for (const auto& item : node.elements()) {
    BoundaryCondition bc;
    const ConfigNode type = item.child("type");
    bc.type = type.as_string();
    if (!owner.count(bc.type)) {
      std::string message = "unknown boundary condition type '" + bc.type + "'";
      const std::string hint = closest_match(bc.type, types);
      if (!hint.empty()) message += "; did you mean '" + hint + "'?";
      throw type.error(message + " Types of the physics in this scene: " + join(types));
    }
    const bool on_nodes = item.has("nodes");
    const bool on_particles = item.has("particles");
    if (on_nodes == on_particles) throw item.error("give exactly one target: 'nodes:' or 'particles:'");
    if (on_nodes) {
      const ConfigNode target = item.child("nodes");
      if (auto face = target.optional_child("face")) {
        bool ok = false;
        const GridFace f = GridFace::parse(face->as_string(), kDim, ok);
        if (!ok) throw face->error("'" + face->as_string() + "' is not a face; valid: x_min, x_max, y_min, y_max");
        face_nodes(grid_, f, bc.nodes, bc.node_areas);
        bc.target_text = "face " + f.name();
      } else if (auto box = target.optional_child("box")) {
        const auto lo = read_point(box->child("min"));
        const auto hi = read_point(box->child("max"));
        box->finish({"min", "max"});
        bc.nodes = box_nodes<kDim>(grid_, lo, hi);
        bc.node_areas.assign(bc.nodes.size(), 0.0);
        bc.target_text = "node box";
        if (bc.nodes.empty()) throw box->error("the box contains no grid nodes");
      }
      target.finish({"face", "box"});
      if (bc.nodes.empty()) throw target.error("expected {face: NAME} or {box: {min, max}}");
    } else {
      const ConfigNode target = item.child("particles");
      const RegionShape shape = read_region_shape(target);
      const auto pos = particles_.field("position");
      for (std::size_t p = 0; p < particles_.size(); ++p)
        if (shape.contains({pos[p * kDim], pos[p * kDim + 1]})) bc.particles.push_back(p);
      if (bc.particles.empty()) throw target.error("the shape contains no particles");
      bc.on_particles = true;
      bc.target_text = "particles in " + shape.kind;
    }
    // The owning physics reads the rest; `type` and the target are consumed here.
    bc.node = std::make_unique<ConfigNode>(item);
    bcs_.push_back(std::move(bc));
  }
  resolved_["boundary_conditions"] = YAML::Clone(node.raw());
}

std::vector<std::uint16_t> Simulation::particle_materials() const {
  std::vector<std::uint16_t> material(particles_.size());
  for (const auto& r : particles_.ranges())
    std::fill(material.begin() + r.begin, material.begin() + r.end, static_cast<std::uint16_t>(r.material));
  return material;
}

void Simulation::fill_from_materials(const std::string& field, const std::string& parameter) {
  auto values = particles_.field(field);
  for (const auto& r : particles_.ranges())
    std::fill(values.begin() + r.begin, values.begin() + r.end, materials_[r.material].params.real(parameter));
}

void Simulation::resolve_step() {
  std::vector<StepPlan::Declared> declared;
  for (std::size_t i = 0; i < physics_.size(); ++i)
    for (auto& stage : physics_[i]->stages()) declared.push_back({std::move(stage), physics_keys_[i], physics_where_[i]});
  plan_ = StepPlan::resolve(std::move(declared), particles_.field_names());
  for (const auto& f : plan_.new_particle_fields()) particles_.declare(f.name, f.components);
  for (const auto& f : plan_.node_fields()) node_fields_.allocate(f.name, f.components, grid_.node_count());
}

std::vector<PersistentArray> Simulation::carried_node_fields() {
  std::vector<PersistentArray> arrays;
  for (const auto& f : plan_.node_fields())
    if (f.carried) arrays.push_back({f.name, &node_fields_.values(f.name)});
  return arrays;
}

std::vector<BoundaryCondition*> Simulation::boundary_conditions(const std::string& type) {
  std::vector<BoundaryCondition*> out;
  for (auto& bc : bcs_)
    if (bc.type == type) out.push_back(&bc);
  return out;
}

void Simulation::declare_state_field(const std::string& name, int components, double default_value,
                                     double max_magnitude) {
  state_bounds_[name] = max_magnitude;
  particles_.declare(name, components, default_value);
  state_defaults_[name] = default_value;
}

void Simulation::apply_initial_values() {
  std::vector<std::string> settable;
  for (const auto& [name, _] : state_defaults_) settable.push_back(name);
  for (auto& init : region_inits_) {
    if (!init.node) continue;
    const ConfigNode& node = *init.node;
    node.reject_unknown(settable);
    for (const auto& key : node.keys()) {
      const ConfigNode entry = node.child(key);
      const double value = entry.as_real();
      // A material parameter set per region obeys the material's range (porosity in (0, 1)).
      if (const ParamSpec* spec = material_schema_.find(key); spec && !spec->in_range(value))
        throw entry.error(number_text(value) + " is outside the range of material parameter '" + key +
                          "'; valid: " + spec->range_text());
      if (std::abs(value) > state_bounds_.at(key))
        throw entry.error(number_text(value) + " is beyond the plausible magnitude " +
                          number_text(state_bounds_.at(key)) + " of '" + key + "'");
      auto column = particles_.field(key);
      const int c = particles_.components(key);
      for (std::size_t p = init.range.begin; p < init.range.end; ++p)
        for (int k = 0; k < c; ++k) column[p * c + k] = value;
    }
  }
}

std::vector<std::string> Simulation::physics_names() const { return physics_keys_; }

void Simulation::read_output(const ConfigNode& node) {
  ParamSchema s;
  s.real("every", "s", "simulated time between field frames (fields.h5); 0 = first and last only")
      .defaults_to(0.0).at_least(0);
  s.real("metrics_every", "s", "simulated time between metrics.csv rows; 0 = every step").defaults_to(0.0).at_least(0);
  s.boolean("progress", "print a progress line with time, step, dt and ETA").defaults_to(true);
  const ParamSet p = parse_params(s, node, {"fields"});
  output_every_ = p.real("every");
  metrics_every_ = p.real("metrics_every");
  if (output_every_ > 0)
    check_count(p, "every", end_time_ / output_every_, max_steps_, "field frames", "time.end / output.every");
  if (metrics_every_ > 0)
    check_count(p, "metrics_every", end_time_ / metrics_every_, max_steps_, "metrics rows",
                "time.end / output.metrics_every");
  YAML::Node out = p.to_yaml();
  const auto names = particles_.field_names();
  if (auto fields = node.optional_child("fields")) {
    for (const auto& f : fields->elements()) {
      const std::string name = f.as_string();
      if (!particles_.has(name)) throw f.error("unknown field '" + name + "'; available: " + join(names));
      if (name != "position") output_fields_.push_back(name);
    }
  }
  out["fields"] = output_fields_;
  resolved_["output"] = out;
}

void Simulation::read_probes(const ConfigNode* node) {
  YAML::Node resolved(YAML::NodeType::Sequence);
  if (node) {
    static const std::vector<std::string> types = {"min", "max", "value_at", "integral", "isotherm"};
    const auto names = particles_.field_names();
    // A scalar field, or one component of a vector field: "water_flux.y".
    std::vector<std::string> scalars;
    for (const auto& n : names) {
      const int c = particles_.components(n);
      if (c == 1) scalars.push_back(n);
      else
        for (int d = 0; d < std::min(c, 3); ++d) scalars.push_back(n + "." + "xyz"[d]);
    }
    // Points a probe samples must lie in the grid's domain (outside, the value was a clamp).
    const auto lo = grid_.origin, hi = grid_.upper();
    auto read_inside = [&](const ConfigNode& n) {
      const auto x = read_point(n);
      for (int d = 0; d < kDim; ++d)
        if (x[d] < lo[d] || x[d] > hi[d])
          throw n.error("the point lies outside the grid [" + number_text(lo[0]) + ", " + number_text(hi[0]) +
                        "] × [" + number_text(lo[1]) + ", " + number_text(hi[1]) + "] m");
      return x;
    };
    std::map<std::string, SourceLocation> first_use;  // probe name -> where it was first given
    auto check_field = [&](const ConfigNode& f) {
      const std::string name = f.as_string();
      if (std::find(scalars.begin(), scalars.end(), name) == scalars.end())
        throw f.error("unknown scalar field '" + name + "'; available: " + join(scalars));
      return name;
    };
    for (const auto& item : node->elements()) {
      auto probe = std::make_unique<Probe>();
      const ConfigNode type = item.child("type");
      probe->type = type.as_string();
      if (std::find(types.begin(), types.end(), probe->type) == types.end())
        throw type.error("unknown probe type '" + probe->type + "'; valid: " + join(types));
      const ConfigNode name = item.child("name");
      probe->name = name.as_string();
      if (const auto [it, fresh] = first_use.emplace(probe->name, name.where()); !fresh)
        throw name.error("probe name '" + probe->name + "' is used twice (first at " + it->second.describe() +
                         "); metrics.csv needs one column per name");
      if (probe->type == "integral") {
        for (const auto& f : item.child("fields").elements()) probe->fields.push_back(check_field(f));
        if (auto scale = item.optional_child("scale")) {
          probe->value = scale->as_real();
          if (!std::isfinite(probe->value)) throw scale->error("scale must be a finite number");
        } else {
          probe->value = 1.0;
        }
        item.finish({"type", "name", "fields", "scale"});
      } else {
        probe->field = check_field(item.child("field"));
        if (probe->type == "value_at") {
          probe->point = read_inside(item.child("point"));
          item.finish({"type", "name", "field", "point"});
        } else if (probe->type == "isotherm") {
          probe->value = item.child("value").as_real();
          probe->from = read_inside(item.child("from"));
          probe->to = read_inside(item.child("to"));
          item.finish({"type", "name", "field", "value", "from", "to"});
        } else {
          item.finish({"type", "name", "field"});
        }
      }
      resolved.push_back(YAML::Clone(item.raw()));
      probes_.push_back(std::move(probe));
    }
  }
  resolved_["probes"] = resolved;
}

void Simulation::read_checkpoint(const ConfigNode& node) {
  ParamSchema s;
  s.integer("every_steps", "steps between checkpoints (OUT/checkpoint.h5); 0 = off").defaults_to(0L).at_least(0);
  s.real("every_minutes", "min", "wall-clock minutes between checkpoints; 0 = off").defaults_to(30.0).at_least(0);
  const ParamSet p = parse_params(s, node);
  checkpoint_every_steps_ = p.integer("every_steps");
  checkpoint_every_minutes_ = p.real("every_minutes");
  resolved_["checkpoint"] = p.to_yaml();
}

// ------------------------------------------------------------------------------------------

void Simulation::update_stencil() {
  const long outside = stencil_.update(grid_, particles_.field("position"), particles_.field("half_size"));
  if (outside < 0) return;
  const auto pos = particles_.field("position");
  std::ostringstream msg;
  msg << "particle " << outside << " at (" << pos[outside * kDim] << ", " << pos[outside * kDim + 1]
      << ") has support outside the grid at t = " << time_ << " s (step " << step_ << ")";
  throw NumericalBlowUp(msg.str());
}

void Simulation::advance(double dt) {
  dt_ = dt;
  auto timed = [&](const std::string& name, const std::function<void()>& fn) {
    const auto start = Clock::now();
    fn();
    stats_.stage_seconds[name] += std::chrono::duration<double>(Clock::now() - start).count();
  };
  if (positions_changed_) {
    timed("kernel.stencil", [&] { update_stencil(); });
    positions_changed_ = false;  // particles move only when a mechanics stage says so
  }
  for (auto& physics : physics_) physics->begin_step(time_, dt);
  for (auto& stage : plan_.stages()) timed(stage.name, stage.run);
  time_ += dt;
  ++step_;
  stats_.steps++;
  stats_.dt_sum += dt;
  stats_.dt_min = stats_.steps == 1 ? dt : std::min(stats_.dt_min, dt);
  stats_.dt_max = std::max(stats_.dt_max, dt);
}

void Simulation::check_finite() const {
  const auto pos = particles_.field("position");
  for (const auto& [name, _] : state_defaults_) {
    const auto column = particles_.field(name);
    const int c = particles_.components(name);
    // The first non-finite entry (a parallel scan; the smallest index, whatever the threads).
    const double first = parallel_min(
        column.size(), [&](std::size_t i) { return std::isfinite(column[i]) ? HUGE_VAL : double(i); }, HUGE_VAL);
    if (first == HUGE_VAL) continue;
    const auto i = static_cast<std::size_t>(first);
    const std::size_t p = i / c;
    std::ostringstream msg;
    msg << "numerical blow-up: " << name << " = " << column[i] << " at particle " << p << " (x = " << pos[p * kDim]
        << ", y = " << pos[p * kDim + 1] << ") at t = " << time_ << " s, step " << step_ << " (dt = " << dt_ << " s)"
        << suspects(p);
    throw NumericalBlowUp(msg.str());
  }
}

std::string Simulation::suspects(std::size_t particle) const {
  // Every region holds particles (read_regions refuses one without), so the k-th particle
  // range is regions.k of the scene.
  std::string out;
  for (std::size_t k = 0; k < region_inits_.size(); ++k)
    if (particle >= region_inits_[k].range.begin && particle < region_inits_[k].range.end)
      out = "; the particle is in regions." + std::to_string(k) + " (material '" +
            materials_[region_inits_[k].range.material].name + "')";
  std::vector<std::string> bcs;
  for (std::size_t i = 0; i < bcs_.size(); ++i)
    bcs.push_back(bcs_[i].label());
  if (!bcs.empty()) out += "; check its values and those of " + join(bcs);
  return out;
}

Simulation::ScalarColumn Simulation::scalar_column(const std::string& name) const {
  const auto dot = name.rfind('.');
  if (dot != std::string::npos && !particles_.has(name)) {
    const std::string base = name.substr(0, dot);
    const std::size_t c = std::string("xyz").find(name.substr(dot + 1));
    return {particles_.field(base), c, static_cast<std::size_t>(particles_.components(base))};
  }
  return {particles_.field(name), 0, 1};
}

double Simulation::sample_field(const std::string& field, const std::array<double, kDim>& point) const {
  // Volume-weighted nodal average of the particle field, then bilinear interpolation.
  const auto [values, component, stride] = scalar_column(field);
  const auto vol = particles_.field("volume");
  const std::size_t K = static_cast<std::size_t>(stencil_.per_particle());
  std::array<int, kDim> base{};
  std::array<double, kDim> frac{};
  for (int d = 0; d < kDim; ++d) {
    const double xi = std::clamp((point[d] - grid_.origin[d]) / grid_.spacing[d], 0.0, double(grid_.cells[d]));
    base[d] = std::min(static_cast<int>(std::floor(xi)), grid_.cells[d] - 1);
    frac[d] = xi - base[d];
  }
  std::array<std::size_t, 4> corner{};
  std::array<double, 4> cw{}, num{}, den{};
  for (int c = 0; c < 4; ++c) {
    const int a = c & 1, b = c >> 1;
    corner[c] = grid_.node_index({base[0] + a, base[1] + b});
    cw[c] = (a ? frac[0] : 1 - frac[0]) * (b ? frac[1] : 1 - frac[1]);
  }
  // Only particles whose stencil touches the four corners contribute.
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    const auto* nodes = stencil_.nodes(p);
    const auto* w = stencil_.weights(p);
    for (std::size_t k = 0; k < K; ++k)
      for (int c = 0; c < 4; ++c)
        if (nodes[k] == corner[c]) {
          num[c] += vol[p] * w[k] * values[p * stride + component];
          den[c] += vol[p] * w[k];
        }
  }
  double value = 0, weight = 0;
  for (int c = 0; c < 4; ++c)
    if (den[c] > 0) {
      value += cw[c] * num[c] / den[c];
      weight += cw[c];
    }
  return weight > 0 ? value / weight : std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> Simulation::evaluate_probes() const {
  std::vector<double> out;
  const auto vol = particles_.field("volume");
  for (const auto& probe : probes_) {
    if (probe->type == "min" || probe->type == "max") {
      const auto [f, component, stride] = scalar_column(probe->field);
      double extreme = f[component];
      for (std::size_t i = component; i < f.size(); i += stride)
        extreme = probe->type == "min" ? std::min(extreme, f[i]) : std::max(extreme, f[i]);
      out.push_back(extreme);
    } else if (probe->type == "integral") {
      double sum = 0;
      std::vector<ScalarColumn> cols;
      for (const auto& name : probe->fields) cols.push_back(scalar_column(name));
      for (std::size_t p = 0; p < particles_.size(); ++p) {
        double v = vol[p];
        for (const auto& c : cols) v *= c.values[p * c.stride + c.component];
        sum += v;
      }
      out.push_back(probe->value * sum);
    } else if (probe->type == "value_at") {
      out.push_back(sample_field(probe->field, probe->point));
    } else {  // isotherm: distance from `from` to the first crossing of `value` along the line
      const double length = std::hypot(probe->to[0] - probe->from[0], probe->to[1] - probe->from[1]);
      const int samples = std::max(2, static_cast<int>(std::ceil(4 * length / grid_.min_spacing())));
      double previous = 0, crossing = std::numeric_limits<double>::quiet_NaN();
      for (int s = 0; s <= samples; ++s) {
        const double f = double(s) / samples;
        const double v = sample_field(probe->field, {probe->from[0] + f * (probe->to[0] - probe->from[0]),
                                                     probe->from[1] + f * (probe->to[1] - probe->from[1])}) -
                         probe->value;
        if (s > 0 && (previous > 0) != (v > 0)) {
          const double f0 = double(s - 1) / samples;
          crossing = (f0 + (f - f0) * previous / (previous - v)) * length;
          break;
        }
        previous = v;
      }
      out.push_back(crossing);
    }
  }
  return out;
}

std::string Simulation::metrics_header() const {
  std::string header = "time_s,step,dt_s";
  for (const auto& probe : probes_) header += ',' + probe->name;
  return header;
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
  // Land exactly on output, metrics and end times without leaving a sliver step: when the
  // target is less than two steps away, split the remaining gap in two.
  for (double target : {loop.next_output, metrics_every_ > 0 ? std::min(loop.next_metrics, end_time_) : end_time_,
                        end_time_}) {
    const double gap = target - time_;
    if (gap <= eps) continue;
    if (dt >= gap - eps) dt = gap;
    else if (2 * dt > gap) dt = 0.5 * gap;
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
  checkpoint.commit();
  stats_.stage_seconds["kernel.checkpoint"] += std::chrono::duration<double>(Clock::now() - start).count();
}

LoopState Simulation::restore_checkpoint(const std::string& dir) {
  const CheckpointReader checkpoint(dir);
  checkpoint.read(particles_);
  for (std::size_t i = 0; i < physics_.size(); ++i)
    checkpoint.read_physics(physics_keys_[i], physics_[i]->persistent_state());
  if (const auto carried = carried_node_fields(); !carried.empty())
    checkpoint.read_physics(kCarriedNodeFields, carried);
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

void Simulation::run(const OutputDir& out, const RunOptions& options) {
  // The stencil is needed by the first probe evaluation; it stays valid until particles move
  // (a physics may key cached grid state to its version).
  update_stencil();
  positions_changed_ = false;
  // On a restart too: whatever a physics derives from the initial state is set up as in a new
  // run, and the checkpoint then overwrites every field and persistent array.
  for (auto& physics : physics_) physics->initialize();
  check_step_budget();
  LoopState loop;
  if (options.restart) {
    loop = restore_checkpoint(out.path());
  } else {
    remove_checkpoint(out.path());  // an earlier run's checkpoint would not match these outputs
    loop.next_output = output_every_ > 0 ? std::min(output_every_, end_time_) : end_time_;
    loop.next_metrics = metrics_every_ > 0 ? metrics_every_ : 0;
  }
  const std::string header = metrics_header();
  ParticleFieldWriter writer =
      options.restart ? reopen_fields(out, loop.frames) : ParticleFieldWriter(out.path(), kDim);
  CheckedFile metrics = options.restart ? reopen_metrics(out, header, loop.metrics_rows)
                                        : CheckedFile(out.file("metrics.csv"), /*append=*/false);
  if (!options.restart) metrics.write(header + '\n');
  loop.frames = static_cast<long>(writer.frames());

  auto write_frame = [&] {
    std::vector<FieldView> views;
    for (const auto& name : output_fields_)
      views.push_back({name, particles_.field(name).data(), particles_.components(name)});
    writer.write(time_, step_, particles_.size(), particles_.field("position").data(), views);
  };
  auto write_metrics = [&] {
    std::ostringstream row;
    row << std::setprecision(12) << time_ << ',' << step_ << ',' << dt_;
    for (double v : evaluate_probes()) row << ',' << v;
    row << '\n';
    metrics.write(row.str(), at_step(step_, time_));  // a whole row or an error, never half a row
  };

  const double eps = 1e-9 * end_time_;
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
  while (time_ < end_time_ - eps) {
    advance(loop.next_dt);
    check_finite();
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
      std::ostringstream line;
      line << std::setprecision(4) << "  t = " << time_ << " s / " << end_time_ << " s  step " << step_
           << "  dt = " << dt_ << " s  ETA " << std::fixed << std::setprecision(0) << eta << " s";
      log::info(line.str());
    }
    if (time_ >= end_time_ - eps) break;

    // A stop request gets readable outputs of this moment; a restart drops them again (they
    // are not part of the schedule), so the loop counters above leave them out.
    const int signal = interrupt_signal();
    if (signal && !metrics_due) write_metrics();
    if (signal && !frame_due) write_frame();
    // The next step is chosen before a checkpoint is written, exactly as without one, and
    // saved with it: a restart continues with the same step and asks no physics for it.
    loop.next_dt = plan_step(loop);
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
  remove_checkpoint(out.path());  // the run is complete: nothing left to resume
}

}  // namespace frostmpm
