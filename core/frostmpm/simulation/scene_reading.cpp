// Reading a simulation scene: grid, time, gravity, physics, materials, regions, boundary
// conditions, output and checkpoint sections. Every problem is an InputError naming the YAML
// path and line.
#include <algorithm>
#include <cmath>
#include <map>

#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/scene/region.hpp"
#include "frostmpm/simulation/run_budget.hpp"
#include "frostmpm/simulation/simulation.hpp"

namespace frostmpm {

namespace {

std::array<double, kDim> read_point(const ConfigNode& node) {
  const auto v = node.as_reals("m");
  if (v.size() != kDim) throw node.error("expected a point with " + std::to_string(kDim) + " coordinates");
  return {v[0], v[1]};
}

/// Two physics reading one material key must mean the same thing by it.
bool same_spec(const ParamSpec& a, const ParamSpec& b) {
  return a.type == b.type && a.unit == b.unit && a.default_value == b.default_value && a.lower == b.lower &&
         a.upper == b.upper && a.lower_open == b.lower_open && a.upper_open == b.upper_open &&
         a.choices == b.choices && a.list_size == b.list_size;
}

std::string spec_text(const ParamSpec& s) {
  return "[" + s.unit + "] default " + s.default_text() + (s.range_text().empty() ? "" : " range " + s.range_text());
}

/// A model parameter named like a material constant (ice_density, latent_heat, ...) is that
/// constant: one source, so a freezing curve cannot silently keep 917 kg/m³ while the heat
/// balance uses the material's 920. Left out of the model section it takes the material's value;
/// given there with another value it is an error naming both places. Same name and same unit
/// make a shared constant.
void take_material_constants(ModelSection& model, const ConfigNode& model_node, const ParamSet& material,
                             const ParamSchema& material_schema) {
  for (const auto& spec : model.entry->schema.params()) {
    const ParamSpec* constant = material_schema.find(spec.name);
    // Another unit is another quantity that happens to share the symbol (the earth-pressure
    // coefficient k0 [-] of a material and the conductivity k0 [m/s] of a permeability model).
    if (!constant || spec.type != ParamType::Real || constant->type != ParamType::Real || spec.unit != constant->unit)
      continue;
    const std::string owner = model.entry->kind + " model '" + model.entry->name + "'";
    const double shared = material.real(spec.name);
    if (model_node.has(spec.name)) {
      const double own = model.params.real(spec.name);
      if (own != shared)
        throw model_node.child(spec.name).error(
            owner + " sets " + spec.name + " = " + number_text(own) + " but its material has " + spec.name + " = " +
            number_text(shared) + " (" + material.where(spec.name).describe() +
            "): a model reads its material's constants; remove it here or make the two agree");
      continue;
    }
    if (!spec.in_range(shared))
      throw InputError(material.where(spec.name),
                       "the material's " + spec.name + " = " + number_text(shared) + " is outside the range " +
                           spec.range_text() + " that " + owner + " accepts");
    model.params.set(spec.name, shared, material.where(spec.name));
  }
}

/// An optional parameter a model section leaves out is the same-named parameter (same unit) of
/// another model of the material: the ice-strength s_c of mohr_coulomb_ice reads λ from the
/// freezing curve (sfcc: {model: van_genuchten_cc, lambda: ...}) instead of a second copy.
/// Given in both sections, the two must agree.
void share_between_models(std::map<std::string, ModelSection>& models, const ConfigNode& material) {
  for (auto& [key, model] : models)
    for (const auto& spec : model.entry->schema.params()) {
      if (spec.optional_meaning.empty() || spec.type != ParamType::Real) continue;
      for (const auto& [other_key, other] : models) {
        if (other_key == key) continue;
        const ParamSpec* theirs = other.entry->schema.find(spec.name);
        if (!theirs || theirs->type != ParamType::Real || theirs->unit != spec.unit || !other.params.has(spec.name))
          continue;
        const double value = other.params.real(spec.name);
        if (!model.params.has(spec.name)) {
          if (!spec.in_range(value))
            throw InputError(other.params.where(spec.name),
                             spec.name + " = " + number_text(value) + " is outside the range " + spec.range_text() +
                                 " that " + model.entry->kind + " model '" + model.entry->name + "' accepts");
          model.params.set(spec.name, value, other.params.where(spec.name));
        } else if (model.params.real(spec.name) != value) {
          throw material.child(key).child(spec.name).error(
              model.entry->kind + " model '" + model.entry->name + "' sets " + spec.name + " = " +
              number_text(model.params.real(spec.name)) + " but the material's " + other_key + " model has " +
              spec.name + " = " + number_text(value) + " (" + other.params.where(spec.name).describe() +
              "): one quantity, one value; leave it out here to use that one");
        }
      }
    }
}

/// The `grid:` section.
ParamSchema grid_schema() {
  ParamSchema s;
  s.reals("origin", "m", "lower-left corner of the grid").size(kDim).defaults_to(std::vector<double>(kDim, 0.0));
  // At most 1e8 per axis: an int, and the 50-million-node cap below still applies.
  s.reals("cells", "-", "number of cells along each axis").size(kDim).at_least(1).at_most(1e8);
  // Bounded so that cell volumes and particle volumes stay normal doubles (1e-300 m gave NaN).
  s.reals("cell_size", "m", "cell size: one value (square cells) or one per axis").at_least(1e-6).at_most(1e6);
  s.choice("shape_function", shape_kind_names(), "MPM shape functions").defaults_to("gimp");
  s.integer("particles_per_cell", "particles per cell along each axis").defaults_to(2L).at_least(1).at_most(8);
  s.choice("particles_leaving", {"stop", "remove"},
           "a particle whose support leaves the grid: stop the run naming it, or remove it (what it carries is "
           "counted in run.json)")
      .defaults_to("stop");
  std::vector<std::string> periodic_choices = {"none", "x", "y"};
  if (kDim == 3) periodic_choices.insert(periodic_choices.end(), {"z", "xz"});
  s.choice("periodic", periodic_choices,
           "axes along which the grid wraps round (max face = min face), e.g. x for an infinite slope or "
           "layer; conditions on those faces are refused")
      .defaults_to("none");
  return s;
}

/// The `time:` section.
ParamSchema time_schema() {
  ParamSchema s;
  s.real("end", "s", "simulated end time").above(0);
  s.real("dt", "s", "fixed time step; 0 = automatic from the physics' stability limits").defaults_to(0.0).at_least(0);
  s.real("dt_max", "s", "upper bound on an automatic step; 0 = none").defaults_to(0.0).at_least(0);
  s.integer("max_steps", "most steps, metrics rows or field frames a run may take; a scene needing more is refused")
      .defaults_to(kDefaultMaxSteps).at_least(1);
  s.real("mass_scaling", "-",
         "factor on every inertia (skeleton and pore water; not on weight): an explicit skeleton's stable step "
         "grows with its square root, for slow processes (consolidation, thaw) where inertia plays no part; "
         "run.json's mechanical.kinetic_to_work_max says whether it stayed negligible")
      .defaults_to(1.0)
      .at_least(1)
      .at_most(1e12);
  s.real("transport_scaling", "-",
         "factor on every thermal conductivity and permeability: heat and pore water move this many times faster, "
         "so one second of the run stands for this many seconds of conduction and seepage while inertia and "
         "prescribed speeds keep real time (Yu et al. 2024 use 250 × 86400 in Sec. 5.3); prescribed fluxes and "
         "heat transfer coefficients are not scaled")
      .defaults_to(1.0)
      .at_least(1)
      .at_most(1e12);
  return s;
}

/// The `output:` section.
ParamSchema output_schema() {
  ParamSchema s;
  s.real("every", "s", "simulated time between field frames (fields.h5); 0 = first and last only")
      .defaults_to(0.0).at_least(0);
  s.real("metrics_every", "s", "simulated time between metrics.csv rows; 0 = every step").defaults_to(0.0).at_least(0);
  s.boolean("progress", "print a progress line every 2 s of wall time: simulated time (in s, min, h, d or yr) and its percentage of time.end, step, dt and ETA").defaults_to(true);
  return s;
}

/// The `checkpoint:` section.
ParamSchema checkpoint_schema() {
  ParamSchema s;
  s.integer("every_steps", "steps between checkpoints (OUT/checkpoint.h5); 0 = off").defaults_to(0L).at_least(0);
  s.real("every_minutes", "min", "wall-clock minutes between checkpoints; 0 = off").defaults_to(30.0).at_least(0);
  s.boolean("at_end",
            "keep a checkpoint of the finished run, so that `run --restart OUT --set time.end=LATER` can extend it")
      .defaults_to(true);
  return s;
}

}  // namespace

std::vector<std::string> Simulation::sections() {
  return {"grid",    "time",       "gravity", "physics", "materials", "regions", "boundary_conditions",
          "output", "probes", "checkpoint"};
}

std::vector<std::pair<std::string, ParamSchema>> Simulation::section_schemas() {
  return {{"grid", grid_schema()}, {"time", time_schema()}, {"output", output_schema()},
          {"checkpoint", checkpoint_schema()}};
}

void Simulation::read_grid(const ConfigNode& node) {
  const ParamSet p = parse_params(grid_schema(), node);
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
  leaving_ = p.string("particles_leaving") == "remove" ? LeavingPolicy::Remove : LeavingPolicy::Stop;
  grid_.ghost_layers = ghost_layers(shape_);
  const std::string& periodic = p.string("periodic");
  for (int d = 0; d < kDim; ++d) {
    grid_.periodic[d] = periodic.find("xyz"[d]) != std::string::npos;  // "none" names no axis
    // More cells than the support is wide: a wrapped stencil never meets itself.
    const int needed = support_width(shape_) + 1;
    if (grid_.periodic[d] && grid_.cells[d] < needed)
      throw p.error("periodic", std::string("a periodic axis needs at least ") + std::to_string(needed) +
                                    " cells with the " + to_string(shape_) + " shape function; axis " + "xyz"[d] +
                                    " has " + std::to_string(grid_.cells[d]));
  }
  transfer_.configure(shape_);
  resolved_["grid"] = p.to_yaml();
}

void Simulation::read_time(const ConfigNode& node) {
  const ParamSet p = parse_params(time_schema(), node);
  end_time_ = p.real("end");
  fixed_dt_ = p.real("dt");
  max_dt_ = p.real("dt_max");
  max_steps_ = p.integer("max_steps");
  if (fixed_dt_ > 0)
    check_count(p, "dt", end_time_ / fixed_dt_, max_steps_, "steps", "time.end / time.dt");
  time_params_ = p;
  resolved_["time"] = p.to_yaml();
}

void Simulation::read_gravity(const ConfigNode* node) {
  if (!node) {
    resolved_["gravity"] = std::vector<double>(kDim, 0.0);
    return;
  }
  gravity_where_ = node->where();
  const auto g = node->as_reals("m/s^2");
  if (g.size() != kDim)
    throw node->error("gravity is a vector of " + std::to_string(kDim) + " components in m/s^2, e.g. [0, -9.81]");
  for (int d = 0; d < kDim; ++d) {
    // 1000 g covers every centrifuge test; beyond is a typo (a unit slip, 9810).
    if (!std::isfinite(g[d]) || std::abs(g[d]) > 1e4)
      throw node->error(number_text(g[d]) + " m/s^2 is beyond the plausible range [-1e4, 1e4] of a gravity component");
    gravity_[d] = g[d];
  }
  resolved_["gravity"] = g;
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
  // One merged schema: a key several physics read (e.g. porosity) is validated once, so the
  // physics must agree on what it is.
  ParamSchema merged;
  std::map<std::string, std::string> declared_by;
  std::vector<ModelSlot> slots;
  for (std::size_t i = 0; i < physics_.size(); ++i) {
    const ParamSchema schema = physics_[i]->material_schema();
    for (const auto& spec : schema.params()) {
      if (const ParamSpec* earlier = merged.find(spec.name)) {
        if (!same_spec(*earlier, spec))
          throw InputError(physics_where_[i], "physics '" + physics_keys_[i] + "' declares the material key '" +
                                                  spec.name + "' as " + spec_text(spec) + ", physics '" +
                                                  declared_by[spec.name] + "' as " + spec_text(*earlier) +
                                                  ": the two plugins disagree on what it means");
        continue;
      }
      auto& added = merged.real(spec.name, spec.unit, spec.doc);
      added = spec;
      declared_by[spec.name] = physics_keys_[i];
    }
    for (const auto& slot : physics_[i]->material_models())
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
      take_material_constants(model, section.child(slot.key), material.params, merged);
      material.models.emplace(slot.key, std::move(model));
    }
    share_between_models(material.models, section);
    for (const auto& slot : slots)
      if (const auto it = material.models.find(slot.key); it != material.models.end()) out[slot.key] = it->second.resolved();
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
  particles_.declare("position", "m", kDim, 0.0, FieldKind::Vector);
  // A 2-D particle stands for a prism one metre thick: its volume is per metre of thickness.
  particles_.declare("volume", "m^3/m");
  particles_.declare("half_size", "m", kDim, 0.0, FieldKind::Vector);
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
    region_inits_.push_back(RegionInit{range, std::move(regions[r].initial)});
  }
  if (particles_.size() == 0) throw node.error("the regions contain no particles inside the grid");
  std::vector<std::uint16_t> material(particles_.size());
  for (const auto& r : particles_.ranges())
    std::fill(material.begin() + r.begin, material.begin() + r.end, static_cast<std::uint16_t>(r.material));
  transfer_.set_materials(std::move(material));
  if (leaving_ == LeavingPolicy::Remove) {
    // Removal renumbers particles: each keeps the index the scene gave it, for output and restarts.
    particles_.declare("particle_id", "1", 1, 0.0, FieldKind::Scalar);
    auto id = particles_.field("particle_id");
    for (std::size_t p = 0; p < id.size(); ++p) id[p] = static_cast<double>(p);
  }
  initial_particles_ = particles_.size();
  resolved_["regions"] = resolved;
}

