#include "frostmpm/step/node_fields.hpp"

#include <stdexcept>

namespace frostmpm {

void NodeFields::allocate(const std::string& name, int components, std::size_t nodes) {
  auto [it, added] = fields_.try_emplace(name);
  if (!added) {
    if (it->second.components != components)
      throw std::logic_error("node field '" + name + "' declared with " + std::to_string(components) +
                             " components and with " + std::to_string(it->second.components));
    return;
  }
  it->second.components = components;
  it->second.values.assign(nodes * static_cast<std::size_t>(components), 0.0);
}

const NodeFields::Column& NodeFields::column(const std::string& name) const {
  const auto it = fields_.find(name);
  if (it == fields_.end())
    throw std::logic_error("node field '" + name + "' is not allocated: no stage of this scene declares it");
  return it->second;
}

int NodeFields::components(const std::string& name) const { return column(name).components; }

std::span<double> NodeFields::field(const std::string& name) { return values(name); }

std::span<const double> NodeFields::field(const std::string& name) const { return column(name).values; }

std::vector<double>& NodeFields::values(const std::string& name) {
  return const_cast<Column&>(column(name)).values;
}

std::vector<std::string> NodeFields::names() const {
  std::vector<std::string> out;
  for (const auto& [name, _] : fields_) out.push_back(name);
  return out;
}

std::size_t NodeFields::bytes() const {
  std::size_t total = 0;
  for (const auto& [_, c] : fields_) total += c.values.size() * sizeof(double);
  return total;
}

}  // namespace frostmpm
