// Checked output writes: a full disk (/dev/full fails every write with ENOSPC) is one
// OutputError line naming the file and step, and an atomic write leaves neither a .partial nor
// a changed earlier file behind.
#include <catch2/catch.hpp>

#include <filesystem>

#include "frostmpm/io/output_dir.hpp"
#include "test_support.hpp"

using namespace frostmpm;
using namespace frostmpm::test;
namespace fs = std::filesystem;

TEST_CASE("CheckedFile: a write to a full disk is one OutputError line with file, step and reason", "[io]") {
  CheckedFile full("/dev/full", /*append=*/false);
  REQUIRE_THROWS_MATCHES(full.write("t,step\n", at_step(12, 0.5)), OutputError,
                         Catch::Message("cannot write /dev/full at step 12 (t = 0.5 s): No space left on device"));
}

TEST_CASE("write_file_atomically: a full disk removes the .partial and keeps the earlier file", "[io]") {
  TempDir dir;
  const std::string path = dir.file("run.json");
  write_file(path, "earlier\n");
  fs::create_symlink("/dev/full", path + ".partial");  // the temp file lands on a full disk
  REQUIRE_THROWS_MATCHES(write_file_atomically(path, "newer\n", at_step(3, 2)), OutputError,
                         Catch::Message("cannot write " + path + " at step 3 (t = 2 s): No space left on device"));
  REQUIRE(read_file(path) == "earlier\n");
  REQUIRE(!fs::exists(fs::symlink_status(path + ".partial")));
  write_file_atomically(path, "newer\n");  // and with room it works
  REQUIRE(read_file(path) == "newer\n");
}
