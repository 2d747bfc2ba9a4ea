#include "frostmpm/simulation/probes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "frostmpm/config/param_schema.hpp"
#include "frostmpm/config/units.hpp"

namespace frostmpm {

namespace {

std::array<double, Probes::kDim> read_point(const ConfigNode& node) {
  const auto v = node.as_reals("m");
  if (v.size() != Probes::kDim)
    throw node.error("expected a point with " + std::to_string(Probes::kDim) + " coordinates");
  return {v[0], v[1]};
}

int read_component(const ConfigNode& node, int dim) {
  const std::string c = node.as_string();
  for (int d = 0; d < dim; ++d)
    if (c == std::string(1, "xyz"[d])) return d;
  throw node.error("unknown component '" + c + "'; valid: x, y" + std::string(dim == 3 ? ", z" : ""));
}

/// The unit of a product of quantities: their units side by side (UDUNITS reads a space as a
/// product, "m/s m^3/m" as (m/s)·m³/m), dimensionless ones left out.
std::string unit_product(const std::vector<std::string>& factors) {
  std::string product;
  for (const auto& unit : factors)
    if (unit != "1") product += (product.empty() ? "" : " ") + unit;
  return product.empty() ? "1" : product;
}

// The units of the geometric and force probes. A 2-D scene is a slice one metre thick: a force
// on it is per metre of thickness.
constexpr const char* kLengthUnit = "m";
constexpr const char* kForceUnit = "N/m";
constexpr const char* kPressureUnit = "Pa";

}  // namespace

struct Probes::Probe {
  std::string name, type, field;
  std::string unit;  ///< of its column
  std::vector<std::string> fields;
  std::array<double, kDim> point{}, from{}, to{};
  double value = 0;
  int component = 0;
  std::vector<std::size_t> particles;  ///< followed material points (displacement, settlement)
  std::vector<double> start;           ///< their initial coordinate along `component`
  std::string boundary;                ///< reaction: the boundary condition's name
  std::string over_time;               ///< "max"/"min": the extreme over the rows so far, else empty
};

void Probes::remove_particles(const ParticleRemoval& removal, double time) {
  for (auto& probe : probes_) {
    if (probe->particles.empty()) continue;
    std::size_t out = 0;
    for (std::size_t k = 0; k < probe->particles.size(); ++k) {
      const std::size_t p = probe->particles[k];
      if (removal.leaving[p]) continue;
      probe->particles[out] = static_cast<std::size_t>(removal.new_index[p]);
      probe->start[out] = probe->start[k];
      ++out;
    }
    if (out == 0 && !removal.restoring) {
      std::ostringstream msg;
      msg << "probe '" << probe->name << "' (" << probe->type << ") follows material points that have all left the grid at t = "
          << time << " s; enlarge the grid, or place the probe on material that stays";
      throw NumericalBlowUp(msg.str());
    }
    probe->particles.resize(out);
    probe->start.resize(out);
  }
}

Probes::Probes() = default;
Probes::~Probes() = default;
Probes::Probes(Probes&&) noexcept = default;
Probes& Probes::operator=(Probes&&) noexcept = default;

std::vector<std::string> Probes::scalar_names() const {
  std::vector<std::string> scalars;
  const auto& particles = *sources_.particles;
  for (const auto& n : particles.field_names()) {
    if (particles.internal(n)) continue;
    const int c = particles.components(n);
    const auto parts = component_names(particles.kind(n), c);
    if (parts.empty()) scalars.push_back(n);
    else
      for (const auto& part : parts) scalars.push_back(n + "." + part);
  }
  return scalars;
}

Probes::ScalarColumn Probes::scalar_column(const std::string& name) const {
  const auto& particles = *sources_.particles;
  const auto dot = name.rfind('.');
  if (dot != std::string::npos && !particles.has(name)) {
    const std::string base = name.substr(0, dot), part = name.substr(dot + 1);
    const int c = particles.components(base);
    const auto parts = component_names(particles.kind(base), c);
    const std::size_t k = static_cast<std::size_t>(std::find(parts.begin(), parts.end(), part) - parts.begin());
    return {particles.field(base), k, static_cast<std::size_t>(c)};
  }
  return {particles.field(name), 0, 1};
}

const std::string& Probes::scalar_unit(const std::string& name) const {
  const auto& particles = *sources_.particles;
  return particles.unit(particles.has(name) ? name : name.substr(0, name.rfind('.')));
}

void Probes::read(const ConfigNode* node, Sources sources) {
  sources_ = std::move(sources);
  resolved_ = YAML::Node(YAML::NodeType::Sequence);
  if (!node) return;
  static const std::vector<std::string> types = {"min",          "max",        "value_at", "integral",  "isotherm",
                                                 "thaw_depth",   "displacement", "settlement", "reaction",
                                                 "footing_force", "footing_pressure", "footing_displacement"};
  const auto scalars = scalar_names();
  const auto& grid = *sources_.grid;
  const auto positions = sources_.particles->field("position");
  const std::size_t n = sources_.particles->size();
  // Points a probe samples must lie in the grid's domain (outside, the value was a clamp).
  const auto lo = grid.origin, hi = grid.upper();
  auto read_inside = [&](const ConfigNode& at) {
    const auto x = read_point(at);
    for (int d = 0; d < kDim; ++d)
      if (x[d] < lo[d] || x[d] > hi[d])
        throw at.error("the point lies outside the grid [" + number_text(lo[0]) + ", " + number_text(hi[0]) + "] × [" +
                       number_text(lo[1]) + ", " + number_text(hi[1]) + "] m");
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
    const auto& reserved = leading_columns();
    if (std::find(reserved.begin(), reserved.end(), probe->name) != reserved.end())
      throw name.error("'" + probe->name + "' is a column metrics.csv always has (" + join(reserved) +
                       "); give the probe another name");
    if (probe->name.empty() || probe->name.find_first_of(",\n\r\"") != std::string::npos)
      throw name.error("a probe name is a metrics.csv column header: not empty, and without commas, quotes or "
                       "line breaks");
    if (const auto [it, fresh] = first_use.emplace(probe->name, name.where()); !fresh)
      throw name.error("probe name '" + probe->name + "' is used twice (first at " + it->second.describe() +
                       "); metrics.csv needs one column per name");
    if (auto over_time = item.optional_child("over_time")) {
      probe->over_time = over_time->as_string();
      if (probe->over_time != "max" && probe->over_time != "min")
        throw over_time->error("unknown over_time '" + probe->over_time +
                               "'; valid: max, min (the extreme of the probe over the rows written so far)");
    }
    if (probe->type == "integral") {
      std::vector<std::string> factors{sources_.particles->unit("volume")};
      for (const auto& f : item.child("fields").elements()) {
        probe->fields.push_back(check_field(f));
        factors.insert(factors.end() - 1, scalar_unit(probe->fields.back()));
      }
      probe->unit = unit_product(factors);
      if (auto scale = item.optional_child("scale")) {
        probe->value = scale->as_real("-");
        if (!std::isfinite(probe->value)) throw scale->error("scale must be a finite number");
      } else {
        probe->value = 1.0;
      }
      if (auto unit = item.optional_child("unit")) {  // a scale with a unit changes the column's
        probe->unit = unit->as_string();
        if (!units::is_output_unit(probe->unit))
          throw unit->error("a unit is UDUNITS-2 text such as \"m/s\" or \"degC\" (\"1\" when dimensionless)");
      }
      item.finish({"type", "name", "over_time", "fields", "scale", "unit"});
    } else if (probe->type == "displacement") {
      const ConfigNode at = item.child("point");
      probe->point = read_inside(at);
      probe->component = read_component(item.child("component"), kDim);
      // The material point that starts nearest to `point` (ties: the lowest index).
      std::size_t best = 0;
      double best_d2 = std::numeric_limits<double>::infinity();
      for (std::size_t p = 0; p < n; ++p) {
        double d2 = 0;
        for (int d = 0; d < kDim; ++d) d2 += (positions[p * kDim + d] - probe->point[d]) * (positions[p * kDim + d] - probe->point[d]);
        if (d2 < best_d2) best_d2 = d2, best = p;
      }
      probe->particles = {best};
      probe->start = {positions[best * kDim + probe->component]};
      probe->unit = kLengthUnit;
      item.finish({"type", "name", "over_time", "point", "component"});
    } else if (probe->type == "settlement") {
      double x_lo = -std::numeric_limits<double>::infinity(), x_hi = std::numeric_limits<double>::infinity();
      if (auto range = item.optional_child("x_range")) {
        const auto r = range->as_reals("m");
        if (r.size() != 2 || !(r[0] < r[1])) throw range->error("expected [x_min, x_max] with x_min < x_max");
        x_lo = r[0];
        x_hi = r[1];
      }
      // The top particle of every particle column (columns one particle spacing wide).
      const auto half = sources_.particles->field("half_size");
      std::map<long, std::size_t> top;
      for (std::size_t p = 0; p < n; ++p) {
        const double x = positions[p * kDim];
        if (x < x_lo || x > x_hi) continue;
        const long column = std::lround((x - grid.origin[0]) / (2 * half[p * kDim]));
        const auto [it, fresh] = top.emplace(column, p);
        if (!fresh && positions[p * kDim + 1] > positions[it->second * kDim + 1]) it->second = p;
      }
      if (top.empty()) throw item.error("no particle lies within x_range");
      probe->component = kDim - 1;
      probe->unit = kLengthUnit;
      // The surface is the top of these particles' domains: their centres sit half a particle
      // below it, and follow it only where the strain vanishes.
      for (const auto& [_, p] : top) {
        probe->particles.push_back(p);
        probe->start.push_back(positions[p * kDim + kDim - 1] + half[p * kDim + kDim - 1]);
      }
      item.finish({"type", "name", "over_time", "x_range"});
    } else if (probe->type == "reaction" || probe->type.starts_with("footing_")) {
      const ConfigNode boundary = item.child("boundary");
      probe->boundary = boundary.as_string();
      const auto& named = sources_.boundaries;
      const auto it = std::find_if(named.begin(), named.end(),
                                   [&](const NamedBoundary& b) { return b.name == probe->boundary; });
      if (it == named.end()) {
        std::vector<std::string> names;
        for (const auto& b : named) names.push_back(b.name);
        throw boundary.error("no boundary condition is named '" + probe->boundary + "'; named: " +
                             (names.empty() ? std::string("none (give one a name: key)") : join(names)));
      }
      probe->unit = probe->type == "footing_pressure"       ? kPressureUnit
                    : probe->type == "footing_displacement" ? kLengthUnit
                                                            : kForceUnit;
      if (probe->type != "reaction") {
        if (!it->is_rigid_body)
          throw boundary.error("the " + it->label + " drives no rigid body; a " + probe->type +
                               " probe names a condition of type footing");
        item.finish({"type", "name", "over_time", "boundary"});
      } else if (!it->has_reaction) {  // its value would be NaN all run
        const auto& types = sources_.reaction_types;
        throw boundary.error("the " + it->label + " reports no reaction force; of this scene's conditions, " +
                             (types.empty() ? std::string("none does")
                                            : "those of type " + join(types, ", ") + " do"));
      } else {
        probe->component = read_component(item.child("component"), kDim);
        item.finish({"type", "name", "over_time", "boundary", "component"});
      }
    } else if (probe->type == "thaw_depth") {
      if (std::find(scalars.begin(), scalars.end(), "liquid_saturation") == scalars.end())
        throw type.error("a thaw_depth probe reads liquid_saturation, which only the thermal physics has; add "
                         "physics.thermal, or use an isotherm probe of another field");
      probe->field = "liquid_saturation";
      probe->unit = kLengthUnit;
      probe->value = 0.5;
      if (auto level = item.optional_child("saturation")) {
        probe->value = level->as_real("-");
        if (!(probe->value > 0 && probe->value < 1))
          throw level->error("the liquid saturation that separates thawed from frozen must lie in (0, 1)");
      }
      probe->from = read_inside(item.child("from"));
      probe->to = read_inside(item.child("to"));
      if (probe->from == probe->to) throw item.child("to").error("'to' is the same point as 'from'");
      item.finish({"type", "name", "over_time", "saturation", "from", "to"});
    } else {
      probe->field = check_field(item.child("field"));
      probe->unit = probe->type == "isotherm" ? kLengthUnit : scalar_unit(probe->field);
      if (probe->type == "value_at") {
        probe->point = read_inside(item.child("point"));
        item.finish({"type", "name", "over_time", "field", "point"});
      } else if (probe->type == "isotherm") {
        probe->value = item.child("value").as_real(scalar_unit(probe->field));
        probe->from = read_inside(item.child("from"));
        probe->to = read_inside(item.child("to"));
        item.finish({"type", "name", "over_time", "field", "value", "from", "to"});
      } else {
        item.finish({"type", "name", "over_time", "field"});
      }
    }
    resolved_.push_back(YAML::Clone(item.raw()));
    probes_.push_back(std::move(probe));
  }
  extremes_.assign(probes_.size(), std::numeric_limits<double>::quiet_NaN());
}

std::vector<double> Probes::record() {
  std::vector<double> values = evaluate();
  for (std::size_t i = 0; i < probes_.size(); ++i) {
    const std::string& over_time = probes_[i]->over_time;
    if (over_time.empty()) continue;
    // A NaN row (no front along the line yet) leaves the extreme as it was.
    if (std::isnan(extremes_[i])) extremes_[i] = values[i];
    else if (!std::isnan(values[i]))
      extremes_[i] = over_time == "max" ? std::max(extremes_[i], values[i]) : std::min(extremes_[i], values[i]);
    values[i] = extremes_[i];
  }
  return values;
}

std::vector<PersistentArray> Probes::persistent_state() {
  const bool any = std::any_of(probes_.begin(), probes_.end(), [](const auto& p) { return !p->over_time.empty(); });
  if (!any) return {};
  return {{"running_extremes", &extremes_}};
}

std::vector<double> Probes::sample_line(const Probe& probe) const {
  const double length = std::hypot(probe.to[0] - probe.from[0], probe.to[1] - probe.from[1]);
  const int samples = std::max(2, static_cast<int>(std::ceil(4 * length / sources_.grid->min_spacing())));
  std::vector<double> values(static_cast<std::size_t>(samples) + 1);
  const auto nodal = nodal_average(probe.field);  // once: the line samples it many times
  for (int s = 0; s <= samples; ++s) {
    const double f = double(s) / samples;
    values[static_cast<std::size_t>(s)] =
        interpolate(nodal, {probe.from[0] + f * (probe.to[0] - probe.from[0]),
                            probe.from[1] + f * (probe.to[1] - probe.from[1])}) -
        probe.value;
  }
  return values;
}

namespace {
/// The columns every metrics.csv starts with, and their units.
const std::vector<std::pair<std::string, std::string>> kLeadingColumns = {{"time_s", "s"}, {"step", "1"}, {"dt_s", "s"}};
}  // namespace

const std::vector<std::string>& Probes::leading_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> names;
    for (const auto& [name, unit] : kLeadingColumns) names.push_back(name);
    return names;
  }();
  return columns;
}

