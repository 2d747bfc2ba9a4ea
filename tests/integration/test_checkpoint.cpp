// Checkpoints and restart as a user meets them: a run killed with SIGKILL, or stopped with
// SIGTERM/SIGINT, continues with `frostmpm run --restart OUT` to fields and metrics equal to an
// uninterrupted run; a kill during a checkpoint write leaves the previous one to restart from;
// bad checkpoints and bad `checkpoint:` values are one-line errors. An in-process physics with
// persistent arrays (growing, nodal, empty) checks that they are restored exactly.
#include <catch2/catch.hpp>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <optional>
#include <thread>

#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/simulation/interrupt.hpp"
#include "frostmpm/simulation/simulation.hpp"
#include "test_support.hpp"

extern char** environ;

using namespace frostmpm;
using namespace frostmpm::test;
namespace fs = std::filesystem;

namespace {

// The Neumann thaw column, explicit: the automatic time step changes as the front moves, so a
// restart must continue the step selection exactly. About 2 s of computing.
constexpr double kEnd = 28800;
std::string scene_args() {
  return source_dir() + "/configs/verification/neumann_thaw.yaml --set time.end=28800 --set output.every=3600" +
         " --set output.metrics_every=60 --set 'checkpoint={every_steps: 100, every_minutes: 0}'";
}


/// Polls `done` every few milliseconds; fails if the run ends first or after `seconds`.
template <class Predicate>
void wait_until(BackgroundRun& run, Predicate done, const std::string& what, double seconds = 120) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (!run.running()) FAIL("the run ended before " << what << ":\n" << run.stderr_text());
    if (std::chrono::steady_clock::now() > deadline) FAIL("timed out waiting for " << what);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

/// Time of the last complete row of OUT/metrics.csv while a run writes it (-1 before the first).
double metrics_time(const std::string& out) {
  const std::string text = read_file(out + "/metrics.csv");
  const auto end = text.rfind('\n');
  if (end == std::string::npos) return -1;
  const auto begin = text.rfind('\n', end - 1);
  return begin == std::string::npos ? -1 : std::strtod(text.c_str() + begin + 1, nullptr);
}

/// Frames OUT/fields.xdmf lists.
long xdmf_frames(const std::string& out) {
  const std::string text = read_file(out + "/fields.xdmf");
  long count = 0;
  for (auto at = text.find("<Grid Name=\"step_"); at != std::string::npos; at = text.find("<Grid Name=\"step_", at + 1))
    ++count;
  return count;
}

bool same_value(double a, double b, double tolerance) {
  return (std::isnan(a) && std::isnan(b)) || std::abs(a - b) <= tolerance * std::max(std::abs(a), std::abs(b));
}

/// Every frame of fields.xdmf (time, step, coordinates, every field) equal to 1e-12 relative,
/// read as a visualiser does (scripts/read_fields.py), and metrics.csv with the same rows.
void require_same_outputs(const std::string& out, const std::string& reference) {
  const std::string script = R"(
import sys
sys.path.insert(0, sys.argv[1])
import numpy as np
import read_fields
a, b = read_fields.read_frames(sys.argv[2]), read_fields.read_frames(sys.argv[3])
problems = []
key = lambda frames: [(f["name"], f["time"], f.get("h5_step")) for f in frames]
if key(a) != key(b):
    problems.append(f"frames {key(a)} != {key(b)}")
for fa, fb in zip(a, b):
    if set(fa["fields"]) != set(fb["fields"]):
        problems.append(f"{fa['name']}: fields {sorted(fa['fields'])} != {sorted(fb['fields'])}")
        continue
    for name in ["coordinates"] + sorted(fb["fields"]):
        x = fa["coordinates"] if name == "coordinates" else fa["fields"][name]
        y = fb["coordinates"] if name == "coordinates" else fb["fields"][name]
        if x.shape != y.shape or np.any(np.abs(x - y) > 1e-12 * np.maximum(np.abs(x), np.abs(y))):
            problems.append(f"{fa['name']}: {name} differs")
print("\n".join(problems) if problems else f"same {len(a)} frames")
sys.exit(1 if problems else 0)
)";
  TempDir tmp;
  write_file(tmp.file("compare.py"), script);
  const auto compared = run_command("/usr/bin/python3 " + tmp.file("compare.py") + " " + source_dir() + "/scripts " +
                                    out + " " + reference);
  INFO(compared.output);
  REQUIRE(compared.exit_code == 0);

