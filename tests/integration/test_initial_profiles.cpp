// Initial fields that vary with position: a measured temperature profile as a table along a
// coordinate or by depth below the surface (a borehole log), and a hydrostatic pore pressure
// from a water table, read back from the first frame of fields.h5.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "frostmpm/io/hdf5_support.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

// A 2 m column, 0.1 m cells, 2 particles per cell per direction: particle centres at
// y = 0.025, 0.075, ..., 1.975.
constexpr const char* kScene = R"(task: simulation
grid: {cells: [1, 20], cell_size: 0.1, particles_per_cell: 2}
time: {end: 1, dt: 1}
gravity: [0, -9.81]
physics:
  thermal: {scheme: implicit}
  hydraulic: {}
materials:
  soil:
    porosity: 0.4
    solid_density: 2650
    solid_heat_capacity: 800
    solid_conductivity: 3.0
    water_density: 1000
    water_heat_capacity: 4182
    water_conductivity: 0.6
    ice_heat_capacity: 2100
    ice_conductivity: 2.2
    sfcc: {model: exponential, width: 0.5, residual_saturation: 0.05}
    absolute_permeability: {model: constant, k0: 1.0e-7}
regions:
  - shape: {box: {min: [0, 0], max: [0.1, 2.0]}}
    material: soil
    initial:
      temperature: {table: [[0.0, 2.0], [0.5, -1.0], [1.5, -3.0]], depth_below: 2.0}
      pore_pressure: {hydrostatic: {water_table: 1.2}}
output: {every: 1, progress: false, fields: [temperature, pore_pressure]}
)";

struct Frame {
  std::vector<double> y, temperature, pore_pressure;
};

Frame first_frame(const std::string& out) {
  namespace h5 = frostmpm::hdf5;
  const auto file = h5::open_file(out + "/fields.h5", false);
  const auto group = h5::open_group(file.get(), h5::child_names(file.get()).front());
  const std::size_t n = h5::dataset_shape(group.get(), "temperature").front();
  std::vector<double> xyz(3 * n);
  Frame f{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  h5::read_reals(group.get(), "coordinates", xyz);
  h5::read_reals(group.get(), "temperature", f.temperature);
  h5::read_reals(group.get(), "pore_pressure", f.pore_pressure);
  for (std::size_t p = 0; p < n; ++p) f.y[p] = xyz[3 * p + 1];
  return f;
}

/// The borehole log of the scene: depth d = 2 − y, linear between (0, 2), (0.5, −1), (1.5, −3)
/// and the end values beyond.
double logged_temperature(double y) {
  const double d = 2.0 - y;
  if (d <= 0.5) return 2.0 - 3.0 * d / 0.5;
  if (d <= 1.5) return -1.0 - 2.0 * (d - 0.5);
  return -3.0;
}

/// `frostmpm check SCENE --set SET` is refused with one line naming `path` and containing `text`.
void refused(const std::string& scene, const std::string& set, const std::string& path, const std::string& text) {
  const auto r = run_frostmpm("check " + scene + " --set '" + set + "'");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  CHECK(r.output.find(path) != std::string::npos);
  CHECK(r.output.find(text) != std::string::npos);
}

/// `frostmpm run SCENE -o OUT ARGS`, required to succeed.
void runs(const std::string& scene, const std::string& out, const std::string& args = "") {
  const auto r = run_frostmpm("run " + scene + " -o " + out + args);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
}

}  // namespace

TEST_CASE("initial fields from a depth table and from a water table", "[initial]") {
  TempDir dir;
  write_file(dir.file("column.yaml"), kScene);
  runs(dir.file("column.yaml"), dir.file("out"));
  const Frame f = first_frame(dir.file("out"));
  REQUIRE(f.y.size() == 80);
  for (std::size_t p = 0; p < f.y.size(); ++p) {
    INFO("y = " << f.y[p]);
    CHECK(f.temperature[p] == Approx(logged_temperature(f.y[p])).margin(1e-12));
    // p = ρ_l g (h − y), negative (suction) above the water table.
    CHECK(f.pore_pressure[p] == Approx(1000 * 9.81 * (1.2 - f.y[p])).margin(1e-9));
  }

  SECTION("the same profile given along y") {
    runs(dir.file("column.yaml"), dir.file("along"),
         " --set 'regions.0.initial.temperature={table: [[0.5, -3.0], [1.5, -1.0], [2.0, 2.0]], along: y}'");
    const Frame g = first_frame(dir.file("along"));
    for (std::size_t p = 0; p < g.y.size(); ++p) CHECK(g.temperature[p] == Approx(f.temperature[p]).margin(1e-12));
  }
}

