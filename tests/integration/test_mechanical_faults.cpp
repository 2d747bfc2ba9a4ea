// Mechanical runs that fail or are stopped, as a user meets them: a scene that blows up exits 3
// with one line naming the particle, its region, the time and the step size, and keeps the frames written
// before it readable; a mechanical and a coupled mechanical + hydraulic run stopped with SIGTERM
// continue with `frostmpm run --restart OUT` to the fields and metrics of an uninterrupted run,
// bit for bit.
#include <catch2/catch.hpp>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <thread>

#include "test_support.hpp"

extern char** environ;

using namespace frostmpm::test;
namespace fs = std::filesystem;

namespace {

std::string python() {
  const char* configured = std::getenv("FROSTMPM_PYTHON");
  return configured && *configured ? configured : "/usr/bin/python3";
}

std::string scene(const std::string& name) { return source_dir() + "/configs/verification/" + name + ".yaml"; }

// ---- blow-up -----------------------------------------------------------------------------------

struct BlowUp {
  std::string what, args;
};

/// The self-weight column (rollers kept) under a surcharge as large as its Young's modulus
/// (1 MPa): it is crushed past its solid volume within a few steps.
std::string crushed_column(const TempDir& dir) {
  std::string text = read_file(scene("self_weight_column"));
  const std::string roller = "  - {type: roller, nodes: {face: x_max}}\n";
  const auto at = text.find(roller);
  REQUIRE(at != std::string::npos);
  text.insert(at + roller.size(), "  - {type: surcharge, nodes: {face: y_max}, value: 1.0e6}\n");
  write_file(dir.file("crushed.yaml"), text);
  return dir.file("crushed.yaml") + " --set output.every=0.0005";
}

/// Time of the blow-up as the message gives it ("at t = 0.0363 s"), NaN when absent.
double blow_up_time(const std::string& message) {
  const auto at = message.find("at t = ");
  return at == std::string::npos ? std::nan("") : std::strtod(message.c_str() + at + 7, nullptr);
}

/// Frames of fields.h5 with every dataset read in full (h5py): their count and latest time.
std::pair<int, double> read_every_frame(const std::string& path) {
  const std::string script =
      "import sys, h5py\n"
      "with h5py.File(sys.argv[1], 'r') as f:\n"
      "    times = []\n"
      "    for g in sorted(f):\n"
      "        for d in f[g]:\n"
      "            f[g][d][()]\n"
      "        times.append(float(f[g].attrs['time']))\n"
      "print(len(times), repr(max(times)))\n";
  TempDir tmp;
  write_file(tmp.file("frames.py"), script);
  const auto r = run_command(python() + " " + tmp.file("frames.py") + " " + path);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  std::istringstream in(r.output);
  int frames = 0;
  double latest = 0;
  in >> frames >> latest;
  return {frames, latest};
}

}  // namespace

TEST_CASE("a mechanical blow-up exits 3 naming the particle, its region, the time and dt, earlier frames readable",
          "[mechanical][blow-up]") {
  TempDir dir;
  const std::vector<BlowUp> cases = {
      // 100 m/s carries the bar's free end past the grid's edge (at 28 m) in about 0.04 s.
      {"a particle leaves the grid",
       scene("vibrating_bar") + " --set 'regions.0.initial={solid_velocity.x: 100}' --set output.every=0.01"},
      {"the skeleton is crushed", crushed_column(dir)}};
  for (const auto& c : cases) {
    SECTION(c.what) {
      const std::string out = dir.file("out");
      const auto r = run_frostmpm("run -q " + c.args + " -o " + out);
      INFO(r.output);
      REQUIRE(r.exit_code == 3);
      REQUIRE(std::count(r.output.begin(), r.output.end(), '\n') == 1);
      REQUIRE(r.output.rfind("error: numerical blow-up: ", 0) == 0);
      CHECK(r.output.find("particle ") != std::string::npos);
      CHECK(r.output.find("in regions.0 (material '") != std::string::npos);
      const double when = blow_up_time(r.output);
      REQUIRE(when > 0);
      CHECK(r.output.find(" s, step ") != std::string::npos);
      CHECK(r.output.find(" (dt = ") != std::string::npos);
      CHECK(!fs::exists(out + "/run.json"));  // a run that blew up did not finish

      // Frames before the blow-up, complete: h5py reads every dataset, the XDMF lists each.
      const auto [frames, latest] = read_every_frame(out + "/fields.h5");
      CHECK(frames >= 2);
      CHECK(latest <= when);  // a frame at that time holds the state the failing step started from
      const auto listed = run_command(python() + " " + source_dir() + "/scripts/read_fields.py " + out);
      INFO(listed.output);
      REQUIRE(listed.exit_code == 0);
      int in_xdmf = 0;
      for (std::size_t at = 0; (at = listed.output.find("\"step\":", at)) != std::string::npos; ++at) ++in_xdmf;
      CHECK(in_xdmf == frames);
      const std::string metrics = read_file(out + "/metrics.csv");
      REQUIRE(!metrics.empty());
      CHECK(metrics.back() == '\n');  // no row cut short
    }
  }
}

