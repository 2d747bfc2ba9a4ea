#include "frostmpm/step/step_plan.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace frostmpm {

const char* phase_name(Phase phase) {
  switch (phase) {
    case Phase::MapToGrid: return "map_to_grid";
    case Phase::Energy: return "energy";
    case Phase::PredictMomentum: return "predict_momentum";
    case Phase::Pressure: return "pressure";
    case Phase::CorrectMomentum: return "correct_momentum";
    case Phase::MapToParticles: return "map_to_particles";
    case Phase::UpdateMaterials: return "update_materials";
  }
  return "?";
}

std::span<double> FieldHandle::storage() const {
  if (!column_)
    throw std::logic_error((location_ == FieldLocation::Node ? "node" : "particle") + std::string(" field '") + name_ +
                           "' used through a handle the kernel never bound: no stage of the physics declares it, "
                           "or it is an optional read this scene does not provide");
  return *column_;
}

std::span<double> FieldHandle::mutable_values() const {
  if (!writable_ && column_)
    throw std::logic_error((location_ == FieldLocation::Node ? "node" : "particle") + std::string(" field '") + name_ +
                           "' written through a handle that no stage declares as a write");
  return storage();
}

std::vector<double>& FieldHandle::vector() const {
  storage();
  return *column_;
}

std::string FieldRef::describe() const {
  return std::string(location == FieldLocation::Node ? "node" : "particle") + " field '" + name + "'";
}

namespace {

bool touches(const std::vector<FieldRef>& list, const FieldRef& f) {
  return std::any_of(list.begin(), list.end(), [&](const FieldRef& g) { return g.same_field(f); });
}

std::string key(const FieldRef& f) { return (f.location == FieldLocation::Node ? "n:" : "p:") + f.name; }

/// Orders the stages of one phase (indices into `all`, in declaration order): Kahn's algorithm,
/// always taking the earliest-declared ready stage.
std::vector<std::size_t> order_phase(const std::vector<StepPlan::Declared>& all, const std::vector<std::size_t>& ids) {
  const std::size_t n = ids.size();
  std::vector<std::vector<std::size_t>> after(n);
  std::vector<int> before(n, 0);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      if (a == b) continue;
      const Stage& writer = all[ids[a]].stage;
      const Stage& reader = all[ids[b]].stage;
      // b reads what a writes; two writers of one field keep their declared order.
      const bool edge = std::any_of(writer.writes.begin(), writer.writes.end(), [&](const FieldRef& f) {
        return touches(reader.reads, f) && (!touches(reader.writes, f) || a < b);
      });
      if (edge) {
        after[a].push_back(b);
        ++before[b];
      }
    }
  std::vector<std::size_t> order;
  std::vector<char> done(n, 0);
  while (order.size() < n) {
    std::size_t next = n;
    for (std::size_t i = 0; i < n && next == n; ++i)
      if (!done[i] && before[i] == 0) next = i;
    if (next == n) {  // a cycle: name two stages on it
      std::vector<std::string> names;
      for (std::size_t i = 0; i < n; ++i)
        if (!done[i]) names.push_back("'" + all[ids[i]].stage.name + "'");
      const auto& first = all[ids[std::find(done.begin(), done.end(), 0) - done.begin()]];
      throw InputError(first.where, "stages " + join(names) + " of phase " + phase_name(first.stage.phase) +
                                        " each read a field another of them writes: no order runs them");
    }
    done[next] = 1;
    order.push_back(ids[next]);
    for (std::size_t b : after[next]) --before[b];
  }
  return order;
}

}  // namespace

