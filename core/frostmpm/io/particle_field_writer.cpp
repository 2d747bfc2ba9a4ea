#include "frostmpm/io/particle_field_writer.hpp"

#include <hdf5.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "frostmpm/io/hdf5_support.hpp"
#include "frostmpm/io/output_dir.hpp"
#include "frostmpm/io/particle_field_reader.hpp"
#include "frostmpm/config/units.hpp"

namespace frostmpm {

namespace {

constexpr const char* kH5Name = "fields.h5";
constexpr const char* kXdmfName = "fields.xdmf";

// ---- validation ----------------------------------------------------------------------------

bool valid_field_name(const std::string& name) {
  if (name.empty() || name.size() > 255 || name.front() == '.' || name.front() == '-') return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return false;
  }
  return name != "coordinates" && name != "connectivity";
}

void require_finite(const double* data, std::size_t count, int components, const std::string& what, long step) {
  const std::size_t n = count * static_cast<std::size_t>(components);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(data[i])) {
      throw std::runtime_error("ParticleFieldWriter: non-finite value " + std::to_string(data[i]) + " in " + what +
                               " (particle " + std::to_string(i / components) + ", component " +
                               std::to_string(i % components) + ") at step " + std::to_string(step));
    }
  }
}

// ---- XDMF ----------------------------------------------------------------------------------

/// Shortest text that reads back as exactly `value`.
std::string number_text(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

/// XDMF attribute type for a field of `components` values per particle, and how many columns
/// the stored dataset has (2-vectors are padded to 3).
std::pair<const char*, int> attribute_layout(int components) {
  switch (components) {
    case 1: return {"Scalar", 1};
    case 2:
    case 3: return {"Vector", 3};
    case 6: return {"Tensor6", 6};
    case 9: return {"Tensor", 9};
    default: return {"Matrix", components};
  }
}

std::string dimensions_text(std::size_t count, int columns) {
  return columns == 1 ? std::to_string(count) : std::to_string(count) + " " + std::to_string(columns);
}

std::string data_item(std::size_t count, int columns, const char* number_type, int precision,
                      const std::string& h5_path) {
  return "<DataItem Dimensions=\"" + dimensions_text(count, columns) + "\" NumberType=\"" + number_type +
         "\" Precision=\"" + std::to_string(precision) + "\" Format=\"HDF\">" + kH5Name + ":" + h5_path +
         "</DataItem>";
}

/// What fields.xdmf says about one stored frame.
struct FrameLayout {
  std::string group;
  double time = 0;
  std::size_t count = 0;
  bool wide_ids = false;  ///< connectivity stored as int64
  std::vector<std::pair<std::string, int>> fields;  ///< name, components
};

/// The XDMF <Grid> element of one frame.
std::string xdmf_grid(const FrameLayout& f) {
  const std::string path = "/" + f.group;
  std::string grid;
  grid += "      <Grid Name=\"" + f.group + "\" GridType=\"Uniform\">\n";
  grid += "        <Time Value=\"" + number_text(f.time) + "\"/>\n";
  grid += "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" + std::to_string(f.count) +
          "\" NodesPerElement=\"1\">\n          " +
          data_item(f.count, 1, "Int", f.wide_ids ? 8 : 4, path + "/connectivity") + "\n        </Topology>\n";
  grid += "        <Geometry GeometryType=\"XYZ\">\n          " +
          data_item(f.count, 3, "Float", 8, path + "/coordinates") + "\n        </Geometry>\n";
  for (const auto& [name, components] : f.fields) {
    const auto [type, columns] = attribute_layout(components);
    grid += "        <Attribute Name=\"" + name + "\" AttributeType=\"" + type + "\" Center=\"Node\">\n          " +
            data_item(f.count, columns, "Float", 8, path + "/" + name) + "\n        </Attribute>\n";
  }
  grid += "      </Grid>\n";
  return grid;
}

/// Reads back the layout of a frame group written by ParticleFieldWriter (fields in name order).
FrameLayout read_layout(hdf5::Id file, const std::string& group_name) {
  const hdf5::Handle group = hdf5::open_group(file, group_name);
  FrameLayout f;
  f.group = group_name;
  f.time = hdf5::read_real_attribute(group.get(), "time");
  f.count = static_cast<std::size_t>(hdf5::read_integer_attribute(group.get(), "count"));
  f.wide_ids = hdf5::dataset_element_size(group.get(), "connectivity") == 8;
  hdf5::dataset_shape(group.get(), "coordinates");  // present, or the frame is not complete
  for (const auto& name : hdf5::child_names(group.get())) {
    if (name == "coordinates" || name == "connectivity") continue;
    const auto shape = hdf5::dataset_shape(group.get(), name);
    const int stored = shape.size() == 2 ? static_cast<int>(shape[1]) : 1;
    f.fields.emplace_back(name, hdf5::dataset_components(group.get(), name, stored));
  }
  return f;
}

void check_dim(int dim) {
  if (dim != 2 && dim != 3)
    throw std::invalid_argument("ParticleFieldWriter: dim must be 2 or 3, got " + std::to_string(dim));
}

/// A new, empty fields file: what a run starts with and what a restart copies kept frames into.
hdf5::Handle create_fields_file(const std::string& path, int dim) {
  hdf5::Handle file = hdf5::create_file(path);
  hdf5::write_attribute(file.get(), "dim", dim);
  return file;
}

}  // namespace