// ---- checkpoint and restart --------------------------------------------------------------------

namespace {


/// Time of the last complete row of OUT/metrics.csv while a run writes it (-1 before the first).
double metrics_time(const std::string& out) {
  const std::string text = read_file(out + "/metrics.csv");
  const auto end = text.rfind('\n');
  if (end == std::string::npos || end == 0) return -1;
  const auto begin = text.rfind('\n', end - 1);
  return begin == std::string::npos ? -1 : std::strtod(text.c_str() + begin + 1, nullptr);
}

/// Every frame of two fields.h5 equal bit for bit: the same frames, attributes and datasets.
/// What differs is listed with its size, relative to the field's largest magnitude.
void require_same_fields(const std::string& restarted, const std::string& reference) {
  const std::string script = R"(
import sys
import h5py
import numpy as np
problems = []
with h5py.File(sys.argv[1], "r") as a, h5py.File(sys.argv[2], "r") as b:
    frames = len(b)
    if sorted(a) != sorted(b):
        problems.append(f"frames {sorted(a)} != {sorted(b)}")
    for g in sorted(set(a) & set(b)):
        for key in sorted(set(a[g].attrs) | set(b[g].attrs)):
            x, y = a[g].attrs.get(key), b[g].attrs.get(key)
            if x is None or y is None or np.asarray(x).tobytes() != np.asarray(y).tobytes():
                problems.append(f"{g}: attribute {key} {x} != {y}")
        if sorted(a[g]) != sorted(b[g]):
            problems.append(f"{g}: datasets {sorted(a[g])} != {sorted(b[g])}")
        for d in sorted(set(a[g]) & set(b[g])):
            x, y = a[g][d][()], b[g][d][()]
            if x.dtype != y.dtype or x.shape != y.shape:
                problems.append(f"{g}/{d}: {x.dtype}{x.shape} != {y.dtype}{y.shape}")
            elif x.tobytes() != y.tobytes():
                diff = np.abs(x.astype(float) - y.astype(float))
                scale = np.abs(y.astype(float)).max()
                problems.append(f"{g}/{d}: {int((x != y).sum())} of {x.size} values differ, max |diff| "
                                f"{diff.max():.3g}, {diff.max() / scale if scale > 0 else np.inf:.3g} of the largest |value|")
print("\n".join(problems) if problems else f"{frames} frames equal bit for bit")
sys.exit(1 if problems else 0)
)";
  TempDir tmp;
  write_file(tmp.file("compare.py"), script);
  const auto compared = run_command(python() + " " + tmp.file("compare.py") + " " + restarted + "/fields.h5 " +
                                    reference + "/fields.h5");
  INFO(compared.output);
  CHECK(compared.exit_code == 0);
}

/// metrics.csv equal as text, line by line (the first difference is shown).
void require_same_metrics(const std::string& restarted, const std::string& reference) {
  std::istringstream a(read_file(restarted + "/metrics.csv")), b(read_file(reference + "/metrics.csv"));
  int line = 0;
  for (std::string x, y;;) {
    const bool more_a = static_cast<bool>(std::getline(a, x)), more_b = static_cast<bool>(std::getline(b, y));
    ++line;
    if (!more_a && !more_b) break;
    INFO("metrics.csv line " << line << "\n  restarted:     " << x << "\n  uninterrupted: " << y);
    CHECK(more_a == more_b);
    CHECK(x == y);
    if (x != y) break;
  }
}

