#include "frostmpm/io/checkpoint.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <set>
#include <stdexcept>

#include "frostmpm/config/input_error.hpp"
#include "frostmpm/io/hdf5_support.hpp"
#include "frostmpm/io/output_dir.hpp"

namespace fs = std::filesystem;

namespace frostmpm {

namespace {

constexpr const char* kFileName = "checkpoint.h5";
constexpr int kFormat = 1;

/// A failure inside `fn` becomes one InputError line: `prefix` + the HDF5 or system message.
template <class F>
auto one_line_errors(const std::string& prefix, F&& fn) {
  const hdf5::QuietErrors quiet;
  try {
    return fn();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(prefix + e.what());
  }
}

std::string list_text(const std::vector<std::string>& names) { return names.empty() ? "none" : join(names); }

// ---- /loop attributes, one table for writing and reading ------------------------------------

template <class Loop>
auto loop_reals(Loop& l) {
  return std::vector<std::pair<const char*, decltype(&l.time)>>{
      {"time", &l.time},
      {"dt", &l.dt},
      {"next_dt", &l.next_dt},
      {"dt_min", &l.statistics.dt_min},
      {"dt_max", &l.statistics.dt_max},
      {"dt_sum", &l.statistics.dt_sum},
      {"next_output", &l.next_output},
      {"next_metrics", &l.next_metrics}};
}

template <class Loop>
auto loop_integers(Loop& l) {
  return std::vector<std::pair<const char*, decltype(&l.step)>>{{"step", &l.step},
                                                               {"steps", &l.statistics.steps},
                                                               {"frames", &l.frames},
                                                               {"metrics_rows", &l.metrics_rows},
                                                               {"restarts", &l.restarts}};
}

}  // namespace

std::string checkpoint_path(const std::string& dir) { return dir + "/" + kFileName; }

void remove_checkpoint(const std::string& dir) {
  std::error_code ec;
  fs::remove(checkpoint_path(dir), ec);
  fs::remove(checkpoint_path(dir) + ".partial", ec);
}

// ---- writer --------------------------------------------------------------------------------

struct CheckpointWriter::Impl {
  std::string final_path, partial_path;
  hdf5::Handle file;
  bool committed = false;

  /// Runs `fn` after reserving the disk for `data_bytes` in `objects` new groups or datasets.
  template <class F>
  void guarded(std::uintmax_t data_bytes, std::size_t objects, F&& fn) {
    one_line_errors("cannot write checkpoint " + partial_path + ": ", [&] {
      if (file.get() < 0) {  // the first call creates the file
        file = hdf5::create_file(partial_path);
        hdf5::write_attribute(file.get(), "format", kFormat);
      }
      hdf5::reserve(file.get(), partial_path, data_bytes, objects);
      fn();
    });
  }