  const CsvTable a = read_csv(out + "/metrics.csv"), b = read_csv(reference + "/metrics.csv");
  REQUIRE(a.header == b.header);
  REQUIRE(a.rows.size() == b.rows.size());
  const std::size_t step = a.column("step");
  for (std::size_t r = 0; r < a.rows.size(); ++r) {
    INFO("metrics.csv row " << r + 2);
    REQUIRE(a.rows[r][step] == b.rows[r][step]);  // no duplicated or missing rows
    if (r > 0) REQUIRE(a.rows[r][step] > a.rows[r - 1][step]);
    REQUIRE(a.rows[r].size() == b.rows[r].size());
    for (std::size_t c = 0; c < a.rows[r].size(); ++c) REQUIRE(same_value(a.rows[r][c], b.rows[r][c], 1e-11));
  }
}

void run_reference(const std::string& reference) {
  const auto r = run_frostmpm("run " + scene_args() + " -o " + reference);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
}

void restart_to_the_end(const std::string& out) {
  const auto r = run_frostmpm("run --restart " + out);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(fs::exists(out + "/checkpoint.h5"));  // the finished run's, for extending it
  REQUIRE(!fs::exists(out + "/checkpoint.h5.partial"));
  CHECK(run_json(out, "['run']['restarts']") == "1");  // a count: a JSON integer
  CHECK(run_json(out, "['status']") == "finished");
}

/// Starts the scene writing to `out`, waits until `ready()` and sends `signal`; returns the exit
/// code. The rest of the run takes about a second, and a loaded machine can hold this process
/// back that long between its last poll and the signal: a run that finished first (exit 0) is
/// started again, at most three times, so that the test fails on what it checks, not on the race.
template <class Ready>
int run_until_signalled(const TempDir& dir, const std::string& out, int signal, Ready ready, const std::string& what) {
  for (int attempt = 1;; ++attempt) {
    fs::remove_all(out);
    BackgroundRun run("run " + scene_args() + " -o " + out, dir.file("stdout"), dir.file("stderr"));
    wait_until(run, ready, what);
    run.signal(signal);
    const int code = run.wait();
    if (code != 0 || attempt == 3) return code;
    WARN("the run finished before signal " << signal << " reached it (attempt " << attempt << "), started again");
  }
}

/// Stops a run with `signal` an eighth of the way in, checks what it leaves, resumes it.
void interrupt_and_resume(int signal) {
  TempDir dir;
  const std::string out = dir.file("out"), reference = dir.file("reference");
  REQUIRE(run_until_signalled(dir, out, signal, [&] { return metrics_time(out) >= kEnd / 8; }, "an eighth of the run") ==
          128 + signal);
  // Exactly one line: where it stopped and how to resume.
  const std::string err = read_file(dir.file("stderr"));
  INFO(err);
  REQUIRE(std::count(err.begin(), err.end(), '\n') == 1);
  REQUIRE(err.rfind("interrupted at t = ", 0) == 0);
  REQUIRE(err.find("; resume with: " + frostmpm_exe() + " run --restart " + out + "\n") != std::string::npos);
  const auto step_at = err.find("(step ");
  REQUIRE(step_at != std::string::npos);
  const long step = std::strtol(err.c_str() + step_at + 6, nullptr, 10);
  REQUIRE(read_file(dir.file("stdout")).empty());
  REQUIRE(fs::exists(out + "/checkpoint.h5"));
  REQUIRE(!fs::exists(out + "/checkpoint.h5.partial"));
  CHECK(run_json(out, "['status']") == "interrupted");

  // Readable outputs of the moment it stopped: the last frame and metrics row are at that step.
  const auto frames = run_command("/usr/bin/python3 " + source_dir() + "/scripts/read_fields.py " + out);
  INFO(frames.output);
  REQUIRE(frames.exit_code == 0);
  const std::string last_frame = frames.output.substr(frames.output.rfind("\"name\""));
  REQUIRE(last_frame.find("\"step\": " + std::to_string(step) + ",") != std::string::npos);
  const CsvTable metrics = read_csv(out + "/metrics.csv");
  REQUIRE(metrics.rows.back()[metrics.column("step")] == step);

  restart_to_the_end(out);
  run_reference(reference);
  require_same_outputs(out, reference);  // the extra frame and row of the stop are gone again
}