// ---- writer --------------------------------------------------------------------------------

struct ParticleFieldWriter::Impl {
  std::string dir;
  int dim = 3;
  hdf5::Handle file;
  std::string xdmf_grids;  ///< the <Grid> elements of every complete frame, in order
  std::size_t frames = 0;
  std::set<long> steps;

  Impl(const std::string& folder, int dimension) : dir(folder.empty() ? std::string(".") : folder), dim(dimension) {}

  std::string h5_path() const { return dir + "/" + kH5Name; }
  std::string xdmf_path() const { return dir + "/" + kXdmfName; }

  ~Impl() {
    const hdf5::QuietErrors quiet;
    file = hdf5::Handle();
    H5Eclear2(H5E_DEFAULT);
  }

  void flush() const { hdf5::check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "flushing " + h5_path()); }

  void write_xdmf(const std::string& when = "") const {
    write_file_atomically(xdmf_path(),
                          "<?xml version=\"1.0\" ?>\n"
                          "<Xdmf Version=\"3.0\">\n"
                          "  <Domain>\n"
                          "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n" +
                              xdmf_grids +
                              "    </Grid>\n"
                              "  </Domain>\n"
                              "</Xdmf>\n",
                          when);
  }

  /// Runs `fn` (HDF5 work on fields.h5); a failure becomes one OutputError line naming the file.
  template <class F>
  void guarded(const std::string& when, F&& fn) {
    const hdf5::QuietErrors quiet;
    try {
      fn();
    } catch (const OutputError&) {
      throw;
    } catch (const std::runtime_error& e) {
      H5Eclear2(H5E_DEFAULT);
      throw OutputError(h5_path(), e.what(), when);
    }
  }

  void add_to_xdmf(const FrameLayout& layout, long step) {
    steps.insert(step);
    xdmf_grids += xdmf_grid(layout);
    ++frames;
  }

  /// Writes the frame's group; returns its layout.
  FrameLayout write_group(const std::string& group_name, double time, long step, std::size_t count,
                          const double* positions, const std::vector<FieldView>& fields) const {
    const hdf5::Handle group = hdf5::create_group(file.get(), group_name);
    hdf5::write_attribute(group.get(), "time", time);
    hdf5::write_attribute(group.get(), "step", static_cast<std::int64_t>(step));
    hdf5::write_attribute(group.get(), "count", static_cast<std::int64_t>(count));
    FrameLayout layout{group_name, time, count, false, {}};

    // Polyvertex cells: ParaView's Xdmf3 reader builds cells only from an explicit connectivity.
    layout.wide_ids = count > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
    if (layout.wide_ids) {
      std::vector<std::int64_t> ids(count);
      std::iota(ids.begin(), ids.end(), std::int64_t{0});
      hdf5::write_dataset(group.get(), "connectivity", H5T_STD_I64LE, H5T_NATIVE_INT64, {count}, ids.data());
    } else {
      std::vector<std::int32_t> ids(count);
      std::iota(ids.begin(), ids.end(), std::int32_t{0});
      hdf5::write_dataset(group.get(), "connectivity", H5T_STD_I32LE, H5T_NATIVE_INT32, {count}, ids.data());
    }

    // Geometry: always XYZ (z = 0 in 2D), the form every ParaView reader handles.
    std::vector<double> xyz(count * 3, 0.0);
    for (std::size_t p = 0; p < count; ++p)
      for (int c = 0; c < dim; ++c) xyz[3 * p + c] = positions[dim * p + c];
    hdf5::write_dataset(group.get(), "coordinates", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {count, 3}, xyz.data(), dim, "m");

    for (const auto& field : fields) {
      const int columns = attribute_layout(field.components).second;
      const double* data = field.data;
      std::vector<double> padded;
      if (columns != field.components) {  // 2-vector stored as 3
        padded.assign(count * columns, 0.0);
        for (std::size_t p = 0; p < count; ++p)
          for (int c = 0; c < field.components; ++c) padded[columns * p + c] = field.data[field.components * p + c];
        data = padded.data();
      }
      const std::vector<std::size_t> dims =
          columns == 1 ? std::vector<std::size_t>{count} : std::vector<std::size_t>{count, std::size_t(columns)};
      hdf5::write_dataset(group.get(), field.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, data, field.components,
                          field.unit);
      layout.fields.emplace_back(field.name, field.components);
    }
    return layout;
  }
};

