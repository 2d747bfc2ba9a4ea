// Registry, parameter schemas and strict scene parsing: every bad input is an InputError that
// names the file, the 1-based line, the YAML path, and (for typos) the closest valid name.
#include <catch2/catch.hpp>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/config/param_schema.hpp"
#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/plugin/registry.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "test_support.hpp"

using frostmpm::ConfigNode;
using frostmpm::InputError;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Message of the InputError thrown by `fn`; fails the test if none (or another type) is thrown.
template <class F>
std::string input_error_of(F&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  FAIL("expected an InputError");
  return {};
}

/// Reads the `material.sfcc` section of a scene text, as the scene reader does.
frostmpm::ModelSection read_sfcc(const std::string& scene_text) {
  const auto root = ConfigNode::load_string(scene_text, "scene.yaml");
  return frostmpm::read_model_section(frostmpm::test::builtin_registry(), "sfcc",
                                      root.child("material").child("sfcc"));
}

frostmpm::RegistryEntry fake_entry(const std::string& kind, const std::string& name, const std::string& library) {
  frostmpm::RegistryEntry entry;
  entry.kind = kind;
  entry.name = name;
  entry.library = library;
  entry.doc = "test entry";
  entry.create = [](const frostmpm::ParamSet&) -> std::shared_ptr<void> { return std::make_shared<int>(7); };
  return entry;
}

}  // namespace

// ---- strict parsing of model sections ----------------------------------------------------------

TEST_CASE("unknown key reports path, 1-based line and the closest key", "[config]") {
  const std::string scene =
      "time:\n"                          // line 1
      "  end: 1.0\n"                     // line 2
      "material:\n"                      // line 3
      "  sfcc:\n"                        // line 4
      "    model: exponential\n"         // line 5
      "    width: 0.5\n"                 // line 6
      "    residual_saturation: 0.05\n"  // line 7
      "    freezing_piont: -0.1\n";      // line 8
  const std::string message = input_error_of([&] { read_sfcc(scene); });
  INFO(message);
  CHECK(contains(message, "scene.yaml:8:"));
  CHECK(contains(message, "'material.sfcc.freezing_piont'"));
  CHECK(contains(message, "unknown key 'freezing_piont'"));
  CHECK(contains(message, "did you mean 'freezing_point'?"));
  // The valid keys are listed, including `model`.
  CHECK(contains(message, "width"));
  CHECK(contains(message, "model"));
}

TEST_CASE("a key with no close match gets no suggestion", "[config]") {
  const std::string message = input_error_of([] {
    read_sfcc("material:\n  sfcc: {model: exponential, width: 0.5, residual_saturation: 0.05, colour: blue}\n");
  });
  INFO(message);
  CHECK(contains(message, "unknown key 'colour'"));
  CHECK_FALSE(contains(message, "did you mean"));
  CHECK(contains(message, "scene.yaml:2:"));
}

TEST_CASE("missing required parameter is named with its section", "[config]") {
  const std::string scene =
      "material:\n"
      "  sfcc:\n"
      "    model: exponential\n"
      "    residual_saturation: 0.05\n";
  const std::string message = input_error_of([&] { read_sfcc(scene); });
  INFO(message);
  CHECK(contains(message, "missing required parameter 'width'"));
  CHECK(contains(message, "'material.sfcc'"));
  CHECK(contains(message, "scene.yaml:3:"));  // where the section's mapping starts
  CHECK(contains(message, "interval, K)"));   // the unit helps the user
}

TEST_CASE("wrong type for a real parameter", "[config]") {
  const std::string scene =
      "material:\n"
      "  sfcc:\n"
      "    model: exponential\n"
      "    width: abc\n"
      "    residual_saturation: 0.05\n";
  const std::string message = input_error_of([&] { read_sfcc(scene); });
  INFO(message);
  CHECK(contains(message, "expected a number (in K, or with its unit), got 'abc'"));
  CHECK(contains(message, "'material.sfcc.width'"));
  CHECK(contains(message, "scene.yaml:4:"));

  // A mapping where a number belongs, and a non-finite number.
  CHECK(contains(input_error_of([] {
                   read_sfcc("material:\n  sfcc: {model: exponential, width: {a: 1}, residual_saturation: 0.05}\n");
                 }),
                 "expected a number"));
  CHECK(contains(input_error_of([] {
                   read_sfcc("material:\n  sfcc: {model: exponential, width: .inf, residual_saturation: 0.05}\n");
                 }),
                 "finite"));
}