/// The failure contract of bad input: exit 2 and one line starting "error: ".
void require_one_line_error(const CommandResult& r, const std::string& expected) {
  INFO(r.output);
  REQUIRE(r.exit_code == 2);
  REQUIRE(r.output.rfind("error: ", 0) == 0);
  REQUIRE(std::count(r.output.begin(), r.output.end(), '\n') == 1);
  REQUIRE(r.output.find(expected) != std::string::npos);
}

}  // namespace

TEST_CASE("a run killed with SIGKILL continues from its checkpoint to the fields and metrics of an uninterrupted run",
          "[checkpoint]") {
  TempDir dir;
  const std::string out = dir.file("out"), reference = dir.file("reference");
  REQUIRE(run_until_signalled(
              dir, out, SIGKILL, [&] { return fs::exists(out + "/checkpoint.h5") && metrics_time(out) >= kEnd / 4; },
              "a checkpoint and a quarter of the run") == 128 + SIGKILL);
  REQUIRE(metrics_time(out) < kEnd);  // killed mid-way
  restart_to_the_end(out);
  run_reference(reference);
  require_same_outputs(out, reference);
}

TEST_CASE("SIGTERM finishes the step, writes a checkpoint and readable outputs, exits 143 with one line",
          "[checkpoint]") {
  interrupt_and_resume(SIGTERM);
}

TEST_CASE("SIGINT finishes the step, writes a checkpoint and readable outputs, exits 130 with one line",
          "[checkpoint]") {
  interrupt_and_resume(SIGINT);
}

TEST_CASE("a kill during a checkpoint write leaves the previous checkpoint, and restart drops newer frames and rows",
          "[checkpoint]") {
  TempDir dir;
  const std::string out = dir.file("out"), reference = dir.file("reference"), older = dir.file("older.h5");
  {
    BackgroundRun run("run " + scene_args() + " -o " + out, dir.file("stdout"), dir.file("stderr"));
    wait_until(run, [&] { return fs::exists(out + "/checkpoint.h5"); }, "the first checkpoint");
    // Checkpoints are replaced by rename, so the copy is one whole checkpoint. At most one
    // frame can appear between counting and copying: two more are surely newer than it.
    const long frames = xdmf_frames(out);
    fs::copy_file(out + "/checkpoint.h5", older);
    wait_until(run, [&] { return xdmf_frames(out) >= frames + 2; }, "two more frames");
    run.signal(SIGKILL);
    REQUIRE(run.wait() == 128 + SIGKILL);
  }
  const std::string good = read_file(older);
  REQUIRE(good.size() > 1000);
  // A checkpoint cut short is refused in one line (it is never published as checkpoint.h5, but
  // a damaged disk could do this)...
  write_file(out + "/checkpoint.h5", good.substr(0, good.size() / 2));
  require_one_line_error(run_frostmpm("run --restart " + out), "checkpoint.h5: not a readable checkpoint");
  // ...while a .partial cut short by a kill beside a good checkpoint is ignored.
  fs::copy_file(older, out + "/checkpoint.h5", fs::copy_options::overwrite_existing);
  write_file(out + "/checkpoint.h5.partial", good.substr(0, good.size() / 2));
  restart_to_the_end(out);
  run_reference(reference);
  require_same_outputs(out, reference);
}