ParticleFieldWriter::ParticleFieldWriter(const std::string& dir, int dim) {
  check_dim(dim);
  impl_ = std::make_unique<Impl>(dir, dim);
  std::error_code ec;
  std::filesystem::create_directories(impl_->dir, ec);
  if (ec) throw std::runtime_error("ParticleFieldWriter: cannot create folder " + impl_->dir + ": " + ec.message());

  // Readers (ParaView, scripts/read_fields.py) may open the file while the run is going on, so
  // it is created without HDF5 file locking.
  impl_->guarded("", [&] {
    impl_->file = create_fields_file(impl_->h5_path(), dim);
    impl_->flush();
  });
  // Replace any fields.xdmf of an earlier run at once: it would point into the truncated file.
  impl_->write_xdmf();
}

ParticleFieldWriter::ParticleFieldWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ParticleFieldWriter ParticleFieldWriter::reopen(const std::string& dir, int dim, std::size_t keep_frames) {
  check_dim(dim);
  auto impl = std::make_unique<Impl>(dir, dim);
  const hdf5::QuietErrors quiet;
  impl->file = hdf5::open_file(impl->h5_path(), /*writable=*/true);
  const hdf5::Id file = impl->file.get();
  const auto stored_dim = hdf5::read_integer_attribute(file, "dim");
  if (stored_dim != dim)
    throw std::runtime_error("ParticleFieldWriter: " + impl->h5_path() + " holds " + std::to_string(stored_dim) +
                             "-D frames, not " + std::to_string(dim) + "-D");
  // A frame a SIGKILL cut short may have its link but no readable group, step or coordinates:
  // it is newer than every complete frame (frames are written in order), so it is dropped with
  // the rest.
  std::vector<std::string> torn;
  const auto stored = ParticleFieldReader::list_frames(file, &torn);
  if (stored.size() < keep_frames)
    throw std::runtime_error("ParticleFieldWriter: " + impl->h5_path() + " holds " + std::to_string(stored.size()) +
                             " frames, fewer than the " + std::to_string(keep_frames) + " to keep");
  if (torn.empty()) {
    for (std::size_t i = keep_frames; i < stored.size(); ++i)
      hdf5::check(H5Ldelete(file, stored[i].group.c_str(), H5P_DEFAULT), "deleting " + stored[i].group);
  } else {
    // HDF5 cannot delete a link whose object header was left half written (deleting updates
    // the header), so the frames to keep are copied into a new file that replaces this one as
    // a checkpoint is published (until then fields.h5 is as the kill left it).
    const std::string partial = impl->h5_path() + ".partial";
    try {
      {
        const hdf5::Handle copy = create_fields_file(partial, dim);
        for (std::size_t i = 0; i < keep_frames; ++i)
          hdf5::check(H5Ocopy(file, stored[i].group.c_str(), copy.get(), stored[i].group.c_str(), H5P_DEFAULT,
                              H5P_DEFAULT),
                      "copying " + stored[i].group + " out of a file with the cut-short frame " + torn.front());
      }
      impl->file = hdf5::Handle();
      publish_synced(partial, impl->h5_path());
    } catch (...) {
      std::error_code ignored;
      std::filesystem::remove(partial, ignored);  // fields.h5 stays as it was
      throw;
    }
    impl->file = hdf5::open_file(impl->h5_path(), /*writable=*/true);
  }
  for (std::size_t i = 0; i < keep_frames; ++i)
    impl->add_to_xdmf(read_layout(impl->file.get(), stored[i].group), stored[i].step);
  impl->flush();
  impl->write_xdmf();
  return ParticleFieldWriter(std::move(impl));
}

