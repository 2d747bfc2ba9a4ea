#include "frostmpm/plugin/plugin_loader.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <boost/dll/import.hpp>
#include <boost/dll/runtime_symbol_info.hpp>
#include <boost/dll/shared_library.hpp>

#include "frostmpm/plugin/plugin_api.hpp"

namespace fs = std::filesystem;

namespace frostmpm {

namespace {
bool looks_like_shared_library(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.size() > 3 && (name.ends_with(".so") || name.find(".so.") != std::string::npos);
}
}  // namespace

std::vector<std::string> PluginLoader::default_search_path() {
  std::vector<std::string> dirs;
  // Built-in plugins sit at <prefix>/lib/frostmpm/plugins, with the binary in <prefix>/bin.
  // The core library's own location gives the same answer for any program that links it.
  const fs::path core_dir = boost::dll::this_line_location().parent_path().string();
  for (const fs::path candidate : {core_dir / "frostmpm" / "plugins",
                                   core_dir.parent_path() / "lib" / "frostmpm" / "plugins"}) {
    std::error_code ec;
    if (fs::is_directory(candidate, ec)) {
      dirs.push_back(fs::weakly_canonical(candidate).string());
      break;
    }
  }
  if (const char* env = std::getenv("FROSTMPM_PLUGIN_PATH")) {
    std::stringstream ss(env);
    for (std::string dir; std::getline(ss, dir, ':');)
      if (!dir.empty()) dirs.push_back(dir);
  }
  return dirs;
}

void PluginLoader::load_directory(const std::string& directory, bool must_exist) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) {
    if (must_exist) throw InputError("plugin path '" + directory + "' is not a directory");
    return;
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory, ec))
    if (entry.is_regular_file() && looks_like_shared_library(entry.path())) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) load_file(f.string());
}

bool PluginLoader::load_file(const std::string& file) {
  std::error_code ec;
  const std::string canonical = fs::weakly_canonical(file, ec).string();
  if (std::find(seen_.begin(), seen_.end(), canonical) != seen_.end()) return true;

  auto library = std::make_shared<boost::dll::shared_library>();
  boost::system::error_code load_error;
  library->load(file, boost::dll::load_mode::rtld_lazy | boost::dll::load_mode::rtld_local, load_error);
  if (load_error) {
    refused_.push_back({file, "cannot be loaded as a shared library: " + load_error.message()});
    return false;
  }
  if (!library->has("frostmpm_plugin_info_v1") || !library->has("frostmpm_plugin_register_v1")) {
    refused_.push_back({file, "not a FrostMPM plugin (no frostmpm_plugin_info_v1 entry point)"});
    return false;
  }
  const auto info_fn = library->get_alias<const PluginInfo*()>("frostmpm_plugin_info_v1");
  const PluginInfo* info = info_fn();
  if (!info || !info->abi_tag || std::string(info->abi_tag) != kKernelAbiTag) {
    refused_.push_back({file, std::string("built for kernel ABI '") +
                                  (info && info->abi_tag ? info->abi_tag : "?") +
                                  "', this FrostMPM is '" + kKernelAbiTag + "'; rebuild it against this SDK"});
    return false;
  }
  const auto register_fn = library->get_alias<void(Registrar&)>("frostmpm_plugin_register_v1");
  Registrar registrar(registry_, canonical, info->name, info->version, library);
  register_fn(registrar);
  seen_.push_back(canonical);
  loaded_.push_back({canonical, info->name, info->version});
  return true;
}

}  // namespace frostmpm