TEST_CASE("restart without a usable checkpoint is one error line and exit 2", "[checkpoint][bad-input]") {
  TempDir dir;
  require_one_line_error(run_frostmpm("run --restart " + dir.file("missing")), "no checkpoint.h5 to restart from");
  fs::create_directories(dir.file("empty"));
  require_one_line_error(run_frostmpm("run --restart " + dir.file("empty")), "no checkpoint.h5 to restart from");
  fs::create_directories(dir.file("garbage"));
  write_file(dir.file("garbage/checkpoint.h5"), "not an HDF5 file\n");
  require_one_line_error(run_frostmpm("run --restart " + dir.file("garbage")), "not a readable checkpoint");

  // A finished run keeps its checkpoint, which only a later time.end continues; without
  // checkpoint.at_end it keeps none; an HDF5 file that is not a checkpoint is refused.
  const std::string finished = dir.file("finished");
  const auto r = run_frostmpm("run " + source_dir() + "/configs/verification/neumann_thaw.yaml --set time.end=600 -o " +
                              finished + " --set 'checkpoint={every_steps: 1}'");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  require_one_line_error(run_frostmpm("run --restart " + finished), "finished at t = 600 s and time.end is 600 s");
  require_one_line_error(run_frostmpm("run --restart " + finished + " --set time.end=300"), "give a later end");
  require_one_line_error(run_frostmpm("run --restart " + finished + " --set grid.cell_size=0.01"),
                         "a restart may change only time.end");
  const std::string no_final = dir.file("no_final");
  REQUIRE(run_frostmpm("run " + source_dir() + "/configs/verification/neumann_thaw.yaml --set time.end=600 -o " +
                       no_final + " --set 'checkpoint={at_end: false}'")
              .exit_code == 0);
  require_one_line_error(run_frostmpm("run --restart " + no_final), "no checkpoint.h5 to restart from");
  fs::remove(finished + "/checkpoint.h5");
  fs::copy_file(finished + "/fields.h5", finished + "/checkpoint.h5");
  require_one_line_error(run_frostmpm("run --restart " + finished), "not a readable checkpoint");

  require_one_line_error(run_frostmpm("run " + source_dir() + "/configs/verification/neumann_thaw.yaml --restart " +
                                      finished),
                         "--restart OUT takes no scene");
  require_one_line_error(run_frostmpm("run"), "give a scene file to run, or --restart OUT");
}

TEST_CASE("bad checkpoint values are one error line naming the YAML path, exit 2", "[checkpoint][bad-input]") {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{every_steps: -1}", "at 'checkpoint.every_steps'"},
      {"{every_steps: 2.5}", "at 'checkpoint.every_steps'"},
      {"{every_minutes: soon}", "expected a number (in min, or with its unit), got 'soon'"},
      {"{every_minutes: -5}", "at 'checkpoint.every_minutes'"},
      {"{every_step: 5}", "did you mean 'every_steps'"}};
  for (const auto& [value, expected] : cases) {
    INFO(value);
    require_one_line_error(run_frostmpm("run " + source_dir() + "/configs/verification/neumann_thaw.yaml -o " +
                                        dir.file("out") + " --set 'checkpoint=" + value + "'"),
                           expected);
    REQUIRE(!fs::exists(dir.file("out")));
  }
}

// ---- physics with persistent arrays, in process ------------------------------------------------

namespace {

/// A physics whose steps depend on arrays it keeps besides particle fields — a history that
/// grows every step, a nodal array, an always-empty one — and whose stable step depends on
/// them too, so a restart continues bit for bit only if they are restored exactly. It can
/// raise SIGTERM during a given step, as a user would.
class MemoryPhysics final : public Physics {
 public:
  MemoryPhysics(std::string name, const ParamSet& p)
      : name_(std::move(name)),
        interrupt_at_(p.integer("interrupt_at_step")),
        extra_(p.boolean("extra_array")),
        value_(FieldHandle::particle(field())) {}

