// scripts/plot.py draws every figure of a run folder: the metrics time series, the particle
// fields of one frame, the profiles and time-depth contour along a vertical line, and the
// freezing-curve tables; on a one-cell column, a TH scene with flow and a restarted run.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace frostmpm::test;

namespace {

/// False (with a warning: the test is skipped) when /usr/bin/python3 cannot plot.
bool have_matplotlib() {
  if (run_command("/usr/bin/python3 -c 'import matplotlib, numpy, h5py'").exit_code == 0) return true;
  WARN("skipped: /usr/bin/python3 lacks matplotlib, numpy or h5py");
  return false;
}

/// Checks `path` is a PNG file (signature) of non-trivial size.
void require_png(const std::string& path) {
  INFO(path);
  REQUIRE(fs::exists(path));
  const std::string png = read_file(path);
  REQUIRE(png.size() > 10000);
  REQUIRE(png.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
}

/// `plot.py ARGS`, required to succeed without a Python traceback.
CommandResult plot(const std::string& args) {
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/scripts/plot.py " + args);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(r.output.find("Traceback") == std::string::npos);
  return r;
}

/// `frostmpm run` of a scene in configs/ into `out`, quietly, with `settings` (--set ...).
void run_scene(const std::string& scene, const std::string& out, const std::string& settings) {
  const auto r = run_frostmpm("run " + source_dir() + "/configs/" + scene + " -o " + out +
                              " --set output.progress=false " + settings);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
}

/// The Neumann thaw column: one cell (two particles, or one with `particles_per_cell` 1) wide,
/// 300 cells tall.
void run_column(const std::string& out, double end, int particles_per_cell = 2) {
  run_scene("verification/neumann_thaw.yaml", out,
            "--set time.end=" + std::to_string(end) + " --set output.every=1800 --set grid.particles_per_cell=" +
                std::to_string(particles_per_cell));
}

/// A field of the line figures, drawn from a column or a line through a 2-D run.
void require_line_figures(const std::string& folder, const std::string& field) {
  require_png(folder + "/" + field + "_profiles.png");
  require_png(folder + "/" + field + "_time_depth.png");
}

}  // namespace

TEST_CASE("plot.py draws the metrics and the fields of a run", "[plot]") {
  if (!have_matplotlib()) return;
  TempDir dir;
  const std::string out = dir.file("out");
  const auto run = run_frostmpm("run " + source_dir() + "/configs/tutorials/frozen_inclusion.yaml -o " + out +
                                " --set time.end=7200 --set output.every=3600 --set output.progress=false");
  INFO(run.output);
  REQUIRE(run.exit_code == 0);
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/scripts/plot.py " + out);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  require_png(out + "/metrics.png");
  require_png(out + "/fields.png");
  REQUIRE(r.output.find("wrote " + out + "/metrics.png") != std::string::npos);
}

TEST_CASE("plot.py draws the freezing curves into another folder with --to", "[plot]") {
  if (!have_matplotlib()) return;
  TempDir dir;
  const std::string out = dir.file("out");
  REQUIRE(run_frostmpm("run " + source_dir() + "/configs/tutorials/freezing_curves.yaml -o " + out).exit_code == 0);
  REQUIRE(!fs::exists(out + "/freezing_curves.png"));  // the task writes tables only
  const auto r = run_command("/usr/bin/python3 " + source_dir() + "/scripts/plot.py " + out + " --to " + dir.file("figures"));
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  require_png(dir.file("figures/freezing_curves.png"));
  REQUIRE(!fs::exists(dir.file("figures/metrics.png")));  // a freezing-curve run has no metrics

  // A folder with nothing to plot is an error, not an empty success.
  fs::create_directories(dir.file("empty"));
  const auto empty = run_command("/usr/bin/python3 " + source_dir() + "/scripts/plot.py " + dir.file("empty"));
  REQUIRE(empty.exit_code == 1);
  REQUIRE(empty.output.find("nothing to plot") != std::string::npos);
}

TEST_CASE("plot.py draws a one-cell-wide column as profiles, trumpet curves and a time-depth contour", "[plot]") {
  if (!have_matplotlib()) return;
  TempDir dir;
  const std::string out = dir.file("column");
  run_column(out, 7200);
  // Two particles across: nothing to triangulate (Qhull failed on it), profiles instead.
  const auto r = plot(out);
  require_png(out + "/metrics.png");
  require_png(out + "/fields.png");
  require_line_figures(out, "temperature");
  CHECK(r.output.find("wrote " + out + "/temperature_time_depth.png") != std::string::npos);
  // One particle across: every x equal, on which Qhull stops with an error.
  run_column(dir.file("thin"), 3600, 1);
  plot(dir.file("thin"));
  require_png(dir.file("thin/fields.png"));
  require_line_figures(dir.file("thin"), "temperature");

  // Another field, profiles at chosen times, the fields of the frame nearest a time.
  plot(out + " --field liquid_saturation --times 30min,1h,2h --time 1h --to " + dir.file("more"));
  require_line_figures(dir.file("more"), "liquid_saturation");
  require_png(dir.file("more/fields.png"));

  // Bad options: one line each, exit 2, no traceback.
  for (const auto& [args, message] :
       {std::pair{"--time 3d", "--time: t = 72 h lies outside the frames of fields.h5 (t = 0 h to 2 h)"},
        {"--times 1h,soon", "--times: 'soon' is not a time"},
        {"--field water_flux", "--field water_flux: fields.h5 has no field 'water_flux'"},
        {"--along y=1", "--along y=1: give a vertical line as x=X (metres)"},
        {"--along x=2", "--along x=2: the line x = 2 m misses the particles"},
        {"--frame 9", "--frame 9: fields.h5 has 5 frames"}}) {
    const auto bad = run_command("/usr/bin/python3 " + source_dir() + "/scripts/plot.py " + out + " " + args +
                                 " --to " + dir.file("bad"));
    INFO(bad.output);
    CHECK(bad.exit_code == 2);
    CHECK(bad.output.find(std::string("plot.py: ") + message) != std::string::npos);
    CHECK(bad.output.find("Traceback") == std::string::npos);
  }
}

TEST_CASE("plot.py draws a TH scene's flux arrows and the profiles along a vertical line through it", "[plot]") {
  if (!have_matplotlib()) return;
  TempDir dir;
  const std::string out = dir.file("inclusion");
  run_scene("paper/frozen_inclusion_case3.yaml", out,
            "--set 'grid.cells=[30, 10]' --set grid.cell_size=0.1 --set time.end=9000 --set output.every=3000");
  plot(out);  // a 2-D run draws no line figures unless asked for
  require_png(out + "/fields.png");
  CHECK(!fs::exists(out + "/temperature_profiles.png"));
  plot(out + " --along x=1 --times 1h,2.5h");
  require_line_figures(out, "temperature");
  plot(out + " --along x=2 --field water_flux.x");
  require_line_figures(out, "water_flux_x");
  const auto refused = run_command("/usr/bin/python3 " + source_dir() + "/scripts/plot.py " + out + " --times 1h");
  CHECK(refused.exit_code == 2);
  CHECK(refused.output.find("plot.py: --field and --times draw along a vertical line: give one with --along x=X") !=
        std::string::npos);
}

TEST_CASE("plot.py draws a restarted run, and a run folder without units", "[plot]") {
  if (!have_matplotlib()) return;
  TempDir dir;
  const std::string out = dir.file("column");
  run_column(out, 3600);
  const auto extended = run_frostmpm("run --restart " + out + " --set time.end=7200");
  INFO(extended.output);
  REQUIRE(extended.exit_code == 0);
  plot(out);
  require_png(out + "/fields.png");
  require_line_figures(out, "temperature");

  // Output written before FrostMPM recorded units: the figures come, with bare names.
  const auto stripped = run_command("/usr/bin/python3 -c \"import h5py, json\nf = h5py.File('" + out +
                                    "/fields.h5', 'r+')\nfor frame in f.values():\n for d in frame.values(): "
                                    "d.attrs.pop('units', None)\ns = json.load(open('" + out +
                                    "/run.json'))\ndel s['metrics_units']\njson.dump(s, open('" + out +
                                    "/run.json', 'w'))\"");
  INFO(stripped.output);
  REQUIRE(stripped.exit_code == 0);
  plot(out + " --to " + dir.file("old"));
  require_png(dir.file("old/metrics.png"));
  require_line_figures(dir.file("old"), "temperature");
}

TEST_CASE("plot.py labels with the recorded units only, and reads times with units", "[plot]") {
  if (!have_matplotlib()) return;
  const auto r = run_command(
      "/usr/bin/python3 -c \"import sys; sys.path.insert(0, '" + source_dir() + "/scripts')\n"
      "from frostplot import units\n"
      "assert units.label('T_min', 'degC') == 'T_min [°C]'\n"
      "assert units.label('liquid_volume_m3', 'm^3/m') == 'liquid_volume_m3 [m³/m]'\n"
      "assert units.label('S_l', '1') == 'S_l [-]'\n"
      "assert units.label('drag', 'kg/(m^3 s)') == 'drag [kg/(m³ s)]'\n"
      "assert units.label('liquid_volume_m3', None) == 'liquid_volume_m3'\n"
      "assert units.label('T_centre', None) == 'T_centre'\n"
      "assert units.parse_time('30d') == 30 * 86400 and units.parse_time('2.5 h') == 9000\n"
      "assert units.parse_time('1yr') == 365.25 * 86400 and units.parse_time('90') == 90\n"
      "print('ok')\"");
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK(r.output == "ok\n");
}
