// scripts/plot.py draws every figure of a run folder: the metrics time series, the particle
// fields of the last frame and the freezing-curve tables.
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
