// Quantities with units: "90 d", "5 cm", "-2 degC" converted to the declared unit by UDUNITS-2,
// the refusals (another dimension, an unknown unit, a Celsius value where a difference is
// declared), the way a scene node reads them, and that every declared unit is one UDUNITS-2 reads.
#include <catch2/catch.hpp>

#include <string>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/config/param_schema.hpp"
#include "frostmpm/config/units.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "test_support.hpp"

using namespace frostmpm;

namespace {

double in(const std::string& text, const std::string& declared) {
  const auto quantity = units::split(text);
  REQUIRE(quantity);
  return units::convert(*quantity, declared);
}

std::string refusal(const std::string& text, const std::string& declared) {
  try {
    in(text, declared);
  } catch (const units::UnitError& e) {
    return e.what();
  }
  FAIL("'" << text << "' in " << declared << " was accepted");
  return {};
}

/// The error of reading `value` (YAML text) as a number in `unit` from a one-key scene.
std::string read_error(const std::string& value, const std::string& unit) {
  const ConfigNode root = ConfigNode::load_string("time:\n  end: " + value + "\n", "scene.yaml");
  try {
    root.child("time").child("end").as_real(unit);
  } catch (const InputError& e) {
    return e.what();
  }
  FAIL("'" << value << "' in " << unit << " was accepted");
  return {};
}

}  // namespace

TEST_CASE("a number with a unit splits into value and unit, anything else does not", "[units]") {
  const auto q = units::split(" 2.1 W/(m K) ");
  REQUIRE(q);
  CHECK(q->value == 2.1);
  CHECK(q->unit == "W/(m K)");
  CHECK(q->text == "2.1 W/(m K)");
  CHECK(units::split("5cm")->unit == "cm");
  CHECK(units::split("-2 degC")->value == -2.0);
  CHECK(units::split("+3e2 s")->value == 300.0);
  CHECK(units::split("0.5 1/K")->unit == "1/K");
  CHECK_FALSE(units::split("12"));
  CHECK_FALSE(units::split("abc"));
  CHECK_FALSE(units::split(""));
  CHECK_FALSE(units::split("kPa 20"));
}

TEST_CASE("units convert to the declared unit, exactly where the factor allows", "[units]") {
  CHECK(in("3 km", "m") == 3000.0);
  CHECK(in("90 d", "s") == 7776000.0);
  CHECK(in("1.5 h", "s") == 5400.0);
  CHECK(in("20 kPa", "Pa") == 20000.0);
  CHECK(in("2.1 W/(m K)", "W/m/K") == 2.1);
  CHECK(in("2.1 W/(m degC)", "W/m/K") == 2.1);  // no offset inside a product: a ratio per kelvin
  CHECK(in("1800 kg/m3", "kg/m^3") == 1800.0);
  CHECK(in("30 deg", "degree") == 30.0);
  CHECK(in("30 °", "degree") == 30.0);
  // A scale of 1/n divides by n: the same double as the number typed in the declared unit.
  CHECK(in("5 cm", "m") == 0.05);
  CHECK(in("7 mm", "m") == 0.007);
  CHECK(in("35 %", "-") == 0.35);
  CHECK(in("0.1 ms", "s") == 1e-4);
  CHECK(in("2 MPa", "kPa") == 2000.0);
  CHECK(in("2.65 g/cm^3", "kg/m^3") == 2650.0);  // UDUNITS-2 alone: 2649.9999999999995
}

TEST_CASE("absolute temperatures convert with the offset between scales", "[units]") {
  CHECK(in("271.15 K", "degC") == Approx(-2.0).margin(1e-12));
  CHECK(in("-2 degC", "degC") == -2.0);
  CHECK(in("32 degF", "degC") == Approx(0.0).margin(1e-12));
}

TEST_CASE("a Celsius or Fahrenheit value where a temperature difference is declared is refused", "[units]") {
  // UDUNITS-2 alone would turn a difference of 5 degC into 278.15 K.
  const std::string message = refusal("5 degC", "K");
  CHECK_THAT(message, Catch::Contains("'5 degC' is a temperature on a scale with an offset (degC)"));
  CHECK_THAT(message, Catch::Contains("a temperature difference in K"));
  CHECK_THAT(message, Catch::Contains("give it in K"));
  CHECK_THAT(refusal("9 degF", "K"), Catch::Contains("offset (degF)"));
  CHECK(in("5 K", "K") == 5.0);
  CHECK(in("5 mK", "K") == 0.005);
  CHECK(in("0.5 1/degC", "1/K") == 0.5);
}

TEST_CASE("a value of another dimension or in an unknown unit is refused, saying what was expected", "[units]") {
  CHECK(refusal("20 kPa", "s") == "'20 kPa' is not a time: its unit kPa is not convertible to s");
  CHECK(refusal("20 kPa/s", "Pa") == "'20 kPa/s' is not a pressure: its unit kPa/s is not convertible to Pa");
  CHECK_THAT(refusal("5 m", "-"), Catch::StartsWith("'5 m' is not a pure number: its unit m is not convertible to 1"));
  CHECK_THAT(refusal("5 m", "degC"), Catch::StartsWith("'5 m' is not a temperature:"));
  CHECK_THAT(refusal("5 m", "K"), Catch::StartsWith("'5 m' is not a temperature difference:"));
  CHECK_THAT(refusal("3 furlongz", "m"), Catch::StartsWith("'3 furlongz': unknown unit 'furlongz'"));
  CHECK_THAT(refusal("3 m", ""), Catch::Contains("takes a bare number"));
}

