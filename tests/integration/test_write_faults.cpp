// Write faults as a user meets them: the disk fills up while a run writes fields.h5, metrics.csv
// or a checkpoint. A file size limit (ulimit -f, RLIMIT_FSIZE, with SIGXFSZ ignored) makes every
// write past that size fail (EFBIG) just as a full disk does (ENOSPC), without root or a mount;
// where a tmpfs can be mounted (root), the fields and metrics cases also run on a really full one.
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
/// `metrics_every` s (0 = every step); `-o OUT` to be added.
std::string scene_args(const std::string& every, const std::string& metrics_every) {
  return "run " + source_dir() + "/configs/verification/neumann_thaw.yaml --set time.end=28800 --set output.every=" +
         every + " --set output.metrics_every=" + metrics_every;
}

/// `frostmpm ARGS` with every file it writes limited to `bytes` (rounded down to KiB).
CommandResult run_with_file_size_limit(const std::string& args, std::uintmax_t bytes) {
  return run_command("bash -c \"trap '' XFSZ; ulimit -f " + std::to_string(bytes / 1024) + "; exec " +
                     frostmpm_exe() + " " + args + "\"");
}

/// Room for `bytes` in the output folder OUT: a file size limit on the run (any user), or a
/// tmpfs of that size mounted on OUT while alive (root only; mounted() tells).
class FullDisk {
 public:
  FullDisk(bool tmpfs, const std::string& out, std::uintmax_t bytes) : tmpfs_(tmpfs), out_(out), bytes_(bytes) {
    if (!tmpfs_) return;
    fs::create_directories(out_);
    mounted_ = run_command("mount -t tmpfs -o size=" + std::to_string(bytes_) + " tmpfs " + out_).exit_code == 0;
    if (!mounted_) WARN("skipped on a tmpfs: it cannot be mounted here (needs root)");
  }
  ~FullDisk() {
    if (mounted_) run_command("umount " + out_);
  }
  FullDisk(const FullDisk&) = delete;
  FullDisk& operator=(const FullDisk&) = delete;
  bool usable() const { return !tmpfs_ || mounted_; }
  /// `frostmpm ARGS -o OUT`.
  CommandResult run(const std::string& args) const {
    return tmpfs_ ? run_frostmpm(args + " -o " + out_) : run_with_file_size_limit(args + " -o " + out_, bytes_);
  }
  /// What the system says: EFBIG past a file size limit, ENOSPC on a full disk.
  std::string reason() const { return tmpfs_ ? "No space left on device" : "File too large"; }

 private:
  bool tmpfs_ = false, mounted_ = false;
  std::string out_;
  std::uintmax_t bytes_ = 0;
};

/// The write-fault contract: exit 2, one line "error: cannot write <file> at step ...: <reason>".
void require_one_line_write_error(const CommandResult& r, const std::string& file, const std::string& reason) {
  INFO(r.output);
  REQUIRE(r.exit_code == 2);
  REQUIRE(r.output.rfind("error: cannot write " + file + " at step ", 0) == 0);
  REQUIRE(r.output.find("): " + reason + "\n") != std::string::npos);
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
  const std::string args = scene_args("3600", "3600");
  REQUIRE(run_frostmpm(args + " -o " + dir.file("full")).exit_code == 0);
  const auto full_size = fs::file_size(dir.file("full/fields.h5"));
  REQUIRE(fs::file_size(dir.file("full/metrics.csv")) < full_size / 4);

  for (const bool tmpfs : {false, true}) {
    const std::string out = dir.file(tmpfs ? "tmpfs" : "limited");
    const FullDisk disk(tmpfs, out, full_size / 2);
    if (!disk.usable()) continue;
    require_one_line_write_error(disk.run(args), out + "/fields.h5", disk.reason());
    const int frames = readable_frames(out);
    CHECK(frames >= 2);
    CHECK(frames < 9);
    require_whole_rows(out + "/metrics.csv");
    require_no_partial_files(out);
  }
}

TEST_CASE("a disk filling up during metrics.csv is one line, exit 2, no row cut short", "[write-faults]") {
  TempDir dir;
  // A row every step, frames at the start and end only.
  const std::string args = scene_args("0", "0");
  REQUIRE(run_frostmpm(args + " -o " + dir.file("full")).exit_code == 0);
  const auto limit = fs::file_size(dir.file("full/metrics.csv")) / 2;
  REQUIRE(fs::file_size(dir.file("full/fields.h5")) < limit / 2);

  for (const bool tmpfs : {false, true}) {
    const std::string out = dir.file(tmpfs ? "tmpfs" : "limited");
    const FullDisk disk(tmpfs, out, limit);
    if (!disk.usable()) continue;
    require_one_line_write_error(disk.run(args), out + "/metrics.csv", disk.reason());
    require_whole_rows(out + "/metrics.csv");
    CHECK(fs::file_size(out + "/metrics.csv") <= limit);
    CHECK(readable_frames(out) == 1);  // the first frame; the run stopped before the last
    require_no_partial_files(out);
  }
}

TEST_CASE("a disk filling up during a checkpoint is one line, exit 2, no .partial left", "[write-faults]") {
  TempDir dir;
  // Frames at the start and end only. checkpoint.h5 holds every particle field, more than both
  // frames together: a limit of that size lets the first frame through and stops the checkpoint.
  const std::string checkpoint = " --set 'checkpoint={every_steps: 10, every_minutes: 0}'";
  REQUIRE(run_frostmpm(scene_args("0", "3600") + " -o " + dir.file("full")).exit_code == 0);
  const std::string out = dir.file("limited");
  const FullDisk disk(false, out, fs::file_size(dir.file("full/fields.h5")));
  const auto r = disk.run(scene_args("0", "3600") + checkpoint);
  INFO(r.output);
  REQUIRE(r.exit_code == 2);  // not a crash in HDF5 on the way out
  REQUIRE(r.output == "error: cannot write checkpoint " + out + "/checkpoint.h5.partial: File too large\n");
  require_no_partial_files(out);
  require_whole_rows(out + "/metrics.csv");
  CHECK(readable_frames(out) == 1);
}