  /// Closes and removes the unfinished .partial (a failed write leaves nothing behind).
  void discard() {
    const hdf5::QuietErrors quiet;
    file = hdf5::Handle();
    H5Eclear2(H5E_DEFAULT);
    std::error_code ec;
    fs::remove(partial_path, ec);
  }
};

CheckpointWriter::CheckpointWriter(const std::string& dir) : impl_(std::make_unique<Impl>()) {
  impl_->final_path = checkpoint_path(dir);
  impl_->partial_path = impl_->final_path + ".partial";
  try {
    impl_->guarded(0, 1, [] {});
  } catch (...) {
    impl_->discard();  // the destructor does not run for a constructor that throws
    throw;
  }
}

CheckpointWriter::~CheckpointWriter() {
  if (!impl_->committed) impl_->discard();
}

void CheckpointWriter::write(const SceneSource& scene) {
  std::uintmax_t bytes = scene.path.size() + scene.text.size();
  for (const auto& list : {scene.overrides, scene.plugin_paths})
    for (const auto& item : list) bytes += item.size() + 16;
  impl_->guarded(bytes, 5, [&] {
    const hdf5::Handle group = hdf5::create_group(impl_->file.get(), "scene");
    hdf5::write_strings(group.get(), "path", {scene.path});
    hdf5::write_strings(group.get(), "text", {scene.text});
    hdf5::write_strings(group.get(), "overrides", scene.overrides);
    hdf5::write_strings(group.get(), "plugin_paths", scene.plugin_paths);
  });
}

void CheckpointWriter::write(const LoopState& loop) {
  impl_->guarded(0, 2 + loop.statistics.stage_seconds.size() / 8, [&] {
    const hdf5::Handle group = hdf5::create_group(impl_->file.get(), "loop");
    for (const auto& [name, value] : loop_reals(loop)) hdf5::write_attribute(group.get(), name, *value);
    for (const auto& [name, value] : loop_integers(loop))
      hdf5::write_attribute(group.get(), name, static_cast<std::int64_t>(*value));
    const hdf5::Handle stages = hdf5::create_group(group.get(), "stage_seconds");
    for (const auto& [name, seconds] : loop.statistics.stage_seconds) hdf5::write_attribute(stages.get(), name, seconds);
  });
}

void CheckpointWriter::write(const ParticleStore& particles) {
  std::uintmax_t bytes = particles.ranges().size() * 3 * 8;
  for (const auto& name : particles.field_names()) bytes += particles.field(name).size() * 8;
  impl_->guarded(bytes, particles.field_names().size() + 3, [&] {
    const hdf5::Handle group = hdf5::create_group(impl_->file.get(), "particles");
    const std::size_t count = particles.size();
    hdf5::write_attribute(group.get(), "count", static_cast<std::int64_t>(count));
    std::vector<std::int64_t> ranges;
    for (const auto& r : particles.ranges())
      ranges.insert(ranges.end(), {std::int64_t(r.begin), std::int64_t(r.end), std::int64_t(r.material)});
    hdf5::write_dataset(group.get(), "ranges", H5T_STD_I64LE, H5T_NATIVE_INT64, {particles.ranges().size(), 3},
                        ranges.data());
    const hdf5::Handle fields = hdf5::create_group(group.get(), "fields");
    for (const auto& name : particles.field_names()) {
      const int components = particles.components(name);
      hdf5::write_dataset(fields.get(), name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                          {count, static_cast<std::size_t>(components)}, particles.field(name).data(), components);
    }
  });
}

void CheckpointWriter::write_physics(const std::string& key, const std::vector<PersistentArray>& arrays) {
  std::uintmax_t bytes = 0;
  for (const auto& array : arrays) bytes += array.values->size() * 8;
  impl_->guarded(bytes, arrays.size() + 2, [&] {
    const hdf5::Id file = impl_->file.get();
    const hdf5::Handle all = hdf5::exists(file, "physics") ? hdf5::open_group(file, "physics")
                                                           : hdf5::create_group(file, "physics");
    const hdf5::Handle group = hdf5::create_group(all.get(), key);
    for (const auto& array : arrays)
      hdf5::write_dataset(group.get(), array.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {array.values->size()},
                          array.values->data());
  });
}

void CheckpointWriter::commit() {
  impl_->guarded(0, 1, [&] {
    if (!hdf5::exists(impl_->file.get(), "physics")) hdf5::create_group(impl_->file.get(), "physics");
    hdf5::check(H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL), "flushing");
    hdf5::reserve(impl_->file.get(), impl_->partial_path, 0, 0);
    impl_->file.close("closing");
    publish_synced(impl_->partial_path, impl_->final_path);
    impl_->committed = true;
  });
}

// ---- reader --------------------------------------------------------------------------------

struct CheckpointReader::Impl {
  std::string path;
  hdf5::Handle file;

  template <class F>
  auto guarded(F&& fn) const {
    return one_line_errors(path + ": not a readable checkpoint: ", std::forward<F>(fn));
  }
  [[noreturn]] void mismatch(const std::string& what) const {
    throw InputError(path + ": the checkpoint does not fit the scene: " + what +
                     " (was FrostMPM or a plugin changed since it was written?)");
  }
};

CheckpointReader::CheckpointReader(const std::string& dir) : impl_(std::make_unique<Impl>()) {
  impl_->path = checkpoint_path(dir);
  std::error_code ec;
  if (!fs::exists(impl_->path, ec))
    throw InputError(dir + ": no checkpoint.h5 to restart from (none was written yet, or the run finished)");
  impl_->guarded([&] {
    impl_->file = hdf5::open_file(impl_->path, /*writable=*/false);
    const auto format = hdf5::read_integer_attribute(impl_->file.get(), "format");
    if (format != kFormat)
      throw InputError(impl_->path + ": checkpoint format " + std::to_string(format) + ", this FrostMPM reads " +
                       std::to_string(kFormat));
  });
}

CheckpointReader::~CheckpointReader() = default;

SceneSource CheckpointReader::scene() const {
  return impl_->guarded([&] {
    const hdf5::Handle group = hdf5::open_group(impl_->file.get(), "scene");
    SceneSource scene;
    const auto path = hdf5::read_strings(group.get(), "path");
    const auto text = hdf5::read_strings(group.get(), "text");
    if (path.size() != 1 || text.size() != 1) throw std::runtime_error("scene path or text missing");
    scene.path = path[0];
    scene.text = text[0];
    scene.overrides = hdf5::read_strings(group.get(), "overrides");
    scene.plugin_paths = hdf5::read_strings(group.get(), "plugin_paths");
    return scene;
  });
}