StepPlan StepPlan::resolve(std::vector<Declared> declared, const std::vector<std::string>& particle_fields) {
  // Field shapes and the units given agree wherever a field is named.
  std::map<std::string, std::pair<int, std::string>> shape;  // key → components, first stage naming it
  std::map<std::string, std::pair<std::string, std::string>> unit;  // key → unit, first stage giving it
  std::set<std::string> carried;
  for (const auto& d : declared)
    for (const auto* list : {&d.stage.reads, &d.stage.writes})
      for (const auto& f : *list) {
        const auto [it, added] = shape.try_emplace(key(f), f.components, d.stage.name);
        if (!added && it->second.first != f.components)
          throw InputError(d.where, "stage '" + d.stage.name + "' declares " + f.describe() + " with " +
                                        std::to_string(f.components) + " components, stage '" + it->second.second +
                                        "' with " + std::to_string(it->second.first));
        if (!f.unit.empty()) {
          const auto [u, first] = unit.try_emplace(key(f), f.unit, d.stage.name);
          if (!first && u->second.first != f.unit)
            throw InputError(d.where, "stage '" + d.stage.name + "' declares " + f.describe() + " in '" + f.unit +
                                          "', stage '" + u->second.second + "' in '" + u->second.first + "'");
        }
        if (list == &d.stage.writes && f.carried) carried.insert(key(f));
      }

  // Skippable stages nobody needs leave the step: none of their writes is read by another stage
  // that stays (repeated, since dropping one can make another unneeded).
  for (bool dropped = true; dropped;) {
    dropped = false;
    for (std::size_t i = 0; i < declared.size(); ++i) {
      if (!declared[i].stage.skippable) continue;
      bool needed = false;
      for (std::size_t j = 0; j < declared.size() && !needed; ++j)
        if (j != i)
          for (const auto& f : declared[i].stage.writes) needed = needed || touches(declared[j].stage.reads, f);
      if (!needed) {
        declared.erase(declared.begin() + static_cast<std::ptrdiff_t>(i));
        dropped = true;
        break;
      }
    }
  }

  // Optional reads nobody provides leave the step: no writer in any stage, and not a particle
  // field the scene has.
  {
    std::set<std::string> writers;
    for (const auto& d : declared)
      for (const auto& f : d.stage.writes) writers.insert(key(f));
    for (auto& d : declared)
      std::erase_if(d.stage.reads, [&](const FieldRef& f) {
        return f.optional && !writers.count(key(f)) &&
               !(f.location == FieldLocation::Particle &&
                 std::find(particle_fields.begin(), particle_fields.end(), f.name) != particle_fields.end());
      });
  }

  std::vector<std::size_t> order;
  for (int p = 0; p < kPhaseCount; ++p) {
    std::vector<std::size_t> ids;
    for (std::size_t i = 0; i < declared.size(); ++i)
      if (static_cast<int>(declared[i].stage.phase) == p) ids.push_back(i);
    for (std::size_t i : order_phase(declared, ids)) order.push_back(i);
  }

  // Every read has a provider.
  std::set<std::string> written;
  const std::set<std::string> state(particle_fields.begin(), particle_fields.end());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Declared& d = declared[order[k]];
    for (const auto& f : d.stage.reads) {
      const bool provided = written.count(key(f)) || carried.count(key(f)) ||
                            (f.location == FieldLocation::Particle && state.count(f.name));
      if (provided) continue;
      std::string later;
      for (std::size_t j = k + 1; j < order.size() && later.empty(); ++j)
        if (touches(declared[order[j]].stage.writes, f))
          later = "; stage '" + declared[order[j]].stage.name + "' writes it later, in phase " +
                  phase_name(declared[order[j]].stage.phase);
      if (later.empty()) {
        std::vector<std::string> physics;
        for (const auto& e : declared)
          if (std::find(physics.begin(), physics.end(), e.physics) == physics.end()) physics.push_back(e.physics);
        later = "; no stage of this scene's physics (" + join(physics) + ") writes it";
      }
      throw InputError(d.where, "stage '" + d.stage.name + "' (phase " + phase_name(d.stage.phase) + ") reads " +
                                    f.describe() + ", which no earlier stage writes" + later);
    }
    for (const auto& f : d.stage.writes) written.insert(key(f));
  }

  StepPlan plan;
  std::set<std::string> listed;
  for (std::size_t i : order) {
    for (const auto* list : {&declared[i].stage.writes, &declared[i].stage.reads})
      for (const auto& f : *list) {
        if (!listed.insert(key(f)).second) continue;
        FieldRef g = f;
        g.carried = carried.count(key(f)) != 0;
        if (f.location == FieldLocation::Node) {
          plan.node_fields_.push_back(g);
        } else if (!state.count(f.name)) {  // the first naming of a new field is its first write
          const auto u = unit.find(key(f));
          if (u == unit.end())
            throw InputError(declared[i].where,
                             "stage '" + declared[i].stage.name + "' writes " + f.describe() +
                                 ", which no physics declares in setup(), and gives no unit for it: declare it there "
                                 "(declare_field(name, unit, ...)) or give the handle of its writer a unit");
          g.unit = u->second.first;
          plan.new_particle_fields_.push_back(g);
        }
      }
    plan.physics_.push_back(declared[i].physics);
    plan.stages_.push_back(std::move(declared[i].stage));
  }
  std::sort(plan.node_fields_.begin(), plan.node_fields_.end(),
            [](const FieldRef& a, const FieldRef& b) { return a.name < b.name; });
  return plan;
}

std::string StepPlan::describe() const {
  std::ostringstream out;
  auto names = [](const std::vector<FieldRef>& list, FieldLocation where) {
    std::vector<std::string> n;
    for (const auto& f : list)
      if (f.location == where) n.push_back(f.name + (f.components > 1 ? "[" + std::to_string(f.components) + "]" : ""));
    return join(n);
  };
  auto fields = [&](const char* verb, const std::vector<FieldRef>& list) {
    for (FieldLocation where : {FieldLocation::Particle, FieldLocation::Node}) {
      const std::string n = names(list, where);
      if (!n.empty())
        out << "      " << verb << (where == FieldLocation::Node ? " node:     " : " particle: ") << n << "\n";
    }
  };
  out << "step: " << stages_.size() << " stages in " << kPhaseCount
      << " phases (a phase without stages is skipped)\n";
  for (int p = 0; p < kPhaseCount; ++p) {
    const Phase phase = static_cast<Phase>(p);
    out << "  " << p + 1 << ". " << phase_name(phase);
    bool any = false;
    for (const auto& s : stages_)
      if (s.phase == phase) {
        if (!any) out << "\n";
        any = true;
        out << "    " << s.name << "\n";
        fields("reads ", s.reads);
        fields("writes", s.writes);
      }
    if (!any) out << ": skipped (no stage)\n";
  }
  std::vector<std::string> nodal;
  for (const auto& f : node_fields_)
    nodal.push_back(f.name + (f.components > 1 ? "[" + std::to_string(f.components) + "]" : "") +
                    (f.carried ? " (carried)" : ""));
  out << "nodal fields allocated: " << (nodal.empty() ? std::string("none") : join(nodal)) << "\n";
  return out.str();
}

}  // namespace frostmpm
