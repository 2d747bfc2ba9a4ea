#pragma once
// A boundary-condition type a physics owns, described like a model: `frostmpm describe
// boundary_conditions/TYPE` prints its keys, and docs/config-reference.md lists every type. The
// physics reads a condition's keys itself — values are time functions (a number, a table or an
// expression of t) and the target (nodes or particles) is the kernel's — and accepts exactly the
// keys named here (BoundaryCondition::accept_keys(type.keys.names())).
#include <cstddef>
#include <span>
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

/// The grid nodes that `particles` make up at least half of by volume, in ascending order:
/// `share` is scratch of the nodes' size, `node_volume[i]` = Σ_p V_p S_ip over every particle.
/// A condition on particles (a temperature or pore pressure held on a surface that is no grid
/// face) holds these nodes: the surface's own, wherever the material has moved it.
///
/// "Half" has a margin, kHalfShareMargin: a layer whose lower edge lies on a node row (two
/// particle rows filling the top cell) makes up exactly half of that row's nodes, and without the
/// margin round-off and strains of 1e-4 decided, node by node, whether the row was held: a 0.1 m
/// strip footing's drained surface came out drained on one node row in places and on two in
/// others, and its undrained frozen ground drew a suction along the stretches of one.
template <class Stencil>
std::vector<std::size_t> nodes_made_up_by(const std::vector<std::size_t>& particles, const Stencil& stencil,
                                          std::span<const double> volume, const std::vector<double>& node_volume,
                                          std::vector<double>& share) {
  share.assign(node_volume.size(), 0.0);
  const int K = stencil.per_particle();
  for (std::size_t p : particles) {
    const auto* nodes = stencil.nodes(p);
    const auto* w = stencil.weights(p);
    for (int k = 0; k < K; ++k) share[nodes[k]] += volume[p] * w[k];
  }
  constexpr double kHalfShareMargin = 0.05;
  std::vector<std::size_t> held;
  for (std::size_t i = 0; i < share.size(); ++i)
    if (share[i] > 0 && share[i] >= (0.5 - kHalfShareMargin) * node_volume[i]) held.push_back(i);
  return held;
}

/// The type called `name` among `types` (a physics' own list; std::out_of_range if absent).
const BoundaryType& boundary_type(const std::vector<BoundaryType>& types, const std::string& name);
/// Their `type:` names, in order.
std::vector<std::string> boundary_type_names(const std::vector<BoundaryType>& types);

}  // namespace frostmpm