LoopState CheckpointReader::loop() const {
  return impl_->guarded([&] {
    const hdf5::Handle group = hdf5::open_group(impl_->file.get(), "loop");
    LoopState loop;
    for (const auto& [name, value] : loop_reals(loop)) *value = hdf5::read_real_attribute(group.get(), name);
    for (const auto& [name, value] : loop_integers(loop)) *value = hdf5::read_integer_attribute(group.get(), name);
    const hdf5::Handle stages = hdf5::open_group(group.get(), "stage_seconds");
    for (const auto& name : hdf5::attribute_names(stages.get()))
      loop.statistics.stage_seconds[name] = hdf5::read_real_attribute(stages.get(), name);
    return loop;
  });
}

void CheckpointReader::read(ParticleStore& particles) const {
  impl_->guarded([&] {
    const hdf5::Handle group = hdf5::open_group(impl_->file.get(), "particles");
    const auto count = hdf5::read_integer_attribute(group.get(), "count");
    if (count != static_cast<std::int64_t>(particles.size()))
      impl_->mismatch("it holds " + std::to_string(count) + " particles, the scene makes " +
                      std::to_string(particles.size()));
    const auto ranges = hdf5::read_integers(group.get(), "ranges");
    std::vector<std::int64_t> expected;
    for (const auto& r : particles.ranges())
      expected.insert(expected.end(), {std::int64_t(r.begin), std::int64_t(r.end), std::int64_t(r.material)});
    if (ranges != expected) impl_->mismatch("its particle ranges or materials differ from the scene's");
    const hdf5::Handle fields = hdf5::open_group(group.get(), "fields");
    const auto stored = hdf5::child_names(fields.get());
    if (stored != particles.field_names())
      impl_->mismatch("it stores the fields " + list_text(stored) + ", the scene has " +
                      list_text(particles.field_names()));
    for (const auto& name : stored) {
      const int components = hdf5::dataset_components(fields.get(), name, 0);
      if (components != particles.components(name))
        impl_->mismatch("field " + name + " has " + std::to_string(components) + " components, the scene's " +
                        std::to_string(particles.components(name)));
      hdf5::read_reals(fields.get(), name, particles.field(name));
    }
  });
}

std::optional<std::vector<double>> CheckpointReader::particle_field(const std::string& name) const {
  return impl_->guarded([&]() -> std::optional<std::vector<double>> {
    const hdf5::Handle group = hdf5::open_group(impl_->file.get(), "particles");
    const hdf5::Handle fields = hdf5::open_group(group.get(), "fields");
    const auto stored = hdf5::child_names(fields.get());
    if (std::find(stored.begin(), stored.end(), name) == stored.end()) return std::nullopt;
    const auto count = static_cast<std::size_t>(hdf5::read_integer_attribute(group.get(), "count"));
    if (hdf5::dataset_components(fields.get(), name, 0) != 1) impl_->mismatch("field " + name + " is not a scalar");
    std::vector<double> values(count);
    hdf5::read_reals(fields.get(), name, values);
    return values;
  });
}

std::vector<std::string> CheckpointReader::physics_keys() const {
  return impl_->guarded([&] {
    const hdf5::Handle group = hdf5::open_group(impl_->file.get(), "physics");
    return hdf5::child_names(group.get());
  });
}

void CheckpointReader::read_physics(const std::string& key, const std::vector<PersistentArray>& arrays) const {
  impl_->guarded([&] {
    const hdf5::Handle all = hdf5::open_group(impl_->file.get(), "physics");
    if (!hdf5::exists(all.get(), key)) impl_->mismatch("it has no state of physics '" + key + "'");
    const hdf5::Handle group = hdf5::open_group(all.get(), key);
    const auto stored = hdf5::child_names(group.get());
    std::vector<std::string> wanted;
    for (const auto& array : arrays) wanted.push_back(array.name);
    if (std::set<std::string>(stored.begin(), stored.end()) != std::set<std::string>(wanted.begin(), wanted.end()))
      impl_->mismatch("physics '" + key + "' stored the arrays " + list_text(stored) + ", it now keeps " +
                      list_text(wanted));
    for (const auto& array : arrays) {
      const auto shape = hdf5::dataset_shape(group.get(), array.name);
      array.values->resize(shape.empty() ? 0 : shape[0]);
      hdf5::read_reals(group.get(), array.name, *array.values);
    }
  });
}

}  // namespace frostmpm
