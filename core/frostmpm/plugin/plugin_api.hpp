#pragma once
// What a plugin library exports. Exactly two symbols, both checked by the loader:
//   frostmpm_plugin_info_v1  -> PluginInfo (name, version, kernel ABI tag)
//   frostmpm_plugin_register_v1(Registrar&) -> registers the library's objects
// A plugin writes FROSTMPM_PLUGIN("name", "version") once, and FROSTMPM_REGISTER(Interface,
// Class) beside each class it provides.
#include <functional>
#include <vector>

#include <boost/dll/alias.hpp>

#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/plugin/abi_tag.hpp"
#include "frostmpm/plugin/registry.hpp"

namespace frostmpm {

/// "frostmpm-abi-<hash>": a hash of the kernel headers a plugin compiles against (comments and
/// whitespace aside), generated at build time (cmake/FrostMPMAbiTag.cmake). A plugin built
/// against headers that differ in anything else carries another tag and is refused.
inline constexpr const char* kKernelAbiTag = FROSTMPM_ABI_TAG;

struct PluginInfo {
  const char* name;
  const char* version;
  const char* abi_tag;
};

namespace plugin_detail {
// Each plugin library has its own copy (plugins build with hidden visibility), so this list
// holds exactly the registrations written in that library.
inline std::vector<std::function<void(Registrar&)>>& local_registrations() {
  static std::vector<std::function<void(Registrar&)>> list;
  return list;
}
struct AutoRegister {
  explicit AutoRegister(std::function<void(Registrar&)> fn) {
    local_registrations().push_back(std::move(fn));
  }
};
}  // namespace plugin_detail

}  // namespace frostmpm

#define FROSTMPM_CONCAT_INNER(a, b) a##b
#define FROSTMPM_CONCAT(a, b) FROSTMPM_CONCAT_INNER(a, b)

/// Registers Class (implementing Interface) under Class::kName; one line beside the class.
#define FROSTMPM_REGISTER(Interface, Class)                                                     \
  static const ::frostmpm::plugin_detail::AutoRegister FROSTMPM_CONCAT(frostmpm_reg_, __LINE__)( \
      [](::frostmpm::Registrar& r) { r.add<Interface, Class>(); });

/// Registers the boundary-condition types Class describes (static std::vector<BoundaryType>
/// boundary_type_docs(), frostmpm/physics/boundary_type.hpp) for `describe` and the reference.
#define FROSTMPM_REGISTER_BOUNDARY_TYPES(Class)                                                 \
  static const ::frostmpm::plugin_detail::AutoRegister FROSTMPM_CONCAT(frostmpm_reg_, __LINE__)( \
      [](::frostmpm::Registrar& r) {                                                           \
        for (auto& t : Class::boundary_type_docs())                                            \
          r.add_description(::frostmpm::BoundaryType::kKind, t.name, t.doc, t.keys);           \
      });

/// The plugin's info record and its one versioned entry point.
#define FROSTMPM_PLUGIN(plugin_name, plugin_version)                                          \
  namespace frostmpm_plugin_entry {                                                          \
  const ::frostmpm::PluginInfo* info() {                                                     \
    static const ::frostmpm::PluginInfo record{plugin_name, plugin_version,                  \
                                               ::frostmpm::kKernelAbiTag};                   \
    return &record;                                                                          \
  }                                                                                          \
  void register_all(::frostmpm::Registrar& registrar) {                                      \
    for (auto& fn : ::frostmpm::plugin_detail::local_registrations()) fn(registrar);         \
  }                                                                                          \
  }                                                                                          \
  BOOST_DLL_ALIAS(frostmpm_plugin_entry::info, frostmpm_plugin_info_v1)                      \
  BOOST_DLL_ALIAS(frostmpm_plugin_entry::register_all, frostmpm_plugin_register_v1)
