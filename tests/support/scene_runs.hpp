#pragma once
// Runs of shipped scenes with overrides, for the verification tests (header-only: it asserts
// with Catch2 in the test that calls it).
#include <catch2/catch.hpp>

#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace frostmpm::test {

/// `v` with 17 significant digits: a --set value that reads back as the same double.
inline std::string exact_number(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

/// configs/verification/<file> in the source tree (a paper scene as "../paper/<file>").
inline std::string verification_scene(const std::string& file) { return source_dir() + "/configs/verification/" + file; }

/// Runs the scene file `scene` into dir/name with `--set` overrides and no progress line (on
/// `threads` threads when given); requires exit 0 and returns its metrics.csv.
inline CsvTable run_scene(const TempDir& dir, const std::string& scene, const std::vector<std::string>& sets,
                          const std::string& name, int threads = 0) {
  std::string cmd = "run " + scene + " -o " + dir.file(name) + " --set output.progress=false";
  if (threads > 0) cmd += " --threads " + std::to_string(threads);
  for (const auto& s : sets) cmd += " --set '" + s + "'";
  const auto r = run_frostmpm(cmd);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return read_csv(dir.file(name + "/metrics.csv"));
}

}  // namespace frostmpm::test
