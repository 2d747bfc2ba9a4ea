#pragma once
// A model section of a scene: `{model: NAME, <that model's parameters>}`. The name picks a
// registry entry of the section's kind; the rest is validated against that entry's schema.
#include <memory>
#include <string>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/plugin/registry.hpp"

namespace frostmpm {

struct ModelSection {
  const RegistryEntry* entry = nullptr;
  ParamSet params;
  SourceLocation where;

  /// {model: name, params...} with defaults filled in, for `check` and run.json.
  YAML::Node resolved() const;

  template <class Interface>
  std::shared_ptr<Interface> create(const Registry& registry) const {
    return registry.create<Interface>(entry->name, params, where);
  }
};

/// Reads and validates a model section of the given kind (`model:` is required).
ModelSection read_model_section(const Registry& registry, const std::string& kind, const ConfigNode& node);

}  // namespace frostmpm
