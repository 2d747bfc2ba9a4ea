#include "frostmpm/io/particle_field_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "frostmpm/io/hdf5_support.hpp"

namespace frostmpm {

struct ParticleFieldReader::Impl {
  std::string path;
  hdf5::Handle file;
  int dim = 2;
  std::vector<Frame> frames;
};

ParticleFieldReader::ParticleFieldReader(const std::string& dir) : impl_(std::make_unique<Impl>()) {
  impl_->path = (std::filesystem::path(dir) / "fields.h5").string();
  if (!std::filesystem::is_regular_file(impl_->path))
    throw std::runtime_error("there is no " + impl_->path + " (give the output folder of a run that wrote fields)");
  const hdf5::QuietErrors quiet;
  try {
    impl_->file = hdf5::open_file(impl_->path, /*writable=*/false);
    const hdf5::Id file = impl_->file.get();
    impl_->dim = static_cast<int>(hdf5::read_integer_attribute(file, "dim"));
    impl_->frames = list_frames(file);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(impl_->path + " is not a readable FrostMPM field file (" + e.what() + ")");
  }
  if (impl_->frames.empty()) throw std::runtime_error(impl_->path + " holds no complete frame");
}

std::vector<ParticleFieldReader::Frame> ParticleFieldReader::list_frames(std::int64_t file,
                                                                          std::vector<std::string>* torn) {
  std::vector<Frame> frames;
  for (const auto& name : hdf5::child_names(file)) {
    if (name.rfind("step_", 0) != 0) continue;
    try {
      const hdf5::Handle group = hdf5::open_group(file, name);
      Frame f;
      f.group = name;
      f.time = hdf5::read_real_attribute(group.get(), "time");
      f.step = static_cast<long>(hdf5::read_integer_attribute(group.get(), "step"));
      f.count = static_cast<std::size_t>(hdf5::read_integer_attribute(group.get(), "count"));
      hdf5::dataset_shape(group.get(), "coordinates");
      frames.push_back(f);
    } catch (const std::runtime_error&) {
      if (torn) torn->push_back(name);
    }
  }
  // Group names sort by step only up to six digits.
  std::sort(frames.begin(), frames.end(), [](const Frame& a, const Frame& b) { return a.step < b.step; });
  return frames;
}

ParticleFieldReader::~ParticleFieldReader() = default;

int ParticleFieldReader::dim() const { return impl_->dim; }
std::string ParticleFieldReader::path() const { return impl_->path; }
const std::vector<ParticleFieldReader::Frame>& ParticleFieldReader::frames() const { return impl_->frames; }

namespace {
/// Reads a count × columns dataset and keeps its first `keep` columns.
std::vector<double> read_columns(hdf5::Id group, const std::string& name, std::size_t count, std::size_t keep) {
  const auto shape = hdf5::dataset_shape(group, name);
  const std::size_t columns = shape.size() == 2 ? shape[1] : 1;
  std::vector<double> all(count * columns);
  hdf5::read_reals(group, name, all);
  if (columns == keep) return all;
  std::vector<double> kept(count * keep);
  for (std::size_t p = 0; p < count; ++p)
    std::copy_n(all.begin() + std::ptrdiff_t(p * columns), keep, kept.begin() + std::ptrdiff_t(p * keep));
  return kept;
}
}  // namespace

std::vector<double> ParticleFieldReader::positions(const Frame& frame) const {
  const hdf5::QuietErrors quiet;
  const hdf5::Handle group = hdf5::open_group(impl_->file.get(), frame.group);
  return read_columns(group.get(), "coordinates", frame.count, std::size_t(impl_->dim));
}

std::vector<std::string> ParticleFieldReader::field_names(const Frame& frame) const {
  const hdf5::QuietErrors quiet;
  const hdf5::Handle group = hdf5::open_group(impl_->file.get(), frame.group);
  std::vector<std::string> names;
  for (auto& name : hdf5::child_names(group.get()))
    if (name != "coordinates" && name != "connectivity") names.push_back(std::move(name));
  return names;
}

ParticleFieldReader::Field ParticleFieldReader::field(const Frame& frame, const std::string& name) const {
  const hdf5::QuietErrors quiet;
  const hdf5::Handle group = hdf5::open_group(impl_->file.get(), frame.group);
  if (!hdf5::exists(group.get(), name)) {
    std::ostringstream msg;
    msg << "the frame at t = " << frame.time << " s of " << impl_->path << " has no field '" << name << "'; it has: ";
    const auto have = field_names(frame);
    for (std::size_t i = 0; i < have.size(); ++i) msg << (i ? ", " : "") << have[i];
    if (have.empty()) msg << "none";
    throw std::runtime_error(msg.str());
  }
  const auto shape = hdf5::dataset_shape(group.get(), name);
  Field f;
  f.components = hdf5::dataset_components(group.get(), name, shape.size() == 2 ? static_cast<int>(shape[1]) : 1);
  f.values = read_columns(group.get(), name, frame.count, std::size_t(f.components));
  return f;
}

}  // namespace frostmpm
