// Initial values of particle fields: the regions' `initial:` entries — constants, expressions,
// profile tables and another run's output (`from: OUT`) — applied at set-up.
#include "frostmpm/simulation/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "frostmpm/io/particle_field_reader.hpp"
#include "frostmpm/scene/expression.hpp"
#include "frostmpm/scene/scattered_field.hpp"

namespace frostmpm {

namespace {
/// `{table: [[c0, v0], [c1, v1], ...], along: y}` (a coordinate) or `{table: [[d0, v0], ...],
/// depth_below: Y}` (depth d = Y − y, a borehole log): linear between the rows, the end values
/// beyond them; coordinates in m, values in `unit`. Calls set(p, value) for every particle of
/// the range.
template <class Set>
void assign_profile(const ConfigNode& node, const std::string& unit, const ParticleRange& range,
                    std::span<const double> pos, int dim, Set&& set) {
  const ConfigNode table = node.child("table");
  std::vector<double> at, values;
  for (const auto& row : table.elements()) {
    const auto pair = row.as_row({"m", unit}, "a row [coordinate, value] of two finite numbers");
    if (!at.empty() && !(pair[0] > at.back()))
      throw row.error("the table's coordinates must increase strictly (" + number_text(at.back()) + " then " +
                      number_text(pair[0]) + ")");
    at.push_back(pair[0]);
    values.push_back(pair[1]);
  }
  if (at.size() < 2) throw table.error("a profile table needs at least 2 rows [coordinate, value]");
  const bool by_depth = node.has("depth_below");
  if (by_depth == node.has("along"))
    throw node.error("give the table's coordinate: along: x|y" + std::string(dim == 3 ? "|z" : "") +
                     ", or depth_below: Y (rows [depth, value], depth = Y − " + std::string(1, "xyz"[dim - 1]) + ")");
  int axis = dim - 1;
  double surface = 0;
  if (by_depth) {
    surface = node.child("depth_below").as_real("m");
  } else {
    const ConfigNode along = node.child("along");
    const std::string name = along.as_string();
    axis = static_cast<int>(std::string("xyz").substr(0, static_cast<std::size_t>(dim)).find(name));
    if (name.size() != 1 || axis < 0)
      throw along.error("unknown coordinate '" + name + "'; valid: x, y" + std::string(dim == 3 ? ", z" : ""));
  }
  node.finish({"table", "along", "depth_below"});
  for (std::size_t p = range.begin; p < range.end; ++p) {
    const double x = pos[p * std::size_t(dim) + std::size_t(axis)];
    const double c = by_depth ? surface - x : x;
    const auto upper = std::upper_bound(at.begin(), at.end(), c);
    double value;
    if (upper == at.begin()) value = values.front();
    else if (upper == at.end()) value = values.back();
    else {
      const std::size_t i = static_cast<std::size_t>(upper - at.begin());
      value = values[i - 1] + (values[i] - values[i - 1]) * (c - at[i - 1]) / (at[i] - at[i - 1]);
    }
    set(p, value);
  }
}
}  // namespace

/// `{from: OUT, frame: last|first|INDEX, field: NAME}`: components [k, k + n) of `field` on the
/// particles of `range` from a frame of another run's fields.h5, interpolated to their
/// positions (ScatteredField). The stored field (by default the same name) has n components,
/// or as many as `field` has and its columns [k, k + n) are taken. Calls set(p, j, value).
template <class Set>
void Simulation::assign_from_run(const ConfigNode& node, const std::string& field, const ParticleRange& range,
                                 int k, int n, Set&& set) {
  const ConfigNode from = node.child("from");
  std::unique_ptr<ParticleFieldReader> reader;
  try {
    reader = std::make_unique<ParticleFieldReader>(from.as_string());
  } catch (const std::runtime_error& e) {
    throw from.error(e.what());
  }
  if (reader->dim() != kDim)
    throw from.error(reader->path() + " holds a " + std::to_string(reader->dim()) + "-D run, this scene is " +
                     std::to_string(kDim) + "-D");
  const auto& frames = reader->frames();
  const ParticleFieldReader::Frame* frame = &frames.back();
  if (node.has("frame")) {
    const ConfigNode f = node.child("frame");
    const std::string text = f.as_string();
    const std::string valid = "valid: last, first, or a frame index 0.." + std::to_string(frames.size() - 1) +
                              " (negative counts from the last)";
    if (text == "first") frame = &frames.front();
    else if (text != "last") {
      long index = 0;
      try {
        std::size_t used = 0;
        index = std::stol(text, &used);
        if (used != text.size()) throw std::invalid_argument(text);
      } catch (const std::exception&) {
        throw f.error("unknown frame '" + text + "'; " + valid);
      }
      const long count = static_cast<long>(frames.size());
      if (index < -count || index >= count)
        throw f.error("frame " + text + " is not among the " + std::to_string(count) + " frames of " + reader->path() +
                      "; " + valid);
      frame = &frames[std::size_t(index < 0 ? index + count : index)];
    }
  }
  const std::string stored = node.has("field") ? node.child("field").as_string() : field;
  node.finish({"from", "frame", "field"});
  const ConfigNode where = node.has("field") ? node.child("field") : from;
  ParticleFieldReader::Field stored_field;
  try {
    stored_field = reader->field(*frame, stored);
  } catch (const std::runtime_error& e) {
    throw where.error(e.what());
  }
  const int sc = stored_field.components;
  std::vector<double> taken;
  if (sc == n) {
    taken = std::move(stored_field.values);
  } else if (sc == particles_.components(field)) {
    // One component of a stored vector: only its column goes into the interpolation.
    taken.resize(frame->count * std::size_t(n));
    for (std::size_t q = 0; q < frame->count; ++q)
      for (int j = 0; j < n; ++j) taken[q * n + j] = stored_field.values[q * std::size_t(sc) + std::size_t(k + j)];
  } else {
    throw where.error("field '" + stored + "' of " + reader->path() + " has " + std::to_string(sc) +
                      " components; '" + field + "' takes " + std::to_string(n));
  }
  const ScatteredField<kDim> source(reader->positions(*frame), std::move(taken), n);
  const auto pos = particles_.field("position");
  std::vector<double> out(static_cast<std::size_t>(n));
  for (std::size_t p = range.begin; p < range.end; ++p) {
    std::array<double, kDim> x;
    for (int d = 0; d < kDim; ++d) x[d] = pos[p * kDim + d];
    if (!source.evaluate(x, out))
      throw from.error(describe_particle(p) + " lies " + number_text(source.nearest_distance(x), 4) +
                       " m from the nearest material point of the frame at t = " + number_text(frame->time) + " s of " +
                       reader->path() + " (its points are " + number_text(source.spacing(), 4) +
                       " m apart): the two runs' material does not cover the same ground");
    for (int j = 0; j < n; ++j) set(p, j, out[std::size_t(j)]);
  }
}

/// Regions' `initial:` values: a state field, or one component of a vector state field
/// ("solid_velocity.x"), set to a number or to an expression of the position,
/// {expression: "0.1*sin(pi*x/50)"} with variables x, y.
void Simulation::apply_initial_values() {
  std::vector<std::string> settable;
  for (const auto& [name, _] : state_defaults_) {
    settable.push_back(name);
    for (const auto& part : component_names(particles_.kind(name), particles_.components(name)))
      settable.push_back(name + "." + part);
  }
  const auto pos = particles_.field("position");
  for (auto& init : region_inits_) {
    if (!init.node) continue;
    const ConfigNode& node = *init.node;
    node.reject_unknown(settable);
    for (const auto& key : node.keys()) {
      const ConfigNode entry = node.child(key);
      // The field and the components the key sets.
      std::string field = key;
      int first = 0, count = 0;
      if (const auto dot = key.rfind('.'); dot != std::string::npos && !particles_.has(key)) {
        field = key.substr(0, dot);
        const auto parts = component_names(particles_.kind(field), particles_.components(field));
        first = static_cast<int>(std::find(parts.begin(), parts.end(), key.substr(dot + 1)) - parts.begin());
        count = 1;
      } else {
        count = particles_.components(field);
      }
      const ParamSpec* spec = material_schema_.find(field);
      const std::string& unit = particles_.unit(field);
      // What is wrong with a value ("is not a finite number"), empty when it is fine.
      auto problem = [&](double value) -> std::string {
        if (!std::isfinite(value)) return "is not a finite number";
        // A material parameter set per region obeys the material's range (porosity in (0, 1)).
        if (spec && !spec->in_range(value))
          return "is outside the range of material parameter '" + field + "'; valid: " + spec->range_text();
        if (std::abs(value) > state_bounds_.at(field))
          return "is beyond the plausible magnitude " + number_text(state_bounds_.at(field)) + " of '" + field + "'";
        return {};
      };
      auto column = particles_.field(field);
      const int c = particles_.components(field);
      // One value, a number, a profile table, a water table or an expression of x and y, into
      // components [k, k + n) of the region's particles.
      auto assign = [&](const ConfigNode& value_node, int k, int n) {
        // Every form's value at particle p goes through here: checked, then stored.
        // `what` names the value when it is refused ("at (x, y) the expression's value ").
        auto store = [&](std::size_t p, double value, const ConfigNode& node, const std::string& what) {
          if (const auto why = problem(value); !why.empty())
            throw node.error(what + number_text(value) + " " + why);
          std::fill_n(column.begin() + std::ptrdiff_t(p * c + k), n, value);
        };
        const auto at_particle = [&](std::size_t p) {
          return "at (" + number_text(pos[p * kDim], 6) + ", " + number_text(pos[p * kDim + 1], 6) + ") ";
        };
        if (!value_node.is_map()) {
          const double value = value_node.as_real(unit);
          for (std::size_t p = init.range.begin; p < init.range.end; ++p) store(p, value, value_node, "the value ");
          return;
        }
        if (value_node.has("table")) {
          assign_profile(value_node, unit, init.range, pos, kDim, [&](std::size_t p, double value) {
            store(p, value, value_node.child("table"), at_particle(p) + "the table's value ");
          });
          return;
        }
        if (value_node.has("from")) {
          assign_from_run(value_node, field, init.range, k, n, [&](std::size_t p, int j, double value) {
            if (const auto why = problem(value); !why.empty())
              throw value_node.error(at_particle(p) + "the value taken from the run " + number_text(value) + " " + why);
            column[p * c + std::size_t(k + j)] = value;
          });
          return;
        }
        if (value_node.has("hydrostatic")) {
          if (field != "pore_pressure")
            throw value_node.child("hydrostatic").error("hydrostatic sets pore_pressure only, not '" + key + "'");
          const ConfigNode h = value_node.child("hydrostatic");
          const double level = h.child("water_table").as_real("m");
          h.finish({"water_table"});
          value_node.finish({"hydrostatic"});
          double g2 = 0;
          for (double g : gravity_) g2 += g * g;
          if (g2 == 0)
            throw h.error("hydrostatic pressure needs gravity, and the scene's gravity is zero; give "
                          "{expression: \"rho*g*(h - y)\"} instead");
          const Material& material = materials_[init.range.material];
          if (!material.params.has("water_density"))
            throw h.error("hydrostatic pressure needs the material's water_density (a hydraulic material)");
          // p = ρ_l g (h − y): the convention of the hydrostatic pore_pressure boundary.
          const double rho_g = material.params.real("water_density") * std::sqrt(g2);
          for (std::size_t p = init.range.begin; p < init.range.end; ++p)
            store(p, rho_g * (level - pos[p * kDim + kDim - 1]), h, at_particle(p) + "the hydrostatic pressure ");
          return;
        }
        if (!value_node.has("expression"))
          throw value_node.error("expected a number, {expression: ...}, {table: ...}, {from: OUT}" +
                                 std::string(field == "pore_pressure" ? " or {hydrostatic: ...}" : "") +
                                 "; got a map with " + join(value_node.keys()));
        const ConfigNode text = value_node.child("expression");
        value_node.finish({"expression"});
        Expression f;
        try {
          f = Expression::compile(text.as_string(), {"x", "y"});
        } catch (const ExpressionError& e) {
          throw text.error("expression '" + text.as_string() + "' : " + e.what());
        }
        for (std::size_t p = init.range.begin; p < init.range.end; ++p) {
          const double at[2] = {pos[p * kDim], pos[p * kDim + 1]};
          store(p, f.evaluate(at), value_node, at_particle(p) + "the expression's value ");
        }
      };
      if (entry.is_sequence()) {
        // One value per component, in the order of their names: solid_velocity: [0.1, 0] (x, y).
        const auto parts = component_names(particles_.kind(field), c);
        const auto values = entry.elements();
        if (count == 1)
          throw entry.error("'" + key + "' is one number: give a number or {expression: ...}, not a list");
        if (values.size() != std::size_t(count))
          throw entry.error("expected one value for every component of '" + field + "' (" + join(parts) + "), got " +
                            std::to_string(values.size()) + "; or one value for all");
        for (int k = 0; k < count; ++k) assign(values[std::size_t(k)], first + k, 1);
      } else {
        assign(entry, first, count);
      }
    }
  }
  // As read: values given with units are now numbers in the fields' units (ConfigNode::as_real).
  for (std::size_t r = 0; r < region_inits_.size(); ++r)
    if (region_inits_[r].node) resolved_["regions"][r]["initial"] = YAML::Clone(region_inits_[r].node->raw());
}

}  // namespace frostmpm