ParticleFieldWriter::~ParticleFieldWriter() = default;
ParticleFieldWriter::ParticleFieldWriter(ParticleFieldWriter&&) noexcept = default;
ParticleFieldWriter& ParticleFieldWriter::operator=(ParticleFieldWriter&&) noexcept = default;

void ParticleFieldWriter::write(double time, long step, std::size_t count, const double* positions,
                                const std::vector<FieldView>& fields) {
  Impl& m = *impl_;
  // Everything is checked before the file is touched, so a refused frame leaves no trace.
  if (!std::isfinite(time))
    throw std::invalid_argument("ParticleFieldWriter: non-finite time at step " + std::to_string(step));
  if (step < 0) throw std::invalid_argument("ParticleFieldWriter: negative step " + std::to_string(step));
  if (m.steps.count(step))
    throw std::invalid_argument("ParticleFieldWriter: step " + std::to_string(step) + " was already written");
  if (count > 0 && !positions) throw std::invalid_argument("ParticleFieldWriter: positions is null");
  std::set<std::string> names;
  for (const auto& field : fields) {
    if (!valid_field_name(field.name))
      throw std::invalid_argument("ParticleFieldWriter: invalid field name '" + field.name +
                                  "' (use letters, digits, '_', '-', '.'; not coordinates/connectivity)");
    if (!names.insert(field.name).second)
      throw std::invalid_argument("ParticleFieldWriter: field '" + field.name + "' given twice");
    if (field.components < 1)
      throw std::invalid_argument("ParticleFieldWriter: field '" + field.name + "' has " +
                                  std::to_string(field.components) + " components");
    if (count > 0 && !field.data)
      throw std::invalid_argument("ParticleFieldWriter: field '" + field.name + "' has no data");
    if (!units::is_output_unit(field.unit))
      throw std::invalid_argument("ParticleFieldWriter: field '" + field.name + "' has the unit '" + field.unit +
                                  "' (give one such as \"degC\", or \"1\" when dimensionless)");
  }
  if (count > 0) {
    require_finite(positions, count, m.dim, "positions", step);
    for (const auto& field : fields) require_finite(field.data, count, field.components, "field '" + field.name + "'", step);
  }

  char name_buffer[32];
  std::snprintf(name_buffer, sizeof name_buffer, "step_%06ld", step);
  const std::string group_name = name_buffer;

  // The frame's data (ids, coordinates, fields) and the growth of the root group's name heap.
  std::uintmax_t bytes = count * (8 + 3 * 8) + 64 * m.frames;
  for (const auto& field : fields) bytes += count * attribute_layout(field.components).second * 8;

  const std::string when = at_step(step, time);
  FrameLayout layout;
  m.guarded(when, [&] {
    // A full disk fails here, before HDF5 has changed the file and its earlier frames.
    hdf5::reserve(m.file.get(), m.h5_path(), bytes, fields.size() + 3);
    try {
      layout = m.write_group(group_name, time, step, count, positions, fields);
    } catch (...) {
      // Drop the half-written group (best effort); the XDMF never referenced it.
      if (H5Lexists(m.file.get(), group_name.c_str(), H5P_DEFAULT) > 0)
        H5Ldelete(m.file.get(), group_name.c_str(), H5P_DEFAULT);
      throw;
    }
    m.flush();
    hdf5::reserve(m.file.get(), m.h5_path(), 0, 0);
  });
  m.add_to_xdmf(layout, step);
  m.write_xdmf(when);
}

std::size_t ParticleFieldWriter::frames() const { return impl_->frames; }
std::string ParticleFieldWriter::h5_path() const { return impl_->h5_path(); }
std::string ParticleFieldWriter::xdmf_path() const { return impl_->xdmf_path(); }

}  // namespace frostmpm
