#pragma once
// Finds and loads plugin libraries from a search path: the built-in plugin folder,
// $FROSTMPM_PLUGIN_PATH (colon-separated), and the scene's plugin_paths. A library that is
// missing, not a shared library, has unresolved symbols, is not a FrostMPM plugin, was built
// against other kernel headers, or registers something invalid is refused with a one-line
// reason; the rest still load. Libraries are never unloaded while anything made from them lives.
#include <string>
#include <vector>

#include "frostmpm/plugin/registry.hpp"

namespace frostmpm {

struct LoadedPlugin {
  std::string file;
  std::string name;
  std::string version;
};

struct RefusedPlugin {
  std::string file;
  std::string reason;
};

class PluginLoader {
 public:
  explicit PluginLoader(Registry& registry) : registry_(registry) {}

  /// Loads every plugin library in `directory` (non-recursive), in name order. A missing
  /// directory is an InputError if `must_exist`, else a warning (see warnings()).
  void load_directory(const std::string& directory, bool must_exist = false);
  /// Loads one library; returns false and records the reason if it is refused.
  bool load_file(const std::string& file);

  const std::vector<LoadedPlugin>& loaded() const { return loaded_; }
  const std::vector<RefusedPlugin>& refused() const { return refused_; }
  /// Problems that refused no library, e.g. a plugin folder that does not exist.
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// The built-in folder (next to the executable's lib dir) plus $FROSTMPM_PLUGIN_PATH.
  static std::vector<std::string> default_search_path();

 private:
  bool refuse(const std::string& file, std::string reason);

  Registry& registry_;
  std::vector<LoadedPlugin> loaded_;
  std::vector<RefusedPlugin> refused_;
  std::vector<std::string> warnings_;
  std::vector<std::string> seen_;  ///< canonical paths already loaded
};

}  // namespace frostmpm
