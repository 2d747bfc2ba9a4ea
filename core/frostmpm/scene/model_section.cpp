#include "frostmpm/scene/model_section.hpp"

namespace frostmpm {

YAML::Node ModelSection::resolved() const {
  YAML::Node node(YAML::NodeType::Map);
  node["model"] = entry->name;
  for (const auto& kv : params.to_yaml()) node[kv.first] = kv.second;
  return node;
}

namespace {
/// `--set material.sfcc.model=other` keeps the old model's parameters, which `other` does not
/// take: name them and the way to swap, rather than one "unknown key" at a time. Keys no model
/// of the kind knows are left to the usual unknown-key message (with its closest match).
void reject_other_models_parameters(const Registry& registry, const RegistryEntry& entry, const ConfigNode& node) {
  std::vector<std::string> foreign;
  for (const auto& key : node.keys()) {
    if (key == "model" || entry.schema.find(key)) continue;
    for (const auto* other : registry.entries(entry.kind))
      if (other->schema.find(key)) {
        foreign.push_back(key + " (of " + other->name + ")");
        break;
      }
  }
  if (foreign.empty()) return;
  throw node.error(entry.kind + " model '" + entry.name + "' does not take " + join(foreign) + "; it takes: " +
                   (entry.schema.params().empty() ? std::string("no parameters") : join(entry.schema.names())) +
                   ". To swap the model, replace the whole section: --set '" + node.path() + "={model: " + entry.name +
                   ", ...}'");
}
}  // namespace

ModelSection read_model_section(const Registry& registry, const std::string& kind, const ConfigNode& node) {
  if (!node.is_map())
    throw node.error("expected a model section {model: NAME, ...}; registered " + kind + " models: " +
                     join(registry.names(kind)));
  if (!node.has("model"))
    throw node.error("missing required key 'model'; registered " + kind + " models: " +
                     join(registry.names(kind)));
  const ConfigNode name_node = node.child("model");
  ModelSection section;
  section.entry = &registry.get(kind, name_node.as_string(), name_node.where());
  reject_other_models_parameters(registry, *section.entry, node);
  section.params = parse_params(section.entry->schema, node, {"model"});
  section.where = node.where();
  return section;
}

}  // namespace frostmpm
