// Boundary conditions of the skeleton, on grid nodes:
//   {type: fixed, nodes: ...}                       every velocity component 0
//   {type: roller, nodes: {face: x_min}}            the face's normal component 0 (or `component: x`)
//   {type: velocity, nodes: ..., x: v(t), y: ...}   the components given follow time functions
//   {type: traction, nodes: {face: ...}, normal: t(t), shear: t(t)}   or x: / y: components [Pa]
//   {type: surcharge, nodes: {face: y_max, range: [a, b]}, value: q(t)}  a pressure pushing in
//   {type: surcharge, particles: {box: ...}, normal: [0, -1], value: q(t)}  on the particles' outer
//        faces (area: their extent across the normal), following the material as it moves
//   {type: rigid_plate, nodes: {face: y_max}, force: F(t)}  a rigid frictionless plate carrying
//                                                   the total force F [N, per m in 2-D] (Mandel)
//   {type: friction, nodes: {face: y_min}, friction_angle: δ}   a rigid wall on a grid face the
//        material may leave but not cross, sliding along it against Coulomb friction μ = tan δ
//   {type: footing, nodes: {box: ...}, y: v(t), contact: rough|smooth}  a rigid footing driven
//        at a prescribed velocity along one axis: the nodes inside its box, which moves with it,
//        and behind its face up to the grid's edge follow it (rough: the other components held
//        at 0); footing_* probes report it
// Velocity conditions also hold the intermediate velocity (paper Sec. 4.2: v* = v^{k+1} on
// ∂Ω_v) and record the force they exert on the material (reaction probes). Where conditions
// meet on a node component:
//  - two velocity conditions must prescribe the same value (a fixed base and side rollers at a
//    corner, both 0); the first keeps the component and its reaction;
//  - a rigid plate shares it with nothing (two plates would each carry their load);
//  - a traction may load some held nodes (a side load reaching the fixed base's corner): the held
//    value wins there and the traction's share goes into that condition's reaction, so no force
//    is lost; a traction all of whose loaded nodes are held on that component is refused, since
//    it could never act.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "mechanical_physics.hpp"

