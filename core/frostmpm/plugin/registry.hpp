#pragma once
// One registry per interface kind ("sfcc", "relative_permeability", ...), names unique within
// a kind. Objects made from a plugin keep its library loaded for as long as they live.
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "frostmpm/config/param_schema.hpp"

namespace frostmpm {

/// One registered object: what `frostmpm plugins` and `describe` print, and how to build it.
struct RegistryEntry {
  // Declared first so it is destroyed last: the members below may hold code from the library.
  std::shared_ptr<void> library_handle;  ///< keeps the shared library mapped
  std::string kind;
  std::string name;
  std::string doc;
  std::string library;  ///< file it came from ("built-in" for the core)
  std::string plugin;   ///< plugin name from the info record
  std::string version;
  ParamSchema schema;
  std::function<std::shared_ptr<void>(const ParamSet&)> create;
};

class Registry {
 public:
  /// Adds an entry; a second entry with the same kind and name is an InputError naming both.
  void add(RegistryEntry entry);
  /// Drops every entry that came from `library` (a plugin refused half-way through registering).
  void remove_library(const std::string& library);
  /// Records a plugin folder the loader searched, for the unknown-name message.
  void note_searched(const std::string& folder);
  const std::vector<std::string>& searched() const { return searched_; }

  const RegistryEntry* find(const std::string& kind, const std::string& name) const;
  /// Like find, but an unknown name is an InputError at `where` listing the registered names
  /// and the plugin folders searched.
  const RegistryEntry& get(const std::string& kind, const std::string& name,
                           const SourceLocation& where) const;
  std::vector<std::string> kinds() const;
  std::vector<std::string> names(const std::string& kind) const;
  std::vector<const RegistryEntry*> entries(const std::string& kind) const;

  /// Builds an object of `kind`/`name` from validated parameters. The returned pointer also
  /// owns a reference to the library the object's code lives in.
  template <class Interface>
  std::shared_ptr<Interface> create(const std::string& name, const ParamSet& params,
                                    const SourceLocation& where = {}) const {
    const RegistryEntry& entry = get(Interface::kKind, name, where);
    std::shared_ptr<void> object = entry.create(params);
    auto typed = std::static_pointer_cast<Interface>(object);
    auto keep = entry.library_handle;
    return std::shared_ptr<Interface>(typed.get(), [typed, keep](Interface*) mutable {
      typed.reset();  // destroy the object before the library handle goes
      keep.reset();
    });
  }

 private:
  std::map<std::string, std::map<std::string, RegistryEntry>> kinds_;
  std::vector<std::string> searched_;
};

/// Handed to a plugin's register entry point; stamps entries with the library they came from.
class Registrar {
 public:
  Registrar(Registry& registry, std::string library, std::string plugin, std::string version,
            std::shared_ptr<void> handle)
      : registry_(registry), library_(std::move(library)), plugin_(std::move(plugin)),
        version_(std::move(version)), handle_(std::move(handle)) {}

  /// Class must provide: static constexpr const char* kName, kDoc; static ParamSchema schema();
  /// and a constructor from const ParamSet&.
  template <class Interface, class Class>
  void add() {
    RegistryEntry entry;
    entry.kind = Interface::kKind;
    entry.name = Class::kName;
    entry.doc = Class::kDoc;
    entry.schema = Class::schema();
    entry.create = [](const ParamSet& p) -> std::shared_ptr<void> {
      return std::static_pointer_cast<void>(
          std::static_pointer_cast<Interface>(std::make_shared<Class>(p)));
    };
    add_entry(std::move(entry));
  }

  /// An entry that only describes (no factory): a boundary-condition type a physics owns, listed
  /// by `describe` and the config reference under `kind`.
  void add_description(std::string kind, std::string name, std::string doc, ParamSchema schema) {
    RegistryEntry entry;
    entry.kind = std::move(kind);
    entry.name = std::move(name);
    entry.doc = std::move(doc);
    entry.schema = std::move(schema);
    entry.create = [name = entry.kind + "/" + entry.name](const ParamSet&) -> std::shared_ptr<void> {
      throw std::logic_error(name + " is a description, not a model");
    };
    add_entry(std::move(entry));
  }

  /// Stamps and adds an entry; a schema whose default lies outside its own range is an
  /// InputError naming the model, the parameter, the default and the range.
  void add_entry(RegistryEntry entry);

 private:
  Registry& registry_;
  std::string library_, plugin_, version_;
  std::shared_ptr<void> handle_;
};

}  // namespace frostmpm