TEST_CASE("bad initial tables and water tables are one line naming the key", "[initial][bad-input]") {
  TempDir dir;
  write_file(dir.file("column.yaml"), kScene);
  const auto refused = [&](const std::string& set, const std::string& path, const std::string& text) {
    ::refused(dir.file("column.yaml"), set, path, text);
  };
  const std::string t = "regions.0.initial.temperature=";
  refused(t + "{table: [[0, 1], [0, 2]], along: y}", "regions.0.initial.temperature.table", "increase strictly");
  refused(t + "{table: [[0, 1]], along: y}", "regions.0.initial.temperature.table", "at least 2 rows");
  refused(t + "{table: [[0, 1, 2], [1, 2]], along: y}", "regions.0.initial.temperature.table.0", "two finite numbers");
  refused(t + "{table: [[0, 1], [1, 2]]}", "regions.0.initial.temperature", "along: x|y, or depth_below");
  refused(t + "{table: [[0, 1], [1, 2]], along: w}", "regions.0.initial.temperature.along", "valid: x, y");
  refused(t + "{table: [[0, 1], [1, 1e9]], along: y}", "regions.0.initial.temperature.table", "plausible magnitude");
  refused(t + "{hydrostatic: {water_table: 1}}", "regions.0.initial.temperature.hydrostatic", "pore_pressure only");
  refused("regions.0.initial.pore_pressure={hydrostatic: {level: 1}}", "regions.0.initial.pore_pressure.hydrostatic",
          "water_table");
}

TEST_CASE("initial fields from another run's output: the same layout bit for bit, a finer one interpolated",
          "[initial]") {
  TempDir dir;
  write_file(dir.file("column.yaml"), kScene);
  // The spin-up: the column's profile, then one step of conduction (fields at t = 0 and 1).
  runs(dir.file("column.yaml"), dir.file("spin"));
  const Frame before = first_frame(dir.file("spin"));
  const std::string from = "regions.0.initial.temperature={from: " + dir.file("spin");

  SECTION("the same particles take the stored values exactly: the first frame and the last") {
    runs(dir.file("column.yaml"), dir.file("same"), " --set '" + from + ", frame: first}'");
    const Frame f = first_frame(dir.file("same"));
    REQUIRE(f.y == before.y);
    CHECK(f.temperature == before.temperature);
    // The last frame (the default) is the profile after a step of conduction: another field.
    runs(dir.file("column.yaml"), dir.file("last"), " --set '" + from + "}' --set time.end=0.5 --set time.dt=0.5");
    CHECK(first_frame(dir.file("last")).temperature != before.temperature);
  }
  SECTION("a finer layout gets the piecewise-linear log within what a linear fit of its kinks leaves") {
    runs(dir.file("column.yaml"), dir.file("fine"), " --set '" + from + ", frame: 0}' --set grid.particles_per_cell=3");
    const Frame f = first_frame(dir.file("fine"));
    REQUIRE(f.y.size() == 180);  // 3 × 3 per cell
    double worst = 0;
    for (std::size_t p = 0; p < f.y.size(); ++p)
      worst = std::max(worst, std::abs(f.temperature[p] - logged_temperature(f.y[p])));
    // The log's slope is at most 6 °C/m, the stored points 0.05 m apart: exact away from its
    // two kinks, and within slope × spacing / 2 next to them.
    CHECK(worst < 6.0 * 0.05 / 2);
    CHECK(worst > 0);  // the kinks do show
  }
  SECTION("a bad frame, a missing field, a missing run and ground the run did not cover: one line each") {
    const auto refused = [&](const std::string& set, const std::string& path, const std::string& text) {
      ::refused(dir.file("column.yaml"), set, path, text);
    };
    const std::string t = "regions.0.initial.temperature";
    refused(from + ", frame: 2}", t + ".frame", "not among the 2 frames");
    refused(from + ", frame: latest}", t + ".frame", "valid: last, first");
    refused(from + ", field: salinity}", t + ".field", "no field 'salinity'; it has: pore_pressure, temperature");
    refused(from + "/nowhere}", t + ".from", "there is no");
    refused(from + ", stride: 2}", t + ".stride", "stride");
    // A column twice as tall: its upper half is 1 m from the stored points.
    const auto r = run_frostmpm("check " + dir.file("column.yaml") + " --set '" + from +
                                "}' --set grid.cells=[1,40] --set 'regions.0.shape.box.max=[0.1,4.0]'");
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.find("does not cover the same ground") != std::string::npos);
  }
}
