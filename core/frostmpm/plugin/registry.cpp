#include "frostmpm/plugin/registry.hpp"

#include "frostmpm/physics/boundary_type.hpp"

#include <algorithm>

#include "frostmpm/config/units.hpp"

namespace frostmpm {

namespace {
/// " model '" — or " type '" for the boundary-condition types physics describe.
const char* noun(const std::string& kind) { return kind == BoundaryType::kKind ? " type '" : " model '"; }
}  // namespace

void Registry::add(RegistryEntry entry) {
  auto& by_name = kinds_[entry.kind];
  const auto it = by_name.find(entry.name);
  if (it != by_name.end())
    throw InputError("duplicate " + entry.kind + " name '" + entry.name + "': registered by " +
                     it->second.library + " and again by " + entry.library);
  by_name.emplace(entry.name, std::move(entry));
}

void Registry::remove_library(const std::string& library) {
  for (auto& [kind, by_name] : kinds_)
    std::erase_if(by_name, [&](const auto& item) { return item.second.library == library; });
}

void Registry::note_searched(const std::string& folder) {
  if (std::find(searched_.begin(), searched_.end(), folder) == searched_.end()) searched_.push_back(folder);
}

const RegistryEntry* Registry::find(const std::string& kind, const std::string& name) const {
  const auto k = kinds_.find(kind);
  if (k == kinds_.end()) return nullptr;
  const auto n = k->second.find(name);
  return n == k->second.end() ? nullptr : &n->second;
}

const RegistryEntry& Registry::get(const std::string& kind, const std::string& name,
                                   const SourceLocation& where) const {
  if (const RegistryEntry* e = find(kind, name)) return *e;
  const auto valid = names(kind);
  std::string message = "unknown " + kind + noun(kind) + name + "'" + did_you_mean(name, valid);
  message += " Registered: " + (valid.empty() ? std::string("(none; is the plugin path right?)") : join(valid));
  message += ". Plugin folders searched: " + (searched_.empty() ? std::string("(none)") : join(searched_));
  throw InputError(where, message);
}

std::vector<std::string> Registry::kinds() const {
  std::vector<std::string> out;
  for (const auto& [kind, _] : kinds_) out.push_back(kind);
  return out;
}

std::vector<std::string> Registry::names(const std::string& kind) const {
  std::vector<std::string> out;
  const auto k = kinds_.find(kind);
  if (k != kinds_.end())
    for (const auto& [name, _] : k->second) out.push_back(name);
  return out;
}

std::vector<const RegistryEntry*> Registry::entries(const std::string& kind) const {
  std::vector<const RegistryEntry*> out;
  const auto k = kinds_.find(kind);
  if (k != kinds_.end())
    for (const auto& [_, entry] : k->second) out.push_back(&entry);
  return out;
}

void Registrar::add_entry(RegistryEntry entry) {
  const std::string owner = entry.kind + noun(entry.kind) + entry.name + "'";
  entry.schema.check_defaults(owner);
  // A unit UDUNITS-2 cannot read would fail only once a scene gave that parameter a unit.
  for (const auto& spec : entry.schema.params())
    if (!units::is_declarable(spec.unit))
      throw InputError(owner + ": parameter '" + spec.name + "' declares the unit '" + spec.unit +
                       "', which UDUNITS-2 does not read; declare one it does (m, Pa, W/(m K), degC for an absolute "
                       "temperature, K for a difference) or '-' for a pure number");
  entry.library = library_;
  entry.plugin = plugin_;
  entry.version = version_;
  entry.library_handle = handle_;
  registry_.add(std::move(entry));
}

}  // namespace frostmpm
