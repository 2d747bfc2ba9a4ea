#pragma once
// Checkpoints: OUT/checkpoint.h5 holds everything a run needs to continue bit for bit — every
// particle field, the run loop's state and every physics' persistent arrays — plus what
// re-creates the scene (its text, the --set overrides, the plugin paths), so that
// `frostmpm run --restart OUT` needs nothing else.
//
// Atomic: a checkpoint is written to checkpoint.h5.partial, flushed, closed, fsync'ed and only
// then renamed over checkpoint.h5 (and the folder fsync'ed), so a kill at any moment leaves
// the previous checkpoint whole; a leftover .partial is never read.
//
// HDF5 layout (format 1):
//   /                        attribute format (int)
//   /scene                   string datasets path, text (one element each), overrides, plugin_paths
//   /loop                    attributes time, step, dt, next_dt, steps, dt_min, dt_max, dt_sum,
//                            next_output, next_metrics, frames, metrics_rows, restarts
//   /loop/stage_seconds      one double attribute per stage name
//   /particles               attribute count; ranges (n x 3 int64: begin, end, material)
//   /particles/fields/NAME   count x components doubles, attribute components
//   /physics/KEY/ARRAY       1-D doubles, any length (0 included)
//
// hdf5.h is included by the .cpp only.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "frostmpm/particles/particle_store.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/simulation/step_statistics.hpp"

namespace frostmpm {

/// What re-creates the scene of a run.
struct SceneSource {
  std::string path;                       ///< scene file, absolute (messages, relative plugin_paths)
  std::string text;                       ///< its contents when the run started
  std::vector<std::string> overrides;     ///< --set assignments, in order
  std::vector<std::string> plugin_paths;  ///< --plugin-path values, absolute
};

/// The run loop's state between two steps. With the particle fields and the physics'
/// persistent arrays it is all that the rest of the run depends on.
struct LoopState {
  double time = 0;
  long step = 0;
  double dt = 0;       ///< the step that ended at `time` (metrics.csv's dt_s)
  double next_dt = 0;  ///< the step already chosen to come next
  StepStatistics statistics;
  double next_output = 0;   ///< simulated time of the next frame
  double next_metrics = 0;  ///< simulated time of the next metrics row (metrics_every > 0)
  long frames = 0;          ///< frames of fields.h5 that belong to the run so far
  long metrics_rows = 0;    ///< rows of metrics.csv that belong to the run so far (header not counted)
  long restarts = 0;        ///< how often the run had been restarted when this was saved
};

std::string checkpoint_path(const std::string& dir);  ///< <dir>/checkpoint.h5
/// Deletes <dir>/checkpoint.h5 and any leftover .partial (a new run must not resume an old one).
void remove_checkpoint(const std::string& dir);

class CheckpointWriter {
 public:
  /// Starts <dir>/checkpoint.h5.partial. Every method throws InputError naming the file when
  /// writing fails (e.g. a full disk); the previous checkpoint is then untouched.
  explicit CheckpointWriter(const std::string& dir);
  /// Deletes the .partial file unless commit() succeeded.
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  void write(const SceneSource& scene);
  void write(const LoopState& loop);
  void write(const ParticleStore& particles);
  /// The persistent arrays of the physics named `key` in the scene (none is fine).
  void write_physics(const std::string& key, const std::vector<PersistentArray>& arrays);
  /// Flushes, closes, fsyncs and renames the file over checkpoint.h5.
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class CheckpointReader {
 public:
  /// Opens <dir>/checkpoint.h5. Every method throws a one-line InputError naming the file
  /// when there is none, it is not a readable checkpoint, or it does not fit the scene.
  explicit CheckpointReader(const std::string& dir);
  ~CheckpointReader();
  CheckpointReader(const CheckpointReader&) = delete;
  CheckpointReader& operator=(const CheckpointReader&) = delete;

  SceneSource scene() const;
  LoopState loop() const;
  /// Overwrites every field of `particles`; the count, the ranges and the field set (names and
  /// components) must equal the stored ones.
  void read(ParticleStore& particles) const;
  /// The stored values of particle field `name` (one component), or nothing when the
  /// checkpoint has no such field: a run that removed particles stores "particle_id", the
  /// index each remaining particle had when the scene made it.
  std::optional<std::vector<double>> particle_field(const std::string& name) const;
  /// Keys of the physics whose arrays are stored.
  std::vector<std::string> physics_keys() const;
  /// Resizes and refills `arrays` of physics `key`; the stored array names must equal theirs.
  void read_physics(const std::string& key, const std::vector<PersistentArray>& arrays) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace frostmpm
