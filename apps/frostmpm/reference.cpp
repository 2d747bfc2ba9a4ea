#include "reference.hpp"

#include <algorithm>
#include <array>
#include <iomanip>
#include <iostream>

#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/scene/plugin_setup.hpp"
#include "frostmpm/simulation/simulation.hpp"

namespace frostmpm::app {
namespace {

struct LoadedRegistry {
  Registry registry;
  PluginLoader loader{registry};
  explicit LoadedRegistry(const std::vector<std::string>& extra_paths) {
    PluginSetup{extra_paths}.load_defaults(loader);
  }
};

// Models are chosen with `model:` inside a section; physics are keys of `physics:`.
std::string scene_form(const RegistryEntry& e) {
  if (e.kind == "physics") return "physics: {" + e.name + ": {...}}";
  if (e.kind == BoundaryType::kKind)
    return "boundary_conditions: [{type: " + e.name + ", nodes: ... or particles: ..." +
           (e.schema.params().empty() ? "" : ", ...") + "}]";
  return "{model: " + e.name + (e.schema.params().empty() ? "}" : ", ...}");
}

/// One row per parameter: name, type, unit, default, allowed range, doc; the columns as wide
/// as their widest entry (UTF-8 aware: units like °C), two spaces apart.
void parameter_table(const ParamSchema& schema, std::ostream& out) {
  std::vector<std::array<std::string, 6>> rows;
  for (const auto& p : schema.params())
    rows.push_back({p.name, to_string(p.type), p.unit.empty() ? "-" : p.unit, p.default_text(),
                    p.type == ParamType::Choice ? "one of: " + join(p.choices) : p.range_text(), p.doc});
  const auto width = [](const std::string& s) {
    return static_cast<std::size_t>(std::count_if(s.begin(), s.end(), [](char c) { return (c & 0xC0) != 0x80; }));
  };
  std::array<std::size_t, 5> widths{};
  for (const auto& row : rows)
    for (std::size_t c = 0; c < widths.size(); ++c) widths[c] = std::max(widths[c], width(row[c]));
  for (const auto& row : rows) {
    out << " ";
    for (std::size_t c = 0; c < widths.size(); ++c) out << " " << row[c] << std::string(widths[c] - width(row[c]) + 1, ' ');
    out << " " << row[5] << "\n";
  }
}

void describe_text(const RegistryEntry& e, std::ostream& out) {
  out << e.kind << "/" << e.name << " — " << e.doc << "\n";
  out << "  from " << e.plugin << " " << e.version << " (" << e.library << ")\n";
  out << "  YAML: " << scene_form(e) << "\n";
  if (e.schema.params().empty()) out << "  (no keys of its own)\n";
  parameter_table(e.schema, out);
}

void describe_markdown(const RegistryEntry& e, std::ostream& out) {
  out << "### `" << e.kind << "/" << e.name << "`\n\n" << e.doc << ".\n\n";
  out << "Plugin `" << e.plugin << "`. Scene form: `" << scene_form(e) << "`.\n\n";
  if (e.schema.params().empty()) {
    out << "No keys of its own.\n\n";
    return;
  }
  out << "| parameter | type | unit | default | allowed | description |\n|---|---|---|---|---|---|\n";
  for (const auto& p : e.schema.params()) {
    const std::string range = p.type == ParamType::Choice ? join(p.choices) : p.range_text();
    out << "| `" << p.name << "` | " << to_string(p.type) << " | " << (p.unit.empty() ? "-" : p.unit)
        << " | " << p.default_text() << " | " << (range.empty() ? "any" : range) << " | " << p.doc << " |\n";
  }
  out << "\n";
}

std::vector<std::string> described_sections() {
  std::vector<std::string> names;
  for (const auto& [name, schema] : Simulation::section_schemas()) names.push_back(name);
  return names;
}

}  // namespace

int cmd_plugins(const std::vector<std::string>& extra_paths, std::ostream& out) {
  LoadedRegistry loaded(extra_paths);
  for (const auto& kind : loaded.registry.kinds()) {
    out << kind << ":\n";
    for (const auto* e : loaded.registry.entries(kind))
      out << "  " << std::left << std::setw(24) << e->name << std::setw(10) << e->version << e->library << "\n";
  }
  for (const auto& r : loaded.loader.refused()) out << "refused: " << r.file << ": " << r.reason << "\n";
  for (const auto& w : loaded.loader.warnings()) out << "warning: " << w << "\n";
  return 0;
}

int cmd_describe(const std::string& target, bool markdown, const std::vector<std::string>& extra_paths,
                 std::ostream& out) {
  LoadedRegistry loaded(extra_paths);
  const Registry& registry = loaded.registry;
  std::vector<const RegistryEntry*> selected;
  const auto slash = target.find('/');
  // A kind nobody registered is a typo or a scene section, not a missing plugin: say which.
  if (const std::string kind = target.substr(0, slash); target != "all" && registry.entries(kind).empty()) {
    const auto kinds = registry.kinds();
    // The kernel's own sections with a fixed set of keys are described like a model.
    for (const auto& [name, schema] : Simulation::section_schemas())
      if (target == name) {
        out << name << " — a scene section the kernel reads\n  YAML: " << name << ": {...}\n";
        parameter_table(schema, out);
        return 0;
      }
    const auto sections = Simulation::sections();  // `physics` is also a kind, found above
    if (std::find(sections.begin(), sections.end(), kind) != sections.end())
      throw InputError("describe: '" + kind + "' is a scene section whose keys depend on the physics and "
                       "models a scene names: docs/config-reference.md and docs/user-guide.md list them, and `frostmpm check SCENE` "
                       "prints a scene's with their defaults. Described here: " + join(described_sections()) +
                       "; plugin kinds: " + join(kinds));
    throw InputError("describe: unknown kind '" + kind + "'" + did_you_mean(kind, kinds) + " Kinds: " + join(kinds));
  }
  if (target == "all") {
    for (const auto& kind : registry.kinds())
      for (const auto* e : registry.entries(kind)) selected.push_back(e);
  } else if (slash == std::string::npos) {
    selected = registry.entries(target);
  } else {
    selected.push_back(&registry.get(target.substr(0, slash), target.substr(slash + 1), {"describe", "", 0, 0}));
  }
  std::string current_kind;
  for (const auto* e : selected) {
    if (markdown && e->kind != current_kind) {
      current_kind = e->kind;
      out << "## " << current_kind << "\n\n";
    }
    if (markdown) describe_markdown(*e, out);
    else describe_text(*e, out);
  }
  return 0;
}

}  // namespace frostmpm::app