  static ParamSchema schema() {
    ParamSchema s;
    s.integer("interrupt_at_step", "raise SIGTERM during this step; 0 = never").defaults_to(0L).at_least(0);
    s.boolean("extra_array", "keep one more persistent array (a changed physics)").defaults_to(false);
    return s;
  }

  ParamSchema material_schema() const override { return {}; }
  std::vector<ModelSlot> material_models() const override { return {}; }
  std::vector<std::string> boundary_types() const override { return {}; }
  void setup(Kernel<2>& sim) override {
    sim_ = &sim;
    sim.declare_state_field(field(), "1", 1, 0.0);
    nodal_.assign(sim.grid().node_count(), 0.0);
  }
  std::vector<Stage> stages() override {
    return {{name_ + ".update", Phase::UpdateMaterials, {value_.read()}, {value_.write()}, [this] { update(); }}};
  }
  void initialize() override {  // an initial condition a restart must overwrite
    auto v = value_.mutable_values();
    for (std::size_t p = 0; p < v.size(); ++p) v[p] = 1.0 + 1e-3 * double(p);
  }
  double stable_time_step() const override {
    return 0.2 + 0.1 * std::fmod(std::accumulate(history_.begin(), history_.end(), 0.0), 1.0);
  }
  void begin_step(double, double dt) override { dt_ = dt; }
  std::vector<PersistentArray> persistent_state() override {
    std::vector<PersistentArray> arrays = {{"history", &history_}, {"nodal", &nodal_}, {"empty", &empty_}};
    if (extra_) arrays.push_back({"extra", &extra_values_});
    return arrays;
  }
  void restored() override { ++restored_calls; }

  std::string field() const { return name_ + "_value"; }
  int restored_calls = 0;

 private:
  std::string name_;
  long interrupt_at_;
  bool extra_;
  Kernel<2>* sim_ = nullptr;
  FieldHandle value_;
  double dt_ = 0;
  std::vector<double> history_, nodal_, empty_, extra_values_;

  void update() {
    auto v = value_.mutable_values();
    const double memory = std::accumulate(history_.begin(), history_.end(), 0.0);
    for (std::size_t p = 0; p < v.size(); ++p) v[p] += dt_ * (1e-3 * memory + nodal_[p % nodal_.size()]);
    for (std::size_t i = 0; i < nodal_.size(); ++i) nodal_[i] = 0.5 * nodal_[i] + 1e-2 * v[i % v.size()];
    history_.push_back(1e-2 * std::accumulate(v.begin(), v.end(), 0.0) / double(v.size()));
    if (sim_->step() + 1 == interrupt_at_) std::raise(SIGTERM);
  }
};

Registry memory_registry() {
  Registry registry;
  for (const std::string name : {"memory_a", "memory_b"}) {
    RegistryEntry entry;
    entry.kind = Physics::kKind;
    entry.name = name;
    entry.doc = "test physics with persistent arrays";
    entry.library = "built-in";
    entry.schema = MemoryPhysics::schema();
    entry.create = [name](const ParamSet& p) -> std::shared_ptr<void> {
      return std::static_pointer_cast<void>(std::static_pointer_cast<Physics>(std::make_shared<MemoryPhysics>(name, p)));
    };
    registry.add(std::move(entry));
  }
  return registry;
}

const char* const kMemoryScene = R"(task: simulation
grid: {cells: [3, 2], cell_size: 0.5}
time: {end: 6}
physics: {memory_a: {}, memory_b: {}}
materials: {soil: {}}
regions: [{shape: {box: {min: [0, 0], max: [1.5, 1]}}, material: soil}]
output: {every: 1.5, progress: false, fields: [memory_a_value, memory_b_value]}
probes: [{name: a_max, type: max, field: memory_a_value}]
checkpoint: {every_steps: 4, every_minutes: 0}
)";