std::string Probes::header() const {
  std::string header = join(leading_columns(), ",");
  for (const auto& probe : probes_) header += ',' + probe->name;
  return header;
}

std::vector<std::pair<std::string, std::string>> Probes::column_units() const {
  auto units = kLeadingColumns;
  for (const auto& probe : probes_) units.emplace_back(probe->name, probe->unit);
  return units;
}

double Probes::sample_field(const std::string& field, const std::array<double, kDim>& point) const {
  return interpolate(nodal_average(field), point);
}

std::pair<std::vector<double>, std::vector<double>> Probes::nodal_average(const std::string& field) const {
  const auto& stencil = sources_.transfer->stencil();
  const auto [values, component, stride] = scalar_column(field);
  const auto vol = sources_.particles->field("volume");
  const std::size_t K = static_cast<std::size_t>(stencil.per_particle());
  std::vector<double> sum(sources_.grid->node_count(), 0.0), weight(sum.size(), 0.0);
  // Serial: a probe row is far cheaper than a step, and the sums stay independent of threads.
  for (std::size_t p = 0; p < sources_.particles->size(); ++p) {
    const auto* nodes = stencil.nodes(p);
    const auto* w = stencil.weights(p);
    for (std::size_t k = 0; k < K; ++k) {
      sum[nodes[k]] += vol[p] * w[k] * values[p * stride + component];
      weight[nodes[k]] += vol[p] * w[k];
    }
  }
  for (std::size_t i = 0; i < sum.size(); ++i)
    if (weight[i] > 0) sum[i] /= weight[i];
  return {std::move(sum), std::move(weight)};
}

