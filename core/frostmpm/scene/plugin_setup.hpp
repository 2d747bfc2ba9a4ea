#pragma once
// Loads the plugins a scene can use: built-in folder, $FROSTMPM_PLUGIN_PATH, extra folders
// from the command line, and the scene's `plugin_paths` (relative to the scene file).
#include <string>
#include <vector>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/plugin/plugin_loader.hpp"

namespace frostmpm {

struct PluginSetup {
  std::vector<std::string> extra_paths;  ///< from --plugin-path
  /// Loads defaults and extra paths; refused libraries found by a folder scan become warnings.
  void load_defaults(PluginLoader& loader) const;
  /// Loads `plugin_paths` from the scene root (consumes the key). A path naming a file that
  /// is refused is an InputError; refused files inside a named folder are warnings.
  void load_scene_paths(PluginLoader& loader, const ConfigNode& scene_root) const;
};

/// One-line warnings: plugin folders that do not exist, then every refused library (file: reason).
std::vector<std::string> refusal_warnings(const PluginLoader& loader);

}  // namespace frostmpm
