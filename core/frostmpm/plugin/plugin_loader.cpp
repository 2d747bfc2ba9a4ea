#include "frostmpm/plugin/plugin_loader.hpp"

#include <dlfcn.h>
#include <cxxabi.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>

#include <boost/dll/runtime_symbol_info.hpp>

#include "frostmpm/plugin/plugin_api.hpp"

namespace fs = std::filesystem;

namespace frostmpm {

namespace {
bool looks_like_shared_library(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.size() > 3 && (name.ends_with(".so") || name.find(".so.") != std::string::npos);
}

/// "foo(int)" for a mangled C++ name, the name itself otherwise.
std::string demangled(const std::string& symbol) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> text(abi::__cxa_demangle(symbol.c_str(), nullptr, nullptr, &status),
                                              std::free);
  return status == 0 && text ? text.get() : symbol;
}

/// dlerror()'s text as one reason line: the file name it starts with dropped, the usual
/// causes said in words.
std::string load_failure_reason(const std::string& file, std::string error) {
  if (error.rfind(file + ": ", 0) == 0) error.erase(0, file.size() + 2);
  const std::string undefined = "undefined symbol: ";
  if (const auto at = error.find(undefined); at != std::string::npos) {
    const std::string symbol = error.substr(at + undefined.size());
    std::string reason = "unresolved symbol '" + demangled(symbol) + "'";
    if (demangled(symbol) != symbol) reason += " (" + symbol + ")";
    return reason + ": built against another FrostMPM, or with another C++ string ABI "
                    "(_GLIBCXX_USE_CXX11_ABI)? rebuild it against this SDK";
  }
  for (const char* not_elf : {"invalid ELF header", "file too short", "only ET_DYN and ET_EXEC", "wrong ELF class"})
    if (error.find(not_elf) != std::string::npos) return "not a shared library (" + error + ")";
  return "cannot be loaded: " + error;
}

/// The function a Boost.DLL alias (BOOST_DLL_ALIAS in plugin_api.hpp) points at, or null.
template <class Function>
Function* alias(void* library, const char* name) {
  const void* const* slot = static_cast<const void* const*>(dlsym(library, name));
  return slot ? reinterpret_cast<Function*>(const_cast<void*>(*slot)) : nullptr;
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
    const std::string what = fs::exists(directory, ec) ? "is not a folder" : "does not exist";
    if (must_exist) throw InputError("plugin path '" + directory + "' " + what);
    warnings_.push_back("plugin folder " + directory + " " + what + "; skipped");
    return;
  }
  registry_.note_searched(fs::weakly_canonical(directory, ec).string());
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory, ec))
    if (entry.is_regular_file() && looks_like_shared_library(entry.path())) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) load_file(f.string());
}

bool PluginLoader::refuse(const std::string& file, std::string reason) {
  refused_.push_back({file, std::move(reason)});
  return false;
}

bool PluginLoader::load_file(const std::string& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return refuse(file, "no such file");
  if (fs::is_directory(file, ec)) return refuse(file, "is a folder, not a library");
  const std::string canonical = fs::weakly_canonical(file, ec).string();
  if (std::find(seen_.begin(), seen_.end(), canonical) != seen_.end()) return true;

  // RTLD_NOW resolves every symbol here, so a library built against another FrostMPM or C++
  // library is refused with dlerror()'s name for the missing symbol; lazy binding would kill
  // the process at the first call instead ("symbol lookup error", exit 127).
  dlerror();
  void* raw = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!raw) {
    const char* error = dlerror();
    return refuse(file, load_failure_reason(canonical, error ? error : "unknown dlopen error"));
  }
  std::shared_ptr<void> library(raw, [](void* handle) { dlclose(handle); });

  const auto info_fn = alias<const PluginInfo*()>(raw, "frostmpm_plugin_info_v1");
  const auto register_fn = alias<void(Registrar&)>(raw, "frostmpm_plugin_register_v1");
  if (!info_fn || !register_fn)
    return refuse(file, "not a FrostMPM plugin (no frostmpm_plugin_info_v1 entry point)");
  const PluginInfo* info = info_fn();
  if (!info || !info->abi_tag || std::string(info->abi_tag) != kKernelAbiTag)
    return refuse(file, std::string("built for kernel ABI '") + (info && info->abi_tag ? info->abi_tag : "?") +
                            "', this FrostMPM is '" + kKernelAbiTag + "'; rebuild it against this SDK");

  // A registration that throws (a duplicate name, a schema whose default breaks its own
  // range) refuses the whole library: nothing it registered stays.
  Registrar registrar(registry_, canonical, info->name, info->version, library);
  try {
    register_fn(registrar);
  } catch (const std::exception& e) {
    registry_.remove_library(canonical);
    return refuse(file, e.what());
  }
  seen_.push_back(canonical);
  loaded_.push_back({canonical, info->name, info->version});
  return true;
}

}  // namespace frostmpm
