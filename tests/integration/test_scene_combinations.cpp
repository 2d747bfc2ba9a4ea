// Scenes that combine conditions in ways the bad-input corpus cannot show, since they are
// accepted: velocity conditions that agree where they meet.
#include <catch2/catch.hpp>

#include <cmath>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

std::string scene(const std::string& path) { return source_dir() + "/configs/" + path + ".yaml"; }

/// `frostmpm ARGS`, required to succeed; its output.
std::string succeeds(const std::string& args) {
  const auto r = run_frostmpm(args);
  INFO("frostmpm " << args << "\n" << r.output);
  REQUIRE(r.exit_code == 0);
  return r.output;
}

}  // namespace

TEST_CASE("velocity conditions that prescribe the same value where they meet are accepted",
          "[mechanical][boundary]") {
  const std::string column = "check " + scene("verification/self_weight_column");
  // The side rollers and the fixed base share the bottom corners, all holding 0 there.
  succeeds(column);
  // A zero side velocity agrees with the base at the corner, as a number or a constant table.
  succeeds(column + " --set 'boundary_conditions.2={type: velocity, nodes: {face: x_max}, x: 0}'");
  succeeds(column +
           " --set 'boundary_conditions.2={type: velocity, nodes: {face: x_max}, x: {table: [[0, 0], [1, 0]]}}'");
}