TEST_CASE("out-of-range parameters are rejected with the allowed range", "[config]") {
  const auto& registry = frostmpm::test::builtin_registry();
  // A porosity-like parameter with range (0, 1).
  const std::string scene =
      "material:\n"
      "  absolute_permeability:\n"
      "    model: kozeny_carman\n"
      "    k0: 1.0e-6\n"
      "    reference_porosity: 1.5\n";
  const std::string message = input_error_of([&] {
    const auto root = ConfigNode::load_string(scene, "scene.yaml");
    frostmpm::read_model_section(registry, "absolute_permeability",
                                 root.child("material").child("absolute_permeability"));
  });
  INFO(message);
  CHECK(contains(message, "value 1.5 is out of range; allowed (0, 1)"));
  CHECK(contains(message, "'material.absolute_permeability.reference_porosity'"));
  CHECK(contains(message, "scene.yaml:5:"));

  // Open bounds exclude their end points; closed bounds include them.
  const auto lambda_error = [](const std::string& value) {
    return input_error_of([&] { read_sfcc("material:\n  sfcc: {model: van_genuchten_cc, p0: 1e5, lambda: " + value + "}\n"); });
  };
  CHECK(contains(lambda_error("1.0"), "out of range"));
  CHECK(contains(lambda_error("0"), "out of range"));
  CHECK(contains(lambda_error("-0.5"), "out of range"));
  CHECK_NOTHROW(read_sfcc("material:\n  sfcc: {model: van_genuchten_cc, p0: 1e5, lambda: 0.999}\n"));
  CHECK_NOTHROW(read_sfcc("material:\n  sfcc: {model: exponential, width: 1, residual_saturation: 0}\n"));
  CHECK(contains(input_error_of([] {
                   read_sfcc("material:\n  sfcc: {model: exponential, width: 1, residual_saturation: 1}\n");
                 }),
                 "allowed [0, 1)"));
}

TEST_CASE("unknown model name lists the registered names", "[config]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto names = registry.names("sfcc");
  REQUIRE_FALSE(names.empty());

  const std::string typo = input_error_of([] {
    read_sfcc("material:\n  sfcc:\n    model: exponentail\n    width: 0.5\n");
  });
  INFO(typo);
  CHECK(contains(typo, "unknown sfcc model 'exponentail'"));
  CHECK(contains(typo, "did you mean 'exponential'?"));
  CHECK(contains(typo, "'material.sfcc.model'"));
  CHECK(contains(typo, "scene.yaml:3:"));
  for (const auto& name : names) CHECK(contains(typo, name));

  const std::string far = input_error_of([] { read_sfcc("material:\n  sfcc: {model: gibberish}\n"); });
  INFO(far);
  CHECK_FALSE(contains(far, "did you mean"));
  for (const auto& name : names) CHECK(contains(far, name));

  // `model:` missing altogether, and a section that is not a mapping.
  const std::string missing = input_error_of([] { read_sfcc("material:\n  sfcc: {width: 0.5}\n"); });
  CHECK(contains(missing, "missing required key 'model'"));
  for (const auto& name : names) CHECK(contains(missing, name));
  CHECK(contains(input_error_of([] { read_sfcc("material:\n  sfcc: exponential\n"); }), "expected a model section"));

  // A kind nobody registered says so.
  const std::string none = input_error_of([&] { registry.get("no_such_kind", "x", {}); });
  CHECK(contains(none, "(none; is the plugin path right?)"));
}

TEST_CASE("malformed YAML and non-mapping scenes are InputErrors with a line", "[config]") {
  const std::string bad = input_error_of([] { ConfigNode::load_string("a: [1, 2\nb: 3\n", "broken.yaml"); });
  INFO(bad);
  CHECK(contains(bad, "broken.yaml:"));
  CHECK(contains(bad, "malformed YAML"));
  CHECK(contains(input_error_of([] { ConfigNode::load_string("- 1\n- 2\n", "list.yaml"); }), "mapping"));
  CHECK(contains(input_error_of([] { ConfigNode::load_file("/nonexistent/scene.yaml"); }), "does not exist"));
}

TEST_CASE("cross-parameter errors from a model constructor point at the parameter", "[config]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto section = read_sfcc(
      "material:\n"
      "  sfcc:\n"
      "    model: linear\n"
      "    mushy_end: 1.0\n"
      "    residual_saturation: 0.05\n");
  const std::string message = input_error_of([&] { section.create<frostmpm::SfccModel>(registry); });
  INFO(message);
  CHECK(contains(message, "scene.yaml:4:"));
  CHECK(contains(message, "'material.sfcc.mushy_end'"));
}

