// Outputs carry their units: every fields.h5 dataset a `units` attribute (frames a restart
// appends too), run.json's `metrics_units` every metrics.csv column, each probe's unit derived
// from its field and type; the CSV keeps its one header line.
#include <catch2/catch.hpp>

#include <string>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

/// The frozen inclusion on 0.1 m cells (a TH scene with flow: fields temperature,
/// liquid_saturation, pore_pressure and water_flux), with a probe of every kind it can have.
std::string coarse_inclusion(const std::string& out) {
  return "run " + source_dir() + "/configs/paper/frozen_inclusion_case3.yaml -o " + out +
         " --set 'grid.cells=[30, 10]' --set grid.cell_size=0.1 --set time.end=6000 --set output.every=3000"
         " --set output.progress=false --set 'probes=["
         "{name: T_min, type: min, field: temperature},"
         "{name: q_y, type: value_at, field: water_flux.y, point: [1.5, 0.5]},"
         "{name: liquid_volume, type: integral, fields: [porosity, liquid_saturation]},"
         "{name: flux_volume, type: integral, fields: [water_flux.x]},"
         "{name: k_eq, type: integral, fields: [water_flux.x], scale: 0.5, unit: m/s},"
         "{name: front, type: isotherm, field: temperature, value: 0, from: [0, 0.5], to: [3, 0.5]},"
         "{name: thaw, type: thaw_depth, from: [1, 1], to: [1, 0]},"
         "{name: uplift, type: displacement, point: [1, 1], component: y},"
         "{name: settlement, type: settlement}]'";
}

std::size_t occurrences(const std::string& text, const std::string& part) {
  std::size_t count = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

/// Every dataset but the connectivity of every frame: "frame/dataset units", one line each.
std::string dataset_units(const std::string& out) {
  const auto r = run_command("/usr/bin/python3 -c \"import h5py\nfor frame in h5py.File('" + out +
                             "/fields.h5', 'r').values():\n for name, d in frame.items():\n  if name != "
                             "'connectivity': print(frame.name[1:] + '/' + name, d.attrs.get('units'))\"");
  REQUIRE(r.exit_code == 0);
  return r.output;
}

}  // namespace

TEST_CASE("fields.h5 datasets and metrics.csv columns carry their units, frames of a restart too", "[units]") {
  TempDir dir;
  const std::string out = dir.file("out");
  const auto run = run_frostmpm(coarse_inclusion(out));
  INFO(run.output);
  REQUIRE(run.exit_code == 0);

  const auto expect = [&](const std::string& column, const std::string& unit) {
    INFO(column);
    CHECK(run_json(out, "['metrics_units']['" + column + "']") == unit);
  };
  expect("time_s", "s");
  expect("step", "1");
  expect("dt_s", "s");
  expect("T_min", "degC");
  expect("q_y", "m/s");                     // a vector's component: the vector's unit
  expect("liquid_volume", "m^3/m");         // dimensionless fields times a volume per metre
  expect("flux_volume", "m/s m^3/m");       // the integrand's unit times the volume's
  expect("k_eq", "m/s");                    // a scale with a unit says so
  expect("front", "m");
  expect("thaw", "m");
  expect("uplift", "m");
  expect("settlement", "m");
  // One unit per column, and the CSV keeps its single header line.
  const CsvTable metrics = read_csv(out + "/metrics.csv");
  CHECK(metrics.header.front() == "time_s");
  CHECK(run_json(out, "['metrics_units'].keys().__len__()") == std::to_string(metrics.header.size()));

  // A restart appends frames: they carry units as the first ones do.
  const auto extended = run_frostmpm("run --restart " + out + " --set time.end=9000");
  INFO(extended.output);
  REQUIRE(extended.exit_code == 0);
  const std::string units = dataset_units(out);
  INFO(units);
  // Frames at t = 0, 3000, 6000 and, after the restart, 9000 s.
  for (const auto& [field, unit] : {std::pair{"coordinates", "m"}, {"temperature", "degC"},
                                    {"liquid_saturation", "1"}, {"pore_pressure", "Pa"}, {"water_flux", "m/s"}})
    CHECK(occurrences(units, std::string("/") + field + " " + unit + "\n") == 4);
  CHECK(units.find("None") == std::string::npos);
  CHECK(run_json(out, "['metrics_units']['k_eq']") == "m/s");
}

TEST_CASE("an integral probe's unit must be unit text", "[units]") {
  TempDir dir;
  const auto r = run_frostmpm("check " + source_dir() + "/configs/verification/periodic_conduction.yaml" +
                              " --set 'probes.3.unit=\"\"'");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("at 'probes.3.unit': a unit is UDUNITS-2 text") != std::string::npos);
}
