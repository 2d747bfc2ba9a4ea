#include "frostmpm/scene/plugin_setup.hpp"

#include <filesystem>

namespace fs = std::filesystem;

namespace frostmpm {

void PluginSetup::load_defaults(PluginLoader& loader) const {
  for (const auto& dir : PluginLoader::default_search_path()) loader.load_directory(dir);
  for (const auto& path : extra_paths) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      loader.load_directory(path);
    } else if (!loader.load_file(path)) {
      throw InputError("--plugin-path " + path + ": refused: " + loader.refused().back().reason);
    }
  }
}

void PluginSetup::load_scene_paths(PluginLoader& loader, const ConfigNode& scene_root) const {
  const auto paths = scene_root.optional_child("plugin_paths");
  if (!paths) return;
  const fs::path scene_dir = fs::path(scene_root.file()).parent_path();
  for (const auto& item : paths->elements()) {
    fs::path path = item.as_string();
    if (path.is_relative()) path = scene_dir / path;
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
      loader.load_directory(path.string());
    } else if (fs::exists(path, ec)) {
      if (!loader.load_file(path.string()))
        throw item.error("plugin " + path.string() + " refused: " + loader.refused().back().reason);
    } else {
      throw item.error("plugin path " + path.string() + " does not exist");
    }
  }
}

std::vector<std::string> refusal_warnings(const PluginLoader& loader) {
  std::vector<std::string> out = loader.warnings();
  for (const auto& r : loader.refused()) out.push_back(r.file + ": refused: " + r.reason);
  return out;
}

}  // namespace frostmpm