namespace frostmpm::mechanical {

namespace {

constexpr double kMaxVelocity = 1e4;   // m/s
constexpr double kMaxTraction = 1e10;  // Pa

/// constraint_owner_ of a node component no condition holds, and of one rigid plate k moves.
constexpr int kFree = -1;
int plate_owner(std::size_t k) { return -2 - static_cast<int>(k); }

const char* axis_name(int d) { return d == 0 ? "x" : d == 1 ? "y" : "z"; }

/// A prescribed velocity as messages give it: "0.1 m/s", "expression: 0.01*t".
std::string velocity_text(const TimeFunction& f) {
  return f.describe() + (f.kind() == TimeFunction::Kind::Constant ? " m/s" : "");
}

/// The keys x, y (, z) of a condition given by components.
template <int Dim>
std::vector<std::string> axis_keys() {
  std::vector<std::string> keys;
  for (int d = 0; d < Dim; ++d) keys.push_back(axis_name(d));
  return keys;
}

template <int Dim>
int read_axis(const ConfigNode& node) {
  const std::string c = node.as_string();
  for (int d = 0; d < Dim; ++d)
    if (c == axis_name(d)) return d;
  throw node.error("unknown component '" + c + "'; valid: x, y" + std::string(Dim == 3 ? ", z" : ""));
}

/// The components x, y, z of a condition's value, each a time function in `unit`.
void component_keys(ParamSchema& keys, const std::string& unit, const std::string& what, double bound) {
  for (int d = 0; d < 3; ++d)
    time_function_key(keys, axis_name(d), unit, what + " along " + axis_name(d) + (d == 2 ? " (3-D only)" : ""), bound)
        .optional("not prescribed");
}

}  // namespace

std::vector<BoundaryType> mechanical_boundary_types() {
  std::vector<BoundaryType> t(8);
  t[0].name = "fixed";
  t[0].doc = "every velocity component of the nodes 0 (faces, node boxes)";
  t[1].name = "roller";
  t[1].doc = "one velocity component of the nodes 0: a face's normal, or `component` (faces, node boxes)";
  t[1].keys.choice("component", {"x", "y", "z"}, "the component held at 0 (required on a node box)")
      .optional("the face's normal");
  t[2].name = "velocity";
  t[2].doc = "the components given follow their time functions (faces, node boxes; at least one component)";
  component_keys(t[2].keys, "m/s", "the velocity", kMaxVelocity);
  t[3].name = "traction";
  t[3].doc = "force per area on the material, tension positive (faces): normal and shear, or components";
  time_function_key(t[3].keys, "normal", "Pa", "along the face's outward normal", kMaxTraction).optional("none");
  time_function_key(t[3].keys, "shear", "Pa", "along the face (2-D)", kMaxTraction).optional("none");
  component_keys(t[3].keys, "Pa", "the traction", kMaxTraction);
  t[4].name = "surcharge";
  t[4].doc = "a pressure pushing into the material (faces, or particles, whose outward normal is then given; on "
             "particles it follows the material as it moves)";
  time_function_key(t[4].keys, "value", "Pa", "the pressure", kMaxTraction);
  t[4].keys.reals("normal", "-", "on particles: their outward normal along an axis, e.g. [0, 1]")
      .optional("a face's own");
  t[5].name = "rigid_plate";
  t[5].doc = "a rigid frictionless plate on a face carrying the total force into the material; its nodes move as one "
             "along the face's normal";
  time_function_key(t[5].keys, "force", "N/m", "the total force (per m in 2-D)", 1e12);
  t[6].name = "footing";
  t[6].doc = "a rigid footing driven at a prescribed velocity along one axis (a node box, which moves with it): the "
             "nodes inside it, and behind its face up to the grid's edge, follow it; footing_* probes report its "
             "force and pressure";
  component_keys(t[6].keys, "m/s", "the footing's velocity (exactly one component; ramp it from 0)", kMaxVelocity);
  t[6].keys.choice("contact", {"rough", "smooth"}, "rough: the other components held at 0; smooth: frictionless")
      .defaults_to("rough");
  t[7].name = "friction";
  t[7].doc = "a rigid wall on a face the material may leave but not cross, sliding along it against Coulomb "
             "friction μ = tan δ";
  t[7].keys.real("friction_angle", "degree", "the wall's friction angle δ (0: smooth)").at_least(0).below(90);
  return t;
}

namespace {
/// The keys a condition of `type` accepts in Dim dimensions (no z in 2-D).
template <int Dim>
std::vector<std::string> accepted_keys(const std::string& type) {
  static const auto types = mechanical_boundary_types();
  std::vector<std::string> keys;
  for (const auto& k : boundary_type(types, type).keys.names())
    if (Dim == 3 || k != "z") keys.push_back(k);
  return keys;
}
}  // namespace

template <int Dim>
void MechanicalPhysics<Dim>::read_boundaries(Kernel<Dim>& kernel) {
  const double end = kernel.end_time();
  const std::size_t nodes = kernel.grid().node_count();
  constraint_owner_.assign(nodes * Dim, kFree);
  // The condition holding a node component (constraint_owner_ ≠ kFree), for messages.
  auto holder = [&](int owner) {
    return owner >= 0 ? velocity_bcs_[std::size_t(owner)].bc : plates_[std::size_t(-2 - owner)].bc;
  };
  auto on_nodes = [](const BoundaryCondition* bc) {
    if (bc->on_particles)
      throw bc->node->error(bc->type + " acts on grid nodes: use nodes: {face: ...} or {box: ...}");
  };
  // Velocity conditions come before plates and tractions, which check against what they hold.
  auto add_velocity = [&](BoundaryCondition* bc, std::array<std::optional<TimeFunction>, Dim> value) {
    const int index = static_cast<int>(velocity_bcs_.size());
    for (std::size_t i : bc->nodes)
      for (int d = 0; d < Dim; ++d) {
        if (!value[d]) continue;
        int& owner = constraint_owner_[i * Dim + d];
        if (owner == kFree) {
          owner = index;
          continue;
        }
        const VelocityCondition& other = velocity_bcs_[std::size_t(owner)];
        if (!other.value[d]->same_values(*value[d]))
          throw bc->node->error("the " + bc->label() + " prescribes " + axis_name(d) + " = " +
                                velocity_text(*value[d]) + " on nodes where the " + other.bc->label() +
                                " prescribes " + velocity_text(*other.value[d]) +
                                ": a node component follows one value; restrict one condition's nodes");
      }
    VelocityCondition c;
    c.bc = bc;
    c.nodes = bc->nodes;
    c.value = std::move(value);
    velocity_bcs_.push_back(std::move(c));
  };
  for (auto* bc : kernel.boundary_conditions("fixed")) {
    bc->accept_keys(accepted_keys<Dim>("fixed"));
    on_nodes(bc);
    std::array<std::optional<TimeFunction>, Dim> value;
    for (int d = 0; d < Dim; ++d) value[d] = TimeFunction::constant(0.0);
    add_velocity(bc, std::move(value));
  }
  for (auto* bc : kernel.boundary_conditions("roller")) {
    bc->accept_keys(accepted_keys<Dim>("roller"));
    on_nodes(bc);
    int axis = bc->face_axis;
    if (auto component = bc->node->optional_child("component")) axis = read_axis<Dim>(*component);
    if (axis < 0) throw bc->node->error("a roller on a node box needs `component:` (the axis held fixed)");
    std::array<std::optional<TimeFunction>, Dim> value;
    value[axis] = TimeFunction::constant(0.0);
    add_velocity(bc, std::move(value));
  }
  for (auto* bc : kernel.boundary_conditions("velocity")) {
    bc->accept_keys(accepted_keys<Dim>("velocity"));
    on_nodes(bc);
    std::array<std::optional<TimeFunction>, Dim> value;
    bool any = false;
    for (int d = 0; d < Dim; ++d)
      if (auto v = bc->node->optional_child(axis_name(d))) {
        value[d] = TimeFunction::read(*v, "m/s", kMaxVelocity, end);
        any = true;
      }
    if (!any)
      throw bc->node->error("a velocity condition prescribes at least one component: " + join(axis_keys<Dim>()) +
                            " (m/s, a constant, table or expression)");
    add_velocity(bc, std::move(value));
  }
  for (auto* bc : kernel.boundary_conditions("rigid_plate")) {
    bc->accept_keys(accepted_keys<Dim>("rigid_plate"));
    on_nodes(bc);
    if (bc->face_axis < 0) throw bc->node->error("rigid_plate acts on a grid face: use nodes: {face: ...}");
    PlateCondition c;
    c.bc = bc;
    c.nodes = bc->nodes;
    c.axis = bc->face_axis;
    c.side = bc->face_side;
    c.load = TimeFunction::read(bc->node->child("force"), "N/m", 1e12, end);
    for (std::size_t i : c.nodes) {
      int& owner = constraint_owner_[i * Dim + c.axis];
      if (owner != kFree) {
        const bool two_plates = owner < kFree;
        throw bc->node->error("the " + bc->label() + " and the " + holder(owner)->label() + " both prescribe the " +
                              axis_name(c.axis) + " motion of some nodes" +
                              (two_plates ? ": two plates would each carry their own load; give one the total force"
                                          : ""));
      }
      owner = plate_owner(plates_.size());
    }
    plates_.push_back(std::move(c));
  }
  for (auto* bc : kernel.boundary_conditions("friction")) {
    bc->accept_keys(accepted_keys<Dim>("friction"));
    on_nodes(bc);
    if (bc->face_axis < 0) throw bc->node->error("a friction wall lies on a grid face: use nodes: {face: ...}");
    const ConfigNode angle = bc->node->child("friction_angle");
    const double delta = angle.as_real("degree");
    if (!(delta >= 0 && delta < 90))
      throw angle.error("the wall's friction angle δ must lie in [0, 90) degrees (0: smooth; μ = tan δ)");
    FrictionCondition c;
    c.bc = bc;
    c.nodes = bc->nodes;
    c.axis = bc->face_axis;
    c.side = bc->face_side;
    c.coefficient = std::tan(delta * M_PI / 180.0);
    friction_bcs_.push_back(std::move(c));
  }
  for (auto* bc : kernel.boundary_conditions("footing")) read_footing(*bc, kernel);
  place_footings();
  auto add_traction = [&](BoundaryCondition* bc, std::array<TimeFunction, Dim> value) {
    TractionCondition c;
    c.bc = bc;
    c.value = std::move(value);
    if (bc->on_particles) {
      c.particles = bc->particles;
      c.normal_axis = particle_normal_axis(*bc);
      traction_bcs_.push_back(std::move(c));
      return;  // it moves with the material: no fixed node to conflict with
    }
    if (bc->face_axis < 0) throw bc->node->error(bc->type + " acts on a grid face: use nodes: {face: ..., range: [from, to]}");
    c.nodes = bc->nodes;
    c.areas = bc->node_areas;
    for (int d = 0; d < Dim; ++d) {
      if (c.value[d].is_constant() && c.value[d](0.0) == 0.0) continue;
      // Held nodes are fine as long as one node it loads is free to move (see the top of this file).
      std::vector<std::string> holders;
      bool acts = false;
      for (std::size_t j = 0; j < c.nodes.size() && !acts; ++j) {
        if (c.areas[j] <= 0) continue;
        const int owner = constraint_owner_[c.nodes[j] * Dim + d];
        if (owner == kFree) acts = true;
        else if (const std::string label = holder(owner)->label();
                 std::find(holders.begin(), holders.end(), label) == holders.end())
          holders.push_back(label);
      }
      if (!acts && !holders.empty())
        throw bc->node->error("the " + bc->label() + " loads the " + axis_name(d) + " component only of nodes the " +
                              join(holders, " and the ") + (holders.size() > 1 ? " hold" : " holds") +
                              ", so it could never act: a velocity condition and a traction fight on that component "
                              "(a rigid plate's load belongs in its force:)");
    }
    traction_bcs_.push_back(std::move(c));
  };
  for (auto* bc : kernel.boundary_conditions("traction")) {
    bc->accept_keys(accepted_keys<Dim>("traction"));
    std::array<TimeFunction, Dim> value;
    bool by_components = false;
    for (int d = 0; d < Dim; ++d) by_components = by_components || bc->node->has(axis_name(d));
    const bool by_normal = bc->node->has("normal") || bc->node->has("shear");
    if (by_components == by_normal)
      throw bc->node->error("give the traction either as normal: (and in 2-D shear:) or as components " +
                            join(axis_keys<Dim>(), ":, ") + ": (Pa, tension positive)");
    if (by_components) {
      for (int d = 0; d < Dim; ++d)
        if (auto t = bc->node->optional_child(axis_name(d))) value[d] = TimeFunction::read(*t, "Pa", kMaxTraction, end);
    } else {
      if (bc->face_axis < 0) throw bc->node->error("normal: and shear: need a face target: nodes: {face: ...}");
      if (auto t = bc->node->optional_child("normal")) {
        // Along the outward normal: +axis on a max face, −axis on a min face.
        const TimeFunction f = TimeFunction::read(*t, "Pa", kMaxTraction, end);
        value[bc->face_axis] = bc->face_side > 0 ? f : f.scaled(-1.0);
      }
      if (auto t = bc->node->optional_child("shear")) {
        if (Dim != 2) throw t->error("shear: is a 2-D key; in 3-D give the traction by components x:, y:, z:");
        value[1 - bc->face_axis] = TimeFunction::read(*t, "Pa", kMaxTraction, end);
      }
    }
    add_traction(bc, std::move(value));
  }
  for (auto* bc : kernel.boundary_conditions("surcharge")) {
    bc->accept_keys(accepted_keys<Dim>("surcharge"));
    int axis = bc->face_axis, side = bc->face_side;
    if (bc->on_particles) {
      axis = particle_normal_axis(*bc);
      side = bc->node->child("normal").as_reals("-")[std::size_t(axis)] > 0 ? 1 : -1;
    } else if (axis < 0) {
      throw bc->node->error("surcharge acts on a grid face (nodes: {face: ...}) or on particles with an outward normal:");
    }
    const TimeFunction q = TimeFunction::read(bc->node->child("value"), "Pa", kMaxTraction, end);
    std::array<TimeFunction, Dim> value;
    // A pressure pushes into the material: against the outward normal.
    value[axis] = side > 0 ? q.scaled(-1.0) : q;
    add_traction(bc, std::move(value));
  }
}

template <int Dim>
void MechanicalPhysics<Dim>::read_footing(BoundaryCondition& bc, const Kernel<Dim>& kernel) {
  bc.accept_keys(accepted_keys<Dim>("footing"));
  if (bc.on_particles || bc.face_axis >= 0)
    throw bc.node->error("a footing is a rigid body: give its extent as nodes: {box: {min: [...], max: [...]}}; the "
                         "grid nodes inside the box, as it moves, follow the footing");
  const auto& grid = kernel.grid();
  const double end = kernel.end_time(), h = grid.min_spacing();
  FootingCondition f;
  const ConfigNode box = bc.node->child("nodes").child("box");
  const auto lo = box.child("min").as_reals("m"), hi = box.child("max").as_reals("m");
  for (int d = 0; d < Dim; ++d) f.lo[d] = lo.at(std::size_t(d)), f.hi[d] = hi.at(std::size_t(d));

  std::array<std::optional<TimeFunction>, Dim> value;
  int given = 0;
  for (int d = 0; d < Dim; ++d)
    if (auto v = bc.node->optional_child(axis_name(d))) {
      value[d] = TimeFunction::read(*v, "m/s", kMaxVelocity, end);
      f.axis = d;
      ++given;
    }
  if (given != 1)
    throw bc.node->error("a footing moves along one axis: give its velocity as exactly one of " +
                         join(axis_keys<Dim>(), ":, ") + ": (m/s, a constant, table or expression; ramp it from 0)");
  const ConfigNode speed_node = bc.node->child(axis_name(f.axis));
  std::string contact = "rough";
  if (auto c = bc.node->optional_child("contact")) {
    contact = c->as_string();
    if (contact != "rough" && contact != "smooth")
      throw c->error("unknown contact '" + contact +
                     "'; valid: rough (the footing holds the material's other velocity components at 0), smooth "
                     "(frictionless: it only pushes along its axis)");
  }
  if (contact == "rough")
    for (int d = 0; d < Dim; ++d)
      if (d != f.axis) value[d] = TimeFunction::constant(0.0);

  // Its travel over the run (trapezoid on a fine sampling): the fastest speed bounds the step,
  // the farthest reach must stay in the grid.
  const TimeFunction& v = *value[f.axis];
  constexpr int kSamples = 8192;
  const double dt = end / kSamples;
  double u = 0, u_min = 0, u_max = 0, peak = v(0.0), before = v(0.0);
  for (int k = 1; k <= kSamples; ++k) {
    const double t = k * dt, now = v(t);
    u += 0.5 * (before + now) * dt;
    before = now;
    if (std::abs(now) > std::abs(peak)) peak = now;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
  }
  if (peak == 0) throw speed_node.error("the footing's velocity is 0 over the whole run: it would never move");
  f.direction = peak > 0 ? 1.0 : -1.0;
  footing_limit_ = std::min(footing_limit_, h / std::abs(peak));
  if (const double fixed = kernel.fixed_dt(); fixed > 0 && fixed * std::abs(peak) > h)
    throw speed_node.error("at its fastest (" + number_text(std::abs(peak)) + " m/s) the footing would move " +
                           number_text(fixed * std::abs(peak)) + " m in one step of time.dt = " + number_text(fixed) +
                           " s, more than a grid cell (" + number_text(h) + " m): lower the speed or time.dt");
  // The leading face (along the motion) must stay in the grid.
  const double lead = f.direction < 0 ? f.lo[f.axis] + u_min : f.hi[f.axis] + u_max;
  if (lead < grid.origin[f.axis] - 1e-9 * h || lead > grid.upper()[f.axis] + 1e-9 * h)
    throw speed_node.error("the footing would leave the grid: its " + std::string(f.direction < 0 ? "lower" : "upper") +
                           " face reaches " + axis_name(f.axis) + " = " + number_text(lead) + " m within the run, "
                           "outside the grid's [" + number_text(grid.origin[f.axis]) + ", " +
                           number_text(grid.upper()[f.axis]) + "] m; shorten the run or slow the footing");
  f.contact_area = 1;
  for (int d = 0; d < Dim; ++d)
    if (d != f.axis)
      f.contact_area *= std::max(0.0, std::min(f.hi[d], grid.upper()[d]) - std::max(f.lo[d], grid.origin[d]));

  // Every node it will cover: no other condition may prescribe something else there.
  auto [swept_lo, swept_hi] = footing_body(f, grid);
  swept_lo[f.axis] += u_min;
  swept_hi[f.axis] += u_max;
  for (std::size_t i : box_nodes<Dim>(grid, swept_lo, swept_hi))
    for (int d = 0; d < Dim; ++d) {
      const int owner = value[d] ? constraint_owner_[i * Dim + d] : kFree;
      if (owner == kFree) continue;
      if (owner < kFree)
        throw bc.node->error("the " + bc.label() + " would reach nodes whose " + axis_name(d) + " motion the " +
                             plates_[std::size_t(-2 - owner)].bc->label() + " drives; keep the footing off the plate");
      const VelocityCondition& other = velocity_bcs_[std::size_t(owner)];
      if (!other.value[d]->same_values(*value[d]))
        throw bc.node->error("the " + bc.label() + " would reach nodes where the " + other.bc->label() +
                             " prescribes " + axis_name(d) + " = " + velocity_text(*other.value[d]) +
                             ": a node component follows one value; shorten the footing's travel or move it");
    }
  f.velocity = velocity_bcs_.size();
  VelocityCondition c;
  c.bc = &bc;
  c.value = std::move(value);
  velocity_bcs_.push_back(std::move(c));
  footings_.push_back(f);
}

/// The footing's body at t = 0: its box, reaching back from its leading face to the grid's edge
/// behind it. Material cannot pass over a rigid footing; a body only as tall as the box would
/// leave the points its face passes (as it snaps from node row to node row) above it on free
/// nodes straddling held ones, where they add forces of their own and can be thrown off.
template <int Dim>
std::pair<std::array<double, Dim>, std::array<double, Dim>> MechanicalPhysics<Dim>::footing_body(
    const FootingCondition& f, const UniformGrid<Dim>& grid) {
  auto lo = f.lo, hi = f.hi;
  // Far enough that the box still reaches the edge after the footing's whole travel.
  const double reach = grid.upper()[f.axis] - grid.origin[f.axis];
  if (f.direction < 0)
    hi[f.axis] = std::max(hi[f.axis], grid.upper()[f.axis] + reach);
  else
    lo[f.axis] = std::min(lo[f.axis], grid.origin[f.axis] - reach);
  return {lo, hi};
}

template <int Dim>
void MechanicalPhysics<Dim>::place_footings() {
  for (auto& f : footings_) {
    auto& c = velocity_bcs_[f.velocity];
    const int index = static_cast<int>(f.velocity);
    // Components another condition holds stay with it (read_footing checked they agree).
    for (std::size_t i : c.nodes)
      for (int d = 0; d < Dim; ++d)
        if (constraint_owner_[i * Dim + d] == index) constraint_owner_[i * Dim + d] = kFree;
    auto [lo, hi] = footing_body(f, kernel_->grid());
    lo[f.axis] += f.displacement;
    hi[f.axis] += f.displacement;
    c.nodes = box_nodes<Dim>(kernel_->grid(), lo, hi);
    for (std::size_t i : c.nodes)
      for (int d = 0; d < Dim; ++d)
        if (c.value[d] && constraint_owner_[i * Dim + d] == kFree) constraint_owner_[i * Dim + d] = index;
  }
}

template <int Dim>
std::optional<Physics::RigidBodyMotion> MechanicalPhysics<Dim>::rigid_body(const BoundaryCondition& bc) const {
  for (const auto& f : footings_) {
    const auto& c = velocity_bcs_[f.velocity];
    if (c.bc != &bc) continue;
    // The reaction is the force on the material; along the motion it is the resistance.
    return RigidBodyMotion{f.displacement * f.direction, c.reaction[std::size_t(f.axis)] * f.direction, f.contact_area};
  }
  return std::nullopt;
}

/// The axis of a particle condition's outward `normal:` ([0, -1]: the loaded faces face −y).
template <int Dim>
int MechanicalPhysics<Dim>::particle_normal_axis(const BoundaryCondition& bc) {
  const ConfigNode n = bc.node->child("normal");
  const auto v = n.as_reals("-");
  int axis = -1, count = 0;
  for (std::size_t d = 0; d < v.size(); ++d)
    if (v[d] != 0) axis = int(d), ++count;
  if (v.size() != std::size_t(Dim) || count != 1 || std::abs(v[std::size_t(axis)]) != 1.0)
    throw n.error("expected the outward unit normal along an axis, e.g. [0, 1] for a top surface");
  return axis;
}

template <int Dim>
void MechanicalPhysics<Dim>::constrain(std::vector<double>& v, double t, double force_scale) {
  for (std::size_t k = 0; k < velocity_bcs_.size(); ++k) {
    auto& c = velocity_bcs_[k];
    for (int d = 0; d < Dim; ++d) {
      if (!c.value[d]) continue;
      const double value = (*c.value[d])(t);
      for (std::size_t i : c.nodes) {
        if (constraint_owner_[i * Dim + d] != static_cast<int>(k) || mass_[i] <= 0) continue;
        double& vi = v[i * Dim + d];
        // The force that holds the component: (m + Δt D)(v_prescribed − v_free)/Δt.
        if (force_scale > 0) c.reaction[d] += force_scale * (mass_[i] + dt_ * drag_[i]) * (value - vi) / dt_;
        vi = value;
      }
    }
  }
  apply_friction(v, force_scale);
}

/// Coulomb friction on the walls, after the velocity conditions: a node moving into its wall
/// stops along the normal, the normal velocity change Δv_n ≥ 0 being the impulse the wall gives
/// per mass, and its tangential velocity shrinks by at most μ Δv_n (to zero: sticking). A node
/// moving away is left alone (the wall pulls nothing). Components a velocity condition holds
/// keep their value; the force is the impulse over the step, as constrain()'s reactions.
template <int Dim>
void MechanicalPhysics<Dim>::apply_friction(std::vector<double>& v, double force_scale) {
  for (auto& c : friction_bcs_) {
    for (std::size_t i : c.nodes) {
      if (mass_[i] <= 0 || constraint_owner_[i * Dim + c.axis] != kFree) continue;
      double* vi = v.data() + i * Dim;
      const double into = vi[c.axis] * c.side;  // > 0: towards the wall
      if (into <= 0) continue;
      double tangential2 = 0;
      for (int d = 0; d < Dim; ++d)
        if (d != c.axis && constraint_owner_[i * Dim + d] == kFree) tangential2 += vi[d] * vi[d];
      const double tangential = std::sqrt(tangential2);
      const double keep = tangential > 0 ? std::max(0.0, 1.0 - c.coefficient * into / tangential) : 0.0;
      const double m = (mass_[i] + dt_ * drag_[i]) / dt_;
      for (int d = 0; d < Dim; ++d) {
        if (d != c.axis && constraint_owner_[i * Dim + d] != kFree) continue;
        const double now = d == c.axis ? 0.0 : keep * vi[d];
        if (force_scale > 0) c.reaction[d] += force_scale * m * (now - vi[d]);
        vi[d] = now;
      }
    }
  }
}

template <int Dim>
void MechanicalPhysics<Dim>::tie_plates(std::vector<double>& v, double t, double dt, bool with_drag) {
  for (auto& c : plates_) {
    double momentum = 0, inertia = 0;
    for (std::size_t i : c.nodes) {
      const double m = mass_[i] + (with_drag ? dt_ * drag_[i] : 0.0);
      momentum += m * v[i * Dim + c.axis];
      inertia += m;
    }
    // The load pushes into the material: against the face's outward normal.
    const double load = -c.side * c.load(t);
    if (dt > 0) {  // the predictor: the load of this step
      c.applied = {};
      c.applied[c.axis] = load;
    }
    if (inertia <= 0) continue;
    const double plate = (momentum + dt * load) / inertia;
    for (std::size_t i : c.nodes)
      if (mass_[i] > 0) v[i * Dim + c.axis] = plate;
  }
}

template <int Dim>
std::optional<std::array<double, 3>> MechanicalPhysics<Dim>::reaction(const BoundaryCondition& bc) const {
  for (const auto& c : plates_)
    if (c.bc == &bc) return c.applied;
  for (const auto& c : velocity_bcs_)
    if (c.bc == &bc) return c.reaction;
  for (const auto& c : traction_bcs_)
    if (c.bc == &bc) return c.applied;
  for (const auto& c : friction_bcs_)
    if (c.bc == &bc) return c.reaction;
  return std::nullopt;
}

// The members defined in this file, for both dimensions (the class itself is instantiated in
// mechanical_physics.cpp).
#define FROSTMPM_MECHANICAL_BOUNDARIES(D)                                                          \
  template void MechanicalPhysics<D>::read_boundaries(Kernel<D>&);                                 \
  template int MechanicalPhysics<D>::particle_normal_axis(const BoundaryCondition&);               \
  template void MechanicalPhysics<D>::constrain(std::vector<double>&, double, double);             \
  template void MechanicalPhysics<D>::tie_plates(std::vector<double>&, double, double, bool);      \
  template void MechanicalPhysics<D>::apply_friction(std::vector<double>&, double);                \
  template std::optional<std::array<double, 3>> MechanicalPhysics<D>::reaction(const BoundaryCondition&) const; \
  template void MechanicalPhysics<D>::read_footing(BoundaryCondition&, const Kernel<D>&);                 \
  template void MechanicalPhysics<D>::place_footings();                                                     \
  template std::pair<std::array<double, D>, std::array<double, D>> MechanicalPhysics<D>::footing_body(        \
      const FootingCondition&, const UniformGrid<D>&);                                                     \
  template std::optional<Physics::RigidBodyMotion> MechanicalPhysics<D>::rigid_body(const BoundaryCondition&) const;
FROSTMPM_MECHANICAL_BOUNDARIES(2)
FROSTMPM_MECHANICAL_BOUNDARIES(3)
#undef FROSTMPM_MECHANICAL_BOUNDARIES

}  // namespace frostmpm::mechanical