std::unique_ptr<Simulation> memory_simulation(const Registry& registry, const std::vector<std::string>& overrides) {
  YAML::Node tree = ConfigNode::load_string(kMemoryScene, "memory.yaml").raw();
  for (const auto& o : overrides) apply_override(tree, o);
  const ConfigNode root(tree, "memory.yaml");
  root.child("task");
  return std::make_unique<Simulation>(registry, root);
}

RunOptions restart_options() {
  RunOptions options;
  options.restart = true;
  return options;
}

}  // namespace

TEST_CASE("persistent arrays of every physics, growing, nodal or empty, are restored exactly", "[checkpoint]") {
  const Registry registry = memory_registry();
  TempDir dir;
  auto reference = memory_simulation(registry, {});
  reference->run(OutputDir(dir.file("reference")), {});

  const std::string out = dir.file("out");
  const std::vector<std::string> stop_at_7 = {"physics.memory_b.interrupt_at_step=7"};
  {
    auto stopped = memory_simulation(registry, stop_at_7);
    const InterruptGuard guard;
    try {
      stopped->run(OutputDir(out), {});
      FAIL("the run was not interrupted");
    } catch (const RunInterrupted& e) {
      REQUIRE(e.signal == SIGTERM);
      REQUIRE(e.step == 7);
    }
  }
  REQUIRE(fs::exists(out + "/checkpoint.h5"));

  // Scenes that do not fit the checkpoint are refused before any output is touched.
  const std::vector<std::pair<std::vector<std::string>, std::string>> misfits = {
      {{"physics.memory_a.extra_array=true"},
       "physics 'memory_a' stored the arrays empty, history, nodal, it now keeps history, nodal, empty, extra"},
      {{"grid.cells=[4, 2]", "regions.0.shape={box: {min: [0, 0], max: [2, 1]}}"},
       "it holds 24 particles, the scene makes 32"},
      {{"physics={memory_a: {}}", "output.fields=[memory_a_value]"},
       "it stores the fields half_size, memory_a_value, memory_b_value, position, volume, the scene has "
       "half_size, memory_a_value, position, volume"}};
  const std::string metrics_when_stopped = read_file(out + "/metrics.csv");
  for (const auto& [overrides, message] : misfits) {
    auto misfit = memory_simulation(registry, overrides);
    try {
      misfit->run(OutputDir(out), restart_options());
      FAIL("a scene that does not fit the checkpoint was accepted");
    } catch (const InputError& e) {
      REQUIRE_THAT(e.what(), Catch::Contains(message) && Catch::Contains("checkpoint.h5: the checkpoint does not fit"));
      REQUIRE(std::string(e.what()).find('\n') == std::string::npos);
    }
  }
  REQUIRE(read_file(out + "/metrics.csv") == metrics_when_stopped);

  auto resumed = memory_simulation(registry, stop_at_7);
  resumed->run(OutputDir(out), restart_options());
  REQUIRE(resumed->restarts() == 1);
  for (const auto& physics : resumed->physics()) REQUIRE(std::static_pointer_cast<MemoryPhysics>(physics)->restored_calls == 1);
  const auto& a = resumed->statistics();
  const auto& b = reference->statistics();
  REQUIRE(a.steps == b.steps);
  REQUIRE(a.dt_min == b.dt_min);
  REQUIRE(a.dt_max == b.dt_max);
  REQUIRE(a.dt_sum == b.dt_sum);
  REQUIRE(resumed->time() == reference->time());
  for (const auto& name : reference->particles().field_names()) {
    INFO(name);
    const auto x = resumed->particles().field(name);
    const auto y = reference->particles().field(name);
    REQUIRE(std::equal(x.begin(), x.end(), y.begin(), y.end()));
  }
  REQUIRE(read_file(out + "/metrics.csv") == read_file(dir.file("reference/metrics.csv")));
}
