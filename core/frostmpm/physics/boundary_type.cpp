#include "frostmpm/physics/boundary_type.hpp"

#include <stdexcept>

namespace frostmpm {

const BoundaryType& boundary_type(const std::vector<BoundaryType>& types, const std::string& name) {
  for (const auto& t : types)
    if (t.name == name) return t;
  throw std::out_of_range("no boundary type '" + name + "'");
}

std::vector<std::string> boundary_type_names(const std::vector<BoundaryType>& types) {
  std::vector<std::string> names;
  for (const auto& t : types) names.push_back(t.name);
  return names;
}

}  // namespace frostmpm