// ---- registry ---------------------------------------------------------------------------------

TEST_CASE("built-in registry holds the SFCC and permeability models", "[config]") {
  const auto& registry = frostmpm::test::builtin_registry();
  const auto kinds = registry.kinds();
  for (const char* kind : {"sfcc", "relative_permeability", "absolute_permeability"})
    CHECK(std::find(kinds.begin(), kinds.end(), kind) != kinds.end());

  const std::vector<std::string> sfcc = registry.names("sfcc");
  for (const char* name : {"exponential", "linear", "power_law", "van_genuchten_cc"})
    CHECK(std::find(sfcc.begin(), sfcc.end(), name) != sfcc.end());
  CHECK(std::is_sorted(sfcc.begin(), sfcc.end()));
  const auto rel = registry.names("relative_permeability");
  CHECK(std::find(rel.begin(), rel.end(), "impedance") != rel.end());
  CHECK(std::find(rel.begin(), rel.end(), "van_genuchten_mualem") != rel.end());
  const auto abs = registry.names("absolute_permeability");
  for (const char* name : {"constant", "intrinsic", "kozeny_carman"})
    CHECK(std::find(abs.begin(), abs.end(), name) != abs.end());

  CHECK(registry.find("sfcc", "no_such_model") == nullptr);
  CHECK(registry.find("no_such_kind", "linear") == nullptr);
  CHECK(registry.names("no_such_kind").empty());

  const auto* entry = registry.find("sfcc", "van_genuchten_cc");
  REQUIRE(entry != nullptr);
  CHECK(entry->kind == "sfcc");
  CHECK(entry->plugin == "frostmpm-sfcc");
  CHECK_FALSE(entry->library.empty());
  CHECK_FALSE(entry->doc.empty());
  CHECK(entry->library_handle != nullptr);  // objects keep the plugin library mapped
}

TEST_CASE("every registered schema is documented and its defaults are in range", "[config]") {
  const auto& registry = frostmpm::test::builtin_registry();
  int params = 0;
  for (const auto& kind : registry.kinds()) {
    for (const auto* entry : registry.entries(kind)) {
      CHECK_FALSE(entry->doc.empty());
      for (const auto& spec : entry->schema.params()) {
        INFO(kind << "/" << entry->name << "." << spec.name);
        ++params;
        CHECK_FALSE(spec.doc.empty());
        if (spec.required()) {
          CHECK(spec.default_text() == "required");
          continue;
        }
        if (!spec.default_value) continue;  // optional with no default: its meaning is documented
        if (const double* v = std::get_if<double>(&*spec.default_value)) {
          CHECK(spec.type == frostmpm::ParamType::Real);
          if (spec.lower) CHECK((spec.lower_open ? *v > *spec.lower : *v >= *spec.lower));
          if (spec.upper) CHECK((spec.upper_open ? *v < *spec.upper : *v <= *spec.upper));
        }
      }
    }
  }
  CHECK(params > 10);
}

TEST_CASE("duplicate registration throws naming both libraries", "[config]") {
  frostmpm::Registry registry;
  registry.add(fake_entry("sfcc", "twin", "libfirst.so"));
  const std::string message = input_error_of([&] { registry.add(fake_entry("sfcc", "twin", "libsecond.so")); });
  INFO(message);
  CHECK(contains(message, "duplicate sfcc name 'twin'"));
  CHECK(contains(message, "libfirst.so"));
  CHECK(contains(message, "libsecond.so"));
  // The first registration survives; the same name under another kind is fine.
  REQUIRE(registry.find("sfcc", "twin") != nullptr);
  CHECK(registry.find("sfcc", "twin")->library == "libfirst.so");
  CHECK_NOTHROW(registry.add(fake_entry("relative_permeability", "twin", "libsecond.so")));
  CHECK(registry.names("sfcc") == std::vector<std::string>{"twin"});
}

TEST_CASE("Registrar stamps entries with their library", "[config]") {
  frostmpm::Registry registry;
  frostmpm::Registrar registrar(registry, "libdemo.so", "demo-plugin", "1.2.3", nullptr);
  registrar.add_entry(fake_entry("sfcc", "demo", "ignored"));
  const auto* entry = registry.find("sfcc", "demo");
  REQUIRE(entry != nullptr);
  CHECK(entry->library == "libdemo.so");
  CHECK(entry->plugin == "demo-plugin");
  CHECK(entry->version == "1.2.3");
  // A second plugin registering the same name is named in the error next to the first.
  frostmpm::Registrar other(registry, "libother.so", "other-plugin", "0.1", nullptr);
  const std::string message = input_error_of([&] { other.add_entry(fake_entry("sfcc", "demo", "")); });
  CHECK(contains(message, "libdemo.so"));
  CHECK(contains(message, "libother.so"));
}

