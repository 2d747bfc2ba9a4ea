#pragma once
// A boundary-condition type a physics owns, described like a model: `frostmpm describe
// boundary_conditions/TYPE` prints its keys, and docs/config-reference.md lists every type. The
// physics reads a condition's keys itself — values are time functions (a number, a table or an
// expression of t) and the target (nodes or particles) is the kernel's — and accepts exactly the
// keys named here (BoundaryCondition::accept_keys(type.keys.names())).
#include <string>
#include <vector>

#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

struct BoundaryType {
  /// The registry kind the types are listed under: the scene section's name.
  static constexpr const char* kKind = "boundary_conditions";
  std::string name;   ///< the condition's `type:`
  std::string doc;    ///< what it does, and on which targets (faces, node boxes, particles)
  ParamSchema keys;   ///< its keys besides type, name and the target
};

/// Declares a key whose value is a time function (a number, a table or an expression of t, read
/// by TimeFunction::read) of magnitude at most `bound`: `what` says what it is.
ParamSpec& time_function_key(ParamSchema& keys, const std::string& name, const std::string& unit,
                             const std::string& what, double bound);

/// The type called `name` among `types` (a physics' own list; std::out_of_range if absent).
const BoundaryType& boundary_type(const std::vector<BoundaryType>& types, const std::string& name);
/// Their `type:` names, in order.
std::vector<std::string> boundary_type_names(const std::vector<BoundaryType>& types);

}  // namespace frostmpm
