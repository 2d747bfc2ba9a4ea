#include "frostmpm/physics/boundary_type.hpp"

#include <stdexcept>

namespace frostmpm {

ParamSpec& time_function_key(ParamSchema& keys, const std::string& name, const std::string& unit,
                             const std::string& what, double bound) {
  return keys.real(name, unit, what + ", a time function: a number, {table: [[t, v], ...]} or {expression: \"...t...\"}")
      .at_least(-bound)
      .at_most(bound);
}

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
