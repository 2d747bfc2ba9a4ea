#include "frostmpm/scene/model_section.hpp"

namespace frostmpm {

YAML::Node ModelSection::resolved() const {
  YAML::Node node(YAML::NodeType::Map);
  node["model"] = entry->name;
  for (const auto& kv : params.to_yaml()) node[kv.first] = kv.second;
  return node;
}

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
  section.params = parse_params(section.entry->schema, node, {"model"});
  section.where = node.where();
  return section;
}

}  // namespace frostmpm
