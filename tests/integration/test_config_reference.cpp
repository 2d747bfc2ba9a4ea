// docs/config-reference.md is generated from the code's schemas by
// scripts/generate-config-reference.sh. This test regenerates it with the frostmpm just built and
// requires the committed file to be identical, so a schema or default changed without
// regenerating the reference fails here instead of shipping stale documentation.
#include <catch2/catch.hpp>

#include <filesystem>

#include "test_support.hpp"

using namespace frostmpm::test;

TEST_CASE("docs/config-reference.md is what scripts/generate-config-reference.sh writes", "[docs]") {
  TempDir dir;
  const std::string generated = dir.file("config-reference.md");
  const std::string committed = source_dir() + "/docs/config-reference.md";

  const auto r = run_command("bash " + source_dir() + "/scripts/generate-config-reference.sh " + generated + " " +
                             frostmpm_exe());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(std::filesystem::exists(generated));
  REQUIRE(std::filesystem::exists(committed));

  const std::string expected = read_file(generated);
  // No machine-specific text: the same reference comes out of every build and install tree.
  CHECK(expected.find(source_dir()) == std::string::npos);
  CHECK(expected.find(binary_dir()) == std::string::npos);

  if (read_file(committed) != expected) {
    const auto diff = run_command("diff -u " + committed + " " + generated);
    FAIL("docs/config-reference.md is out of date: run `bash scripts/generate-config-reference.sh` "
         "and commit the result.\n"
         << diff.output);
  }
  SUCCEED("docs/config-reference.md is up to date");
}