TEST_CASE("a schema whose default lies outside its own range is refused at registration", "[config]") {
  frostmpm::Registry registry;
  frostmpm::Registrar registrar(registry, "libbad.so", "bad-plugin", "0.1", nullptr);
  auto entry = fake_entry("sfcc", "bad_default", "");
  entry.schema.real("residual_saturation", "-", "S_res").defaults_to(1).at_least(0).below(1);
  const std::string message = input_error_of([&] { registrar.add_entry(entry); });
  INFO(message);
  CHECK(message == "sfcc model 'bad_default': the default 1 of parameter 'residual_saturation' is outside its own range [0, 1)");
  CHECK(registry.find("sfcc", "bad_default") == nullptr);

  frostmpm::ParamSchema choices;
  choices.choice("solver", {"direct", "cg"}, "solver").defaults_to("gmres");
  CHECK(contains(input_error_of([&] { choices.check_defaults("physics 'x'"); }), "{direct, cg}"));
  frostmpm::ParamSchema list;
  list.reals("origin", "m", "a point").defaults_to(std::vector<double>{0.0, -1.0}).at_least(0);
  CHECK(contains(input_error_of([&] { list.check_defaults("physics 'x'"); }), "parameter 'origin'"));
  frostmpm::ParamSchema fine;
  fine.real("fraction", "-", "a fraction").defaults_to(0.25).at_least(0).at_most(1);
  CHECK_NOTHROW(fine.check_defaults("sfcc model 'fine'"));
}

TEST_CASE("a refused library's entries are removed, others stay", "[config]") {
  frostmpm::Registry registry;
  frostmpm::Registrar first(registry, "libfirst.so", "first", "1", nullptr);
  first.add_entry(fake_entry("sfcc", "kept", ""));
  frostmpm::Registrar second(registry, "libsecond.so", "second", "1", nullptr);
  second.add_entry(fake_entry("sfcc", "dropped", ""));
  second.add_entry(fake_entry("relative_permeability", "dropped_too", ""));
  registry.remove_library("libsecond.so");
  CHECK(registry.names("sfcc") == std::vector<std::string>{"kept"});
  CHECK(registry.names("relative_permeability").empty());
}

// ---- ParamSchema / ParamSet -------------------------------------------------------------------

namespace {
frostmpm::ParamSchema demo_schema() {
  frostmpm::ParamSchema s;
  s.real("length", "m", "a length").above(0);
  s.real("fraction", "-", "a fraction").defaults_to(0.25).at_least(0).at_most(1);
  s.integer("count", "how many").defaults_to(3L).at_least(1);
  s.boolean("verbose", "talk more").defaults_to(false);
  s.string("label", "a label").defaults_to("none");
  s.choice("solver", {"direct", "gmres", "cg"}, "linear solver").defaults_to("direct");
  s.reals("origin", "m", "a point").size(2).defaults_to(std::vector<double>{0.0, 0.0});
  return s;
}

frostmpm::ParamSet parse_demo(const std::string& body) {
  const auto root = ConfigNode::load_string("demo: {" + body + "}\n", "demo.yaml");
  return frostmpm::parse_params(demo_schema(), root.child("demo"));
}
}  // namespace

TEST_CASE("ParamSchema range and default texts", "[config]") {
  const auto schema = demo_schema();
  REQUIRE(schema.find("length") != nullptr);
  CHECK(schema.find("nope") == nullptr);
  CHECK(schema.find("length")->required());
  CHECK(schema.find("length")->range_text() == "(0, inf)");
  CHECK(schema.find("length")->default_text() == "required");
  CHECK(schema.find("fraction")->range_text() == "[0, 1]");
  CHECK(schema.find("fraction")->default_text() == "0.25");
  CHECK(schema.find("verbose")->range_text().empty());
  // A string-literal default stays a string (not the bool alternative of ParamValue).
  CHECK(std::holds_alternative<std::string>(*schema.find("label")->default_value));
  CHECK(schema.find("label")->default_text() == "none");
  CHECK(schema.names() == std::vector<std::string>{"length", "fraction", "count", "verbose", "label", "solver", "origin"});

  frostmpm::ParamSchema twice;
  twice.real("x", "m", "x");
  CHECK_THROWS_AS(twice.real("x", "m", "again"), std::logic_error);
}

