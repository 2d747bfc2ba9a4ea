// Write faults as a user meets them: the disk fills up while a run writes fields.h5, metrics.csv
// or a checkpoint. A file size limit (ulimit -f, RLIMIT_FSIZE, with SIGXFSZ ignored) makes every
// write past that size fail (EFBIG) just as a full disk does (ENOSPC), without root or a mount.
// Expected: exit 2, one line naming the file and step, no HDF5 error dump, earlier frames and
// rows readable, no .partial left behind.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>

#include "test_support.hpp"

using namespace frostmpm::test;
namespace fs = std::filesystem;

namespace {

/// The Neumann thaw column (about a second), outputs every `every` s, metrics every
/// `metrics_every` s (0 = every step).
std::string scene_args(const std::string& every, const std::string& metrics_every, const std::string& out) {
  return source_dir() + "/configs/verification/neumann_thaw.yaml --set time.end=28800 --set output.every=" + every +
         " --set output.metrics_every=" + metrics_every + " -o " + out;
}

/// `frostmpm ARGS` with every file it writes limited to `bytes` (rounded down to KiB).
CommandResult run_with_file_size_limit(const std::string& args, std::uintmax_t bytes) {
  return run_command("bash -c \"trap '' XFSZ; ulimit -f " + std::to_string(bytes / 1024) + "; exec " +
                     frostmpm_exe() + " " + args + "\"");
}

/// The write-fault contract: exit 2, one line "error: cannot write <file> at step ...".
void require_one_line_write_error(const CommandResult& r, const std::string& file) {
  INFO(r.output);
  REQUIRE(r.exit_code == 2);
  REQUIRE(r.output.rfind("error: cannot write " + file + " at step ", 0) == 0);
  REQUIRE(r.output.find("File too large\n") != std::string::npos);  // the system's reason (EFBIG)
  REQUIRE(std::count(r.output.begin(), r.output.end(), '\n') == 1);  // no HDF5 error stack
}

void require_no_partial_files(const std::string& out) {
  for (const auto& entry : fs::directory_iterator(out)) {
    INFO(entry.path());
    REQUIRE(entry.path().extension() != ".partial");
  }
}

/// Every line of metrics.csv complete: as many columns as the header, ending in a newline.
void require_whole_rows(const std::string& path) {
  const std::string text = read_file(path);
  REQUIRE(!text.empty());
  REQUIRE(text.back() == '\n');
  const CsvTable table = read_csv(path);
  REQUIRE(!table.rows.empty());
  for (const auto& row : table.rows) REQUIRE(row.size() == table.header.size());
}

/// Number of frames in OUT that scripts/read_fields.py reads (via fields.xdmf and h5py); every
/// frame group in fields.h5 must read completely with h5py too.
int readable_frames(const std::string& out) {
  const auto listed = run_command("/usr/bin/python3 " + source_dir() + "/scripts/read_fields.py " + out + " --dump");
  INFO(listed.output);
  REQUIRE(listed.exit_code == 0);
  const auto all = run_command("/usr/bin/python3 -c \"import h5py, sys; f = h5py.File(sys.argv[1], 'r'); "
                               "[f[g][d][()] for g in f for d in f[g]]; print(len(f))\" " + out + "/fields.h5");
  INFO(all.output);
  REQUIRE(all.exit_code == 0);
  const int frames = std::stoi(all.output);
  int in_xdmf = 0;
  for (std::size_t at = 0; (at = listed.output.find("\"step\":", at)) != std::string::npos; ++at) ++in_xdmf;
  REQUIRE(in_xdmf == frames);  // the XDMF lists exactly the frames fields.h5 holds
  return frames;
}

}  // namespace

TEST_CASE("a disk filling up during fields.h5 is one line, exit 2, earlier frames readable", "[write-faults]") {
  TempDir dir;
  // Nine frames; metrics.csv stays far below the limit.
  REQUIRE(run_frostmpm("run " + scene_args("3600", "3600", dir.file("full"))).exit_code == 0);
  const auto full_size = fs::file_size(dir.file("full/fields.h5"));
  REQUIRE(fs::file_size(dir.file("full/metrics.csv")) < full_size / 4);

  const std::string out = dir.file("out");
  const auto r = run_with_file_size_limit("run " + scene_args("3600", "3600", out), full_size / 2);
  require_one_line_write_error(r, out + "/fields.h5");
  const int frames = readable_frames(out);
  CHECK(frames >= 2);
  CHECK(frames < 9);
  require_whole_rows(out + "/metrics.csv");
  require_no_partial_files(out);
}

TEST_CASE("a disk filling up during metrics.csv is one line, exit 2, no row cut short", "[write-faults]") {
  TempDir dir;
  // A row every step, frames at the start and end only.
  REQUIRE(run_frostmpm("run " + scene_args("0", "0", dir.file("full"))).exit_code == 0);
  const auto metrics_size = fs::file_size(dir.file("full/metrics.csv"));
  const auto limit = metrics_size / 2;
  REQUIRE(fs::file_size(dir.file("full/fields.h5")) < limit / 2);

  const std::string out = dir.file("out");
  const auto r = run_with_file_size_limit("run " + scene_args("0", "0", out), limit);
  require_one_line_write_error(r, out + "/metrics.csv");
  require_whole_rows(out + "/metrics.csv");
  CHECK(fs::file_size(out + "/metrics.csv") <= limit);
  CHECK(readable_frames(out) == 1);  // the first frame; the run stopped before the last
  require_no_partial_files(out);
}

TEST_CASE("a disk filling up during a checkpoint is one line, exit 2, no .partial left", "[write-faults]") {
  TempDir dir;
  // Frames at the start and end only. checkpoint.h5 holds every particle field, more than both
  // frames together: a limit of that size lets the first frame through and stops the checkpoint.
  const std::string checkpoint = " --set 'checkpoint={every_steps: 10, every_minutes: 0}'";
  REQUIRE(run_frostmpm("run " + scene_args("0", "3600", dir.file("full"))).exit_code == 0);
  const auto limit = fs::file_size(dir.file("full/fields.h5"));

  const std::string out = dir.file("out");
  const auto r = run_with_file_size_limit("run " + scene_args("0", "3600", out) + checkpoint, limit);
  INFO(r.output);
  REQUIRE(r.exit_code == 2);  // not a crash in HDF5 on the way out
  REQUIRE(r.output == "error: cannot write checkpoint " + out + "/checkpoint.h5.partial: File too large\n");
  require_no_partial_files(out);
  require_whole_rows(out + "/metrics.csv");
  CHECK(readable_frames(out) == 1);
}
