#include "frostmpm/io/particle_field_reader.hpp"

#include <algorithm>
#include <filesystem>
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
    for (const auto& name : hdf5::child_names(file)) {
      if (name.rfind("step_", 0) != 0) continue;
      // A frame a crash cut short (no readable attributes or coordinates) is skipped.
      try {
        const hdf5::Handle group = hdf5::open_group(file, name);
        Frame f;
        f.group = name;
        f.time = hdf5::read_real_attribute(group.get(), "time");
        f.step = static_cast<long>(hdf5::read_integer_attribute(group.get(), "step"));
        f.count = static_cast<std::size_t>(hdf5::read_integer_attribute(group.get(), "count"));
        hdf5::dataset_shape(group.get(), "coordinates");
        impl_->frames.push_back(f);
      } catch (const std::runtime_error&) {
      }
    }
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(impl_->path + " is not a readable FrostMPM field file (" + e.what() + ")");
  }
  std::sort(impl_->frames.begin(), impl_->frames.end(),
            [](const Frame& a, const Frame& b) { return a.step < b.step; });
  if (impl_->frames.empty()) throw std::runtime_error(impl_->path + " holds no complete frame");
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

int ParticleFieldReader::components(const Frame& frame, const std::string& field) const {
  const hdf5::QuietErrors quiet;
  const hdf5::Handle group = hdf5::open_group(impl_->file.get(), frame.group);
  if (!hdf5::exists(group.get(), field)) {
    std::string have;
    for (const auto& name : field_names(frame)) have += (have.empty() ? "" : ", ") + name;
    throw std::runtime_error("the frame at t = " + std::to_string(frame.time) + " s of " + impl_->path +
                             " has no field '" + field + "'; it has: " + (have.empty() ? "none" : have));
  }
  const auto shape = hdf5::dataset_shape(group.get(), field);
  return hdf5::dataset_components(group.get(), field, shape.size() == 2 ? static_cast<int>(shape[1]) : 1);
}

std::vector<double> ParticleFieldReader::values(const Frame& frame, const std::string& field) const {
  const int c = components(frame, field);
  const hdf5::QuietErrors quiet;
  const hdf5::Handle group = hdf5::open_group(impl_->file.get(), frame.group);
  return read_columns(group.get(), field, frame.count, std::size_t(c));
}

}  // namespace frostmpm