double Probes::interpolate(const std::pair<std::vector<double>, std::vector<double>>& nodal,
                           const std::array<double, kDim>& point) const {
  const auto& grid = *sources_.grid;
  std::array<int, kDim> base{};
  std::array<double, kDim> frac{};
  for (int d = 0; d < kDim; ++d) {
    const double xi = std::clamp((point[d] - grid.origin[d]) / grid.spacing[d], 0.0, double(grid.cells[d]));
    base[d] = std::min(static_cast<int>(std::floor(xi)), grid.cells[d] - 1);
    frac[d] = xi - base[d];
  }
  double value = 0, weight = 0;
  for (int c = 0; c < 4; ++c) {
    const int a = c & 1, b = c >> 1;
    const std::size_t node = grid.node_index({base[0] + a, base[1] + b});
    if (!(nodal.second[node] > 0)) continue;  // no particle reaches this corner
    const double cw = (a ? frac[0] : 1 - frac[0]) * (b ? frac[1] : 1 - frac[1]);
    value += cw * nodal.first[node];
    weight += cw;
  }
  return weight > 0 ? value / weight : std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> Probes::evaluate() const {
  std::vector<double> out;
  const auto& particles = *sources_.particles;
  const auto vol = particles.field("volume");
  const auto positions = particles.field("position");
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
      for (std::size_t p = 0; p < particles.size(); ++p) {
        double v = vol[p];
        for (const auto& c : cols) v *= c.values[p * c.stride + c.component];
        sum += v;
      }
      out.push_back(probe->value * sum);
    } else if (probe->type == "value_at") {
      out.push_back(sample_field(probe->field, probe->point));
    } else if (probe->type == "displacement") {
      const std::size_t p = probe->particles.front();
      out.push_back(positions[p * kDim + probe->component] - probe->start.front());
    } else if (probe->type == "settlement") {
      const auto half = particles.field("half_size");
      double sum = 0;
      for (std::size_t k = 0; k < probe->particles.size(); ++k) {
        const std::size_t p = probe->particles[k];
        sum += probe->start[k] - (positions[p * kDim + probe->component] + half[p * kDim + probe->component]);
      }
      out.push_back(sum / double(probe->particles.size()));
    } else if (probe->type == "reaction") {
      out.push_back(sources_.reaction(probe->boundary)[probe->component]);
    } else if (probe->type.starts_with("footing_")) {
      const auto body = sources_.rigid_body(probe->boundary);
      out.push_back(probe->type == "footing_force"      ? body.force
                    : probe->type == "footing_pressure" ? body.force / body.contact_area
                                                        : body.displacement);
    } else {
      // isotherm: distance from `from` to the first crossing of `value` along the line.
      // thaw_depth: to the last place where thawed material (S_l ≥ level) lies over frozen —
      // the bottom of the thawed layer even once the surface refreezes; 0 when nothing along
      // the line is thawed, the line's length when it is thawed to its end.
      const auto v = sample_line(*probe);
      const double length = std::hypot(probe->to[0] - probe->from[0], probe->to[1] - probe->from[1]);
      const std::size_t last = v.size() - 1;
      const auto at_crossing = [&](std::size_t s) {  // between samples s − 1 and s
        const double f0 = double(s - 1) / double(last), f = double(s) / double(last);
        return (f0 + (f - f0) * v[s - 1] / (v[s - 1] - v[s])) * length;
      };
      double crossing = std::numeric_limits<double>::quiet_NaN();
      if (probe->type == "isotherm") {
        for (std::size_t s = 1; s <= last; ++s)
          if ((v[s - 1] > 0) != (v[s] > 0)) {
            crossing = at_crossing(s);
            break;
          }
      } else {
        crossing = v[last] >= 0 ? length : 0.0;
        for (std::size_t s = last; s >= 1 && v[last] < 0; --s)
          if (v[s - 1] >= 0 && v[s] < 0) {
            crossing = at_crossing(s);
            break;
          }
      }
      out.push_back(crossing);
    }
  }
  return out;
}

}  // namespace frostmpm