TEST_CASE("parse_params reads every type and fills defaults", "[config]") {
  const auto set = parse_demo("length: 2.5, count: 7, verbose: true, solver: cg, origin: [1, -2]");
  CHECK(set.real("length") == 2.5);
  CHECK(set.real("fraction") == 0.25);
  CHECK(set.integer("count") == 7);
  CHECK(set.boolean("verbose"));
  CHECK(set.string("label") == "none");
  CHECK(set.string("solver") == "cg");
  CHECK(set.reals("origin") == std::vector<double>{1.0, -2.0});
  CHECK(set.has("fraction"));
  CHECK_FALSE(set.has("nope"));
  // Values remember where they came from; defaults point at the section.
  CHECK(set.where("length").path == "demo.length");
  CHECK(set.where("length").line == 1);
  CHECK(set.where("fraction").path == "demo");
  const std::string message = set.error("count", "too many").what();
  CHECK(contains(message, "demo.yaml:1:"));
  CHECK(contains(message, "'demo.count'"));
  CHECK(contains(message, "too many"));
}

TEST_CASE("parse_params rejects bad values of each type", "[config]") {
  CHECK(contains(input_error_of([] { parse_demo("length: 1, solver: gmress"); }), "did you mean 'gmres'?"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, solver: gmress"); }), "direct, gmres, cg"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, origin: [1, 2, 3]"); }),
                 "expected a list of 2 numbers, got 3"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, count: 2.5"); }), "expected an integer"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, count: 0"); }), "out of range"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, verbose: maybe"); }), "expected true or false"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, fraction: 1.01"); }), "allowed [0, 1]"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, origin: [1, x]"); }), "'demo.origin.1'"));
  CHECK(contains(input_error_of([] { parse_demo("fraction: 0.5"); }), "missing required parameter 'length' (a length, m)"));
  CHECK(contains(input_error_of([] { parse_demo("length: 1, lenght: 2"); }), "did you mean 'length'?"));
  // Not a mapping at all.
  const auto root = ConfigNode::load_string("demo: [1, 2]\n", "demo.yaml");
  CHECK(contains(input_error_of([&] { frostmpm::parse_params(demo_schema(), root.child("demo")); }),
                 "expected a mapping of parameters"));
}

TEST_CASE("ParamSet::to_yaml and ModelSection::resolved include defaults", "[config]") {
  const auto section = read_sfcc("material:\n  sfcc: {model: van_genuchten_cc, lambda: 0.5, p0: 1.0e5}\n");
  const YAML::Node params = section.params.to_yaml();
  REQUIRE(params.IsMap());
  CHECK(params["lambda"].as<double>() == 0.5);
  CHECK(params["p0"].as<double>() == 1.0e5);
  CHECK(params["ice_density"].as<double>() == 917.0);
  CHECK(params["water_density"].as<double>() == 1000.0);
  CHECK(params["latent_heat"].as<double>() == 3.34e5);
  CHECK(params["residual_saturation"].as<double>() == 0.0);
  // Schema order.
  std::vector<std::string> keys;
  for (const auto& kv : params) keys.push_back(kv.first.as<std::string>());
  CHECK(keys == std::vector<std::string>{"lambda", "p0", "ice_density", "water_density", "latent_heat",
                                         "residual_saturation"});
  const YAML::Node resolved = section.resolved();
  CHECK(resolved["model"].as<std::string>() == "van_genuchten_cc");
  CHECK(resolved["ice_density"].as<double>() == 917.0);

  // Every parameter type round-trips through YAML.
  const YAML::Node demo = parse_demo("length: 2").to_yaml();
  CHECK(demo["count"].as<long>() == 3);
  CHECK(demo["verbose"].as<bool>() == false);
  CHECK(demo["label"].as<std::string>() == "none");
  CHECK(demo["solver"].as<std::string>() == "direct");
  REQUIRE(demo["origin"].IsSequence());
  CHECK(demo["origin"].size() == 2);
}

// ---- command-line overrides -------------------------------------------------------------------

