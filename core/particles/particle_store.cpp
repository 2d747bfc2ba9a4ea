#include "frostmpm/particles/particle_store.hpp"

#include <stdexcept>

namespace frostmpm {

void ParticleStore::declare(const std::string& name, int components, double initial) {
  auto it = fields_.find(name);
  if (it != fields_.end()) {
    if (it->second.components != components)
      throw std::logic_error("particle field '" + name + "' declared with " + std::to_string(components) +
                             " and " + std::to_string(it->second.components) + " components");
    return;
  }
  Column column{components, initial, std::vector<double>(size_ * components, initial)};
  fields_.emplace(name, std::move(column));
}

int ParticleStore::components(const std::string& name) const {
  const auto it = fields_.find(name);
  if (it == fields_.end()) throw std::logic_error("particle field '" + name + "' was never declared");
  return it->second.components;
}

std::span<double> ParticleStore::field(const std::string& name) {
  const auto it = fields_.find(name);
  if (it == fields_.end()) throw std::logic_error("particle field '" + name + "' was never declared");
  return it->second.values;
}

std::span<const double> ParticleStore::field(const std::string& name) const {
  const auto it = fields_.find(name);
  if (it == fields_.end()) throw std::logic_error("particle field '" + name + "' was never declared");
  return it->second.values;
}

ParticleRange ParticleStore::append(std::size_t count, int material) {
  ParticleRange range{size_, size_ + count, material};
  size_ += count;
  for (auto& [_, column] : fields_) column.values.resize(size_ * column.components, column.initial);
  ranges_.push_back(range);
  return range;
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
