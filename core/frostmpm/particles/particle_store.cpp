#include "frostmpm/particles/particle_store.hpp"

#include "frostmpm/config/units.hpp"
#include "frostmpm/parallel/parallel.hpp"

#include <algorithm>
#include <stdexcept>

namespace frostmpm {

std::vector<std::string> component_names(FieldKind kind, int components) {
  switch (kind) {
    case FieldKind::Scalar: return {};
    case FieldKind::Vector: {
      std::vector<std::string> names;
      for (int d = 0; d < std::min(components, 3); ++d) names.push_back(std::string(1, "xyz"[d]));
      return names;
    }
    case FieldKind::SymmetricTensor: return {"xx", "yy", "zz", "yz", "xz", "xy"};
    case FieldKind::Tensor: return {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
    case FieldKind::Other: break;
  }
  if (components == 1) return {};
  std::vector<std::string> names;
  for (int c = 0; c < components; ++c) names.push_back("c" + std::to_string(c));
  return names;
}

void ParticleStore::declare(const std::string& name, const std::string& unit, int components, double initial,
                            FieldKind kind) {
  if (!units::is_output_unit(unit))
    throw std::logic_error("particle field '" + name + "' declared with the unit '" + unit +
                           "'; give a UDUNITS-2 unit such as \"degC\", \"m/s\", or \"1\" when dimensionless");
  auto it = fields_.find(name);
  if (it != fields_.end()) {
    if (it->second.components != components)
      throw std::logic_error("particle field '" + name + "' declared with " + std::to_string(components) +
                             " and " + std::to_string(it->second.components) + " components");
    if (it->second.unit != unit)
      throw std::logic_error("particle field '" + name + "' declared in '" + unit + "' and in '" + it->second.unit + "'");
    if (it->second.kind == FieldKind::Other) it->second.kind = kind;
    return;
  }
  // Undeclared shapes: 1 component is a scalar, 2 or 3 a vector (x, y[, z]).
  if (kind == FieldKind::Other && components == 1) kind = FieldKind::Scalar;
  if (kind == FieldKind::Other && (components == 2 || components == 3)) kind = FieldKind::Vector;
  Column column{components, initial, kind, unit, false, std::vector<double>(size_ * components, initial)};
  fields_.emplace(name, std::move(column));
}

void ParticleStore::declare_history(const std::string& name, const std::string& unit, int components, double initial,
                                    FieldKind kind) {
  declare(name, unit, components, initial, kind);
  const std::string start = history_name(name);
  declare(start, unit, components, initial, kind);
  fields_.at(start).internal = true;
  if (std::find(history_.begin(), history_.end(), name) == history_.end()) history_.push_back(name);
}

void ParticleStore::begin_step() {
  for (const auto& name : history_) {
    const auto& current = fields_.at(name).values;
    auto& start = fields_.at(history_name(name)).values;
    const std::size_t n = current.size();
    const double* from = current.data();
    double* to = start.data();
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (std::size_t i = 0; i < n; ++i) to[i] = from[i];
  }
}

const ParticleStore::Column& ParticleStore::find(const std::string& name) const {
  const auto it = fields_.find(name);
  if (it == fields_.end()) throw std::logic_error("particle field '" + name + "' was never declared");
  return it->second;
}

int ParticleStore::components(const std::string& name) const { return find(name).components; }
FieldKind ParticleStore::kind(const std::string& name) const { return find(name).kind; }
const std::string& ParticleStore::unit(const std::string& name) const { return find(name).unit; }
bool ParticleStore::internal(const std::string& name) const { return find(name).internal; }

std::span<double> ParticleStore::field(const std::string& name) { return column(name); }

std::span<const double> ParticleStore::field(const std::string& name) const { return find(name).values; }

std::vector<double>& ParticleStore::column(const std::string& name) { return const_cast<Column&>(find(name)).values; }

ParticleRange ParticleStore::append(std::size_t count, int material) {
  ParticleRange range{size_, size_ + count, material};
  size_ += count;
  for (auto& [_, column] : fields_) column.values.resize(size_ * column.components, column.initial);
  ranges_.push_back(range);
  return range;
}

void ParticleStore::remove(const ParticleRemoval& removal) {
  if (removal.leaving.size() != size_) throw std::invalid_argument("ParticleStore::remove: one flag per particle expected");
  for (auto& [_, column] : fields_) removal.compact(column.values, static_cast<std::size_t>(column.components));
  // Each region keeps its (possibly empty) range, so range k still names regions.k.
  std::size_t kept = 0;
  for (auto& range : ranges_) {
    const std::size_t begin = kept;
    for (std::size_t p = range.begin; p < range.end; ++p) kept += removal.leaving[p] ? 0 : 1;
    range.begin = begin;
    range.end = kept;
  }
  size_ = kept;
}

std::vector<std::string> ParticleStore::field_names() const {
  std::vector<std::string> out;
  for (const auto& [name, _] : fields_) out.push_back(name);
  return out;
}

std::size_t ParticleStore::bytes() const {
  std::size_t total = 0;
  for (const auto& [_, column] : fields_) total += column.values.capacity() * sizeof(double);
  return total;
}

}  // namespace frostmpm