/// Runs ARGS to the end, and again stopped with `signal` once metrics.csv reaches `stop_at`
/// seconds and resumed with `run --restart`; both with the same periodic checkpoints. SIGTERM
/// checkpoints the step it stopped at; after SIGKILL the run resumes from the last periodic one.
void stop_resume_and_compare(const std::string& args, double stop_at, int signal = SIGTERM) {
  TempDir dir;
  const std::string out = dir.file("out"), reference = dir.file("reference");
  const auto uninterrupted = run_frostmpm("run -q " + args + " -o " + reference);
  INFO(uninterrupted.output);
  REQUIRE(uninterrupted.exit_code == 0);
  {
    BackgroundRun run("run -q " + args + " -o " + out, dir.file("output"));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(300);
    while (metrics_time(out) < stop_at) {
      if (!run.running()) FAIL("the run ended before t = " << stop_at << " s:\n" << run.output());
      if (std::chrono::steady_clock::now() > deadline) FAIL("timed out waiting for t = " << stop_at << " s");
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    run.signal(signal);
    const int code = run.wait();
    INFO(run.output());
    REQUIRE(code == 128 + signal);
  }
  REQUIRE(fs::exists(out + "/checkpoint.h5"));
  const auto resumed = run_frostmpm("run -q --restart " + out);
  INFO(resumed.output);
  REQUIRE(resumed.exit_code == 0);
  require_same_fields(out, reference);
  require_same_metrics(out, reference);
}

// Every particle field a step starts from (and the ones derived from them) in the frames.
const std::string kSkeletonFields =
    "stress, strain, displacement, solid_velocity, deformation_gradient, porosity, volume, half_size";

}  // namespace

TEST_CASE("a mechanical run stopped with SIGTERM continues bit for bit with run --restart",
          "[mechanical][checkpoint]") {
  // The self-weight column undamped, so it keeps ringing and a difference would not die out;
  // about a second of computing, stopped a quarter of the way in.
  stop_resume_and_compare(scene("self_weight_column") + " --set time.end=6 --set physics.mechanical.local_damping=0" +
                              " --set output.every=0.25 --set 'output.fields=[" + kSkeletonFields + "]'" +
                              " --set 'checkpoint={every_steps: 200, every_minutes: 0}'",
                          1.5);
}

// A coupled run's pressure solver has state of its own: a preconditioner built (and refreshed)
// from earlier steps' matrices, and the last increment as the next initial guess. The checkpoint
// holds the values the preconditioner was made from and the increment, and a restart rebuilds
// the same solver, so a run resumed from any step continues bit for bit.
TEST_CASE("a coupled mechanical and hydraulic run killed and resumed from its checkpoint continues bit for bit",
          "[mechanical][hydraulic][checkpoint]") {
  // Terzaghi's consolidation, about 3 s of computing, killed a quarter of the way in (after the
  // checkpoint of step 3000, t ≈ 2.3 s).
  stop_resume_and_compare(scene("terzaghi_consolidation") + " --set 'output.fields=[" + kSkeletonFields +
                              ", pore_pressure, liquid_velocity, water_flux]'" +
                              " --set 'checkpoint={every_steps: 1000, every_minutes: 0}'",
                          2.5, SIGKILL);
}

TEST_CASE("a sealed frozen column stopped with SIGTERM while it warms continues bit for bit",
          "[mechanical][hydraulic][thermal][checkpoint]") {
  // configs/verification/undrained_warming.yaml (about 6 s of computing), stopped half-way
  // through the warming: the volume each step's projection leaves for the next (the ice's share
  // of the skeleton's correction) is state of the pressure solve and must come back.
  stop_resume_and_compare(scene("undrained_warming") + " --set output.every=0.1 --set 'output.fields=[" +
                              kSkeletonFields + ", pore_pressure, liquid_saturation, temperature]'" +
                              " --set 'checkpoint={every_steps: 0, every_minutes: 0}'",
                          0.5);
}

TEST_CASE("a thermo-hydraulic run stopped with SIGTERM between checkpoints continues bit for bit",
          "[hydraulic][checkpoint]") {
  // The paper's frozen inclusion (case 3) on 4 cm cells, implicit heat and the multigrid pressure
  // solve, stopped halfway, where the preconditioner has been refreshed and the heat step's first
  // guess extrapolates from the last substep.
  stop_resume_and_compare(source_dir() + "/configs/paper/frozen_inclusion_case3.yaml --set 'grid.cells=[75,25]'" +
                              " --set grid.cell_size=0.04 --set time.end=12000 --set output.every=1500" +
                              " --set 'checkpoint={every_steps: 0, every_minutes: 0}'",
                          6000, SIGTERM);
}

TEST_CASE("a coupled mechanical and hydraulic run stopped with SIGTERM between checkpoints continues bit for bit",
          "[mechanical][hydraulic][checkpoint]") {
  // The same run with no periodic checkpoint: SIGTERM checkpoints the step it came in, where the
  // solver holds a preconditioner of earlier steps (refreshed some 20 times by then).
  stop_resume_and_compare(scene("terzaghi_consolidation") + " --set 'output.fields=[" + kSkeletonFields +
                              ", pore_pressure, liquid_velocity, water_flux]'" +
                              " --set 'checkpoint={every_steps: 0, every_minutes: 0}'",
                          2.5, SIGTERM);
}