TEST_CASE("apply_override sets nested values and list entries", "[config]") {
  YAML::Node root = YAML::Load(
      "material:\n"
      "  sfcc: {model: exponential, width: 0.5, residual_saturation: 0.05}\n"
      "regions:\n"
      "  - {name: a, material: sand}\n"
      "  - {name: b, material: silt}\n"
      "output:\n"
      "  fields: [temperature, pressure]\n");

  frostmpm::apply_override(root, "material.sfcc.width=0.7");
  CHECK(root["material"]["sfcc"]["width"].as<double>() == 0.7);
  // A new leaf under an existing section is allowed (strict parsing checks it later).
  frostmpm::apply_override(root, "material.sfcc.freezing_point=-0.2");
  CHECK(root["material"]["sfcc"]["freezing_point"].as<double>() == -0.2);
  // List indices, in the middle and at the end of a path; values are parsed as YAML.
  frostmpm::apply_override(root, "regions.1.material=clay");
  CHECK(root["regions"][1]["material"].as<std::string>() == "clay");
  CHECK(root["regions"][0]["material"].as<std::string>() == "sand");
  frostmpm::apply_override(root, "output.fields.0=ice_saturation");
  CHECK(root["output"]["fields"][0].as<std::string>() == "ice_saturation");
  CHECK(root["output"]["fields"][1].as<std::string>() == "pressure");
  frostmpm::apply_override(root, "regions.0.box=[0, 1, 2]");
  REQUIRE(root["regions"][0]["box"].IsSequence());
  CHECK(root["regions"][0]["box"][2].as<int>() == 2);

  // The overridden tree still parses through the registry.
  const auto section = frostmpm::read_model_section(frostmpm::test::builtin_registry(), "sfcc",
                                                    ConfigNode(root, "--set").child("material").child("sfcc"));
  CHECK(section.params.real("width") == 0.7);
  CHECK(section.params.real("freezing_point") == -0.2);
}

TEST_CASE("apply_override rejects paths that do not exist", "[config]") {
  YAML::Node root = YAML::Load(
      "material:\n"
      "  sfcc: {model: exponential, width: 0.5}\n"
      "regions:\n"
      "  - {name: a}\n");
  const YAML::Node before = YAML::Clone(root);

  const std::string typo = input_error_of([&] { frostmpm::apply_override(root, "material.sfcx.width=1"); });
  INFO(typo);
  CHECK(contains(typo, "does not exist"));
  CHECK(contains(typo, "no key 'sfcx'"));
  CHECK(contains(typo, "did you mean 'sfcc'?"));

  const std::string top = input_error_of([&] { frostmpm::apply_override(root, "nosuch.key=1"); });
  CHECK(contains(top, "does not exist"));
  CHECK(contains(top, "<top>"));

  CHECK(contains(input_error_of([&] { frostmpm::apply_override(root, "regions.3.name=b"); }), "is not an index"));
  CHECK(contains(input_error_of([&] { frostmpm::apply_override(root, "regions.x.name=b"); }), "is not an index"));
  CHECK(contains(input_error_of([&] { frostmpm::apply_override(root, "regions.7=b"); }), "is not an index"));
  CHECK(contains(input_error_of([&] { frostmpm::apply_override(root, "material.sfcc.width.deeper=1"); }),
                 "is a value, not a section"));
  CHECK(contains(input_error_of([&] { frostmpm::apply_override(root, "material.sfcc.width"); }),
                 "expected path.to.key=value"));
  CHECK(contains(input_error_of([&] { frostmpm::apply_override(root, "=3"); }), "expected path.to.key=value"));

  // Failed overrides leave the tree untouched.
  CHECK(YAML::Dump(root) == YAML::Dump(before));

  // A typo in the leaf is caught later by strict parsing, with a suggestion.
  frostmpm::apply_override(root, "material.sfcc.widht=0.7");
  const std::string later = input_error_of([&] {
    frostmpm::read_model_section(frostmpm::test::builtin_registry(), "sfcc",
                                 ConfigNode(root, "--set").child("material").child("sfcc"));
  });
  CHECK(contains(later, "did you mean 'width'?"));
}

TEST_CASE("closest_match and join", "[config]") {
  const std::vector<std::string> keys = {"width", "residual_saturation", "freezing_point"};
  CHECK(frostmpm::closest_match("widht", keys) == "width");
  CHECK(frostmpm::closest_match("residual_saturaton", keys) == "residual_saturation");
  CHECK(frostmpm::closest_match("temperature", keys).empty());
  CHECK(frostmpm::closest_match("x", {}).empty());
  CHECK(frostmpm::join({"a", "b", "c"}) == "a, b, c");
  CHECK(frostmpm::join({}) == "");
}