TEST_CASE("a scene node converts a value with a unit and writes the number back into the tree", "[units][config]") {
  const ConfigNode root =
      ConfigNode::load_string("time:\n  end: \"90 d\"\ngrid:\n  cell_size: [5 cm, 0.1]\n", "scene.yaml");
  CHECK(root.child("time").child("end").as_real("s") == 7776000.0);
  // The tree now holds the number, unquoted: the resolved scene (check, run.json) shows seconds.
  const YAML::Node end = root.raw()["time"]["end"];
  CHECK(end.Scalar() == "7776000");
  CHECK(end.Tag() == "?");
  CHECK(root.child("grid").child("cell_size").as_reals("m") == std::vector<double>{0.05, 0.1});
  CHECK(root.raw()["grid"]["cell_size"][0].as<double>() == 0.05);
  // A bare number is taken as it is, in the declared unit.
  CHECK(ConfigNode::load_string("a: 12\n").child("a").as_real("d") == 12.0);
}

TEST_CASE("a refused value names file, line, column and YAML path", "[units][config]") {
  CHECK(read_error("20 kPa", "s") ==
        "scene.yaml:2:8: at 'time.end': '20 kPa' is not a time: its unit kPa is not convertible to s");
  CHECK_THAT(read_error("3 furlongz", "s"), Catch::StartsWith("scene.yaml:2:8: at 'time.end': '3 furlongz': unknown unit"));
  CHECK_THAT(read_error("abc", "s"), Catch::EndsWith("expected a number (in s, or with its unit), got 'abc'"));
  CHECK_THAT(read_error("1e999 s", "s"), Catch::Contains("got '1e999 s'"));
  const ConfigNode root = ConfigNode::load_string("n: 2 m\n", "scene.yaml");
  try {
    root.child("n").as_integer();
    FAIL("a count with a unit was accepted");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::EndsWith("expected an integer, got '2 m' (a count takes no unit)"));
  }
}

TEST_CASE("a table row reads each column in its own unit", "[units][config]") {
  const ConfigNode root = ConfigNode::load_string("row: [30 d, -2 degC]\nshort: [1]\n", "scene.yaml");
  CHECK(root.child("row").as_row({"s", "degC"}, "a row [time, value]") == std::vector<double>{2592000.0, -2.0});
  CHECK_THROWS_WITH(root.child("short").as_row({"s", "degC"}, "a row [time, value]"),
                    Catch::EndsWith("expected a row [time, value]"));
}

TEST_CASE("every unit a schema declares is a UDUNITS-2 unit, '-' or ''", "[units]") {
  std::vector<std::pair<std::string, const ParamSchema*>> schemas;
  const auto kernel = Simulation::section_schemas();
  for (const auto& [section, schema] : kernel) schemas.push_back({"kernel section " + section, &schema});
  const Registry& registry = test::builtin_registry();
  // A physics declares its material keys once it exists: make each with its defaults.
  std::vector<ParamSchema> material_schemas;
  for (const auto* entry : registry.entries(Physics::kKind)) {
    const ParamSet defaults = parse_params(entry->schema, ConfigNode(YAML::Node(YAML::NodeType::Map), "<defaults>"));
    material_schemas.push_back(registry.create<Physics>(entry->name, defaults, {})->material_schema());
  }
  for (std::size_t i = 0; i < material_schemas.size(); ++i)
    schemas.push_back({"materials of physics " + registry.entries(Physics::kKind)[i]->name, &material_schemas[i]});
  for (const auto& kind : registry.kinds())
    for (const auto* entry : registry.entries(kind)) schemas.push_back({kind + "/" + entry->name, &entry->schema});
  REQUIRE(schemas.size() > 20);
  for (const auto& [owner, schema] : schemas)
    for (const auto& spec : schema->params()) {
      INFO(owner << " parameter " << spec.name << " [" << spec.unit << "]");
      CHECK(units::is_declarable(spec.unit));
      // A number without a declared unit would refuse every unit: reals say "-" when pure.
      if (spec.type == ParamType::Real || spec.type == ParamType::RealList) CHECK_FALSE(spec.unit.empty());
    }
}

TEST_CASE("durations read in the unit that fits", "[units]") {
  CHECK(units::readable_duration(45) == "45 s");
  CHECK(units::readable_duration(150) == "2.5 min");
  CHECK(units::readable_duration(5400) == "1.5 h");
  CHECK(units::readable_duration(7776000) == "90 d");
  CHECK(units::readable_duration(in("2 yr", "s")) == "2 yr");
  CHECK(units::readable_duration(0.0125) == "0.0125 s");
}
