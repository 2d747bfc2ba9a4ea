// Fuzzing the shipped scenes: bench/fuzz mutates every scene in configs/ with
// fixed seeds; each mutation must be accepted (0), refused (2, one error line) or stop as a
// blow-up (3) — never crash, hang or end in an internal error. The longer run is bench/fuzz.
#include <catch2/catch.hpp>

#include "test_support.hpp"

using namespace frostmpm::test;

TEST_CASE("fuzzed scenes exit 0, 2 or 3 and never crash or hang", "[cli][bad-input][fuzz]") {
  const CommandResult r = run_command("/usr/bin/python3 " + source_dir() + "/bench/fuzz --count 240 --seed 20261123 --jobs 2 " +
                                      "--run-fraction 0.04 --timeout 30 --exe " + frostmpm_exe());
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("240 mutations") != std::string::npos);
}