void Simulation::read_boundary_conditions(const ConfigNode& node) {
  for (std::size_t i = 0; i < physics_.size(); ++i)
    for (const auto& type : physics_[i]->boundary_types()) bc_owner_[type] = physics_keys_[i];
  std::vector<std::string> types;
  for (const auto& [t, _] : bc_owner_) types.push_back(t);
  std::map<std::string, SourceLocation> names;
  for (const auto& item : node.elements()) {
    BoundaryCondition bc;
    const ConfigNode type = item.child("type");
    bc.type = type.as_string();
    if (!bc_owner_.count(bc.type)) {
      // A type another physics owns: say which, so the fix is to enable it, not to rename.
      if (const RegistryEntry* described = registry_.find(BoundaryType::kKind, bc.type))
        for (const RegistryEntry* physics : registry_.entries("physics"))
          if (physics->library == described->library)
            throw type.error("boundary condition type '" + bc.type + "' belongs to the physics '" + physics->name +
                             "', which this scene does not enable (add it under physics:). Types of the physics in "
                             "this scene: " + join(types));
      throw type.error("unknown boundary condition type '" + bc.type + "'" + did_you_mean(bc.type, types) +
                       " Types of the physics in this scene: " + join(types));
    }
    if (auto name = item.optional_child("name")) {
      bc.name = name->as_string();
      if (const auto [it, fresh] = names.emplace(bc.name, name->where()); !fresh)
        throw name->error("boundary condition name '" + bc.name + "' is used twice (first at " +
                          it->second.describe() + ")");
    }
    const bool on_nodes = item.has("nodes");
    const bool on_particles = item.has("particles");
    if (on_nodes == on_particles) throw item.error("give exactly one target: 'nodes:' or 'particles:'");
    if (on_nodes) {
      const ConfigNode target = item.child("nodes");
      target.reject_unknown({"face", "range", "box"});
      if (target.has("face") == target.has("box"))
        throw target.error("expected {face: NAME} (with an optional range: [from, to]) or {box: {min, max}}");
      if (auto face = target.optional_child("face")) {
        bool ok = false;
        const GridFace f = GridFace::parse(face->as_string(), kDim, ok);
        if (!ok) throw face->error("'" + face->as_string() + "' is not a face; valid: x_min, x_max, y_min, y_max");
        if (grid_.periodic[f.axis])
          throw face->error("face " + f.name() + " is not a boundary: the grid is periodic along " + "xyz"[f.axis] +
                            " (grid.periodic); use a face across another axis or a box");
        face_nodes(grid_, f, bc.nodes, bc.node_areas);
        bc.face_axis = f.axis;
        bc.face_side = f.side;
        bc.target_text = "face " + f.name();
        // Part of a face: `from`/`to` along the face's other axis (a footing, a surcharge strip).
        if (auto along = target.optional_child("range")) {
          const auto r = along->as_reals("m");
          if (r.size() != 2 || !(r[0] < r[1])) throw along->error("expected [from, to] with from < to, in metres");
          const int other = 1 - f.axis;
          std::vector<std::size_t> kept;
          std::vector<double> areas;
          const double h = grid_.spacing[other], tol = 1e-9 * h;
          const double face_lo = grid_.origin[other], face_hi = grid_.upper()[other];
          for (std::size_t j = 0; j < bc.nodes.size(); ++j) {
            const double x = grid_.node_position(bc.nodes[j])[other];
            // The node's part of [from, to]: its tributary half cells, cut to the range and the face,
            // so a traction integrates to exactly q (to − from) wherever the ends fall.
            const double share = std::max(0.0, std::min({x + 0.5 * h, r[1], face_hi}) -
                                                   std::max({x - 0.5 * h, r[0], face_lo}));
            if (share <= tol && (x < r[0] - tol || x > r[1] + tol)) continue;
            kept.push_back(bc.nodes[j]);
            areas.push_back(share);
          }
          if (kept.empty()) throw along->error("no node of face " + f.name() + " lies within the range");
          bc.nodes = std::move(kept);
          bc.node_areas = std::move(areas);
          bc.target_text += " within [" + number_text(r[0]) + ", " + number_text(r[1]) + "] m";
        }
      } else {
        // A box has its extent already; `range:` would have been ignored.
        if (auto range = target.optional_child("range"))
          throw range->error("range: selects part of a face (nodes: {face: ..., range: [from, to]}); a box gives "
                             "its extent with min: and max:");
        const ConfigNode box = target.child("box");
        box.reject_unknown({"min", "max"});
        const auto lo = read_point(box.child("min"));
        const auto hi = read_point(box.child("max"));
        bc.nodes = box_nodes<kDim>(grid_, lo, hi);
        bc.node_areas.assign(bc.nodes.size(), 0.0);
        bc.target_text = "node box";
        if (bc.nodes.empty()) throw box.error("the box contains no grid nodes");
      }
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
    // The owning physics reads the rest; `type`, `name` and the target are consumed here.
    bc.node = std::make_unique<ConfigNode>(item);
    bcs_.push_back(std::move(bc));
  }
}

void Simulation::read_output(const ConfigNode& node) {
  const ParamSet p = parse_params(output_schema(), node, {"fields"});
  output_every_ = p.real("every");
  metrics_every_ = p.real("metrics_every");
  if (output_every_ > 0)
    check_count(p, "every", end_time_ / output_every_, max_steps_, "field frames", "time.end / output.every");
  if (metrics_every_ > 0)
    check_count(p, "metrics_every", end_time_ / metrics_every_, max_steps_, "metrics rows",
                "time.end / output.metrics_every");
  YAML::Node out = p.to_yaml();
  std::vector<std::string> names;
  for (const auto& n : particles_.field_names())
    if (!particles_.internal(n)) names.push_back(n);
  if (auto fields = node.optional_child("fields")) {
    for (const auto& f : fields->elements()) {
      const std::string name = f.as_string();
      if (!particles_.has(name) || particles_.internal(name))
        throw f.error("unknown field '" + name + "'; available: " + join(names));
      if (name != "position") output_fields_.push_back(name);
    }
  }
  out["fields"] = output_fields_;
  resolved_["output"] = out;
}

void Simulation::read_checkpoint(const ConfigNode& node) {
  const ParamSet p = parse_params(checkpoint_schema(), node);
  checkpoint_every_steps_ = p.integer("every_steps");
  checkpoint_every_minutes_ = p.real("every_minutes");
  checkpoint_at_end_ = p.boolean("at_end");
  resolved_["checkpoint"] = p.to_yaml();
}

}  // namespace frostmpm
