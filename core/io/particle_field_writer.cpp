#include "frostmpm/io/particle_field_writer.hpp"

#include <hdf5.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace frostmpm {

namespace {

constexpr const char* kH5Name = "fields.h5";
constexpr const char* kXdmfName = "fields.xdmf";

// ---- HDF5 error handling -------------------------------------------------------------------

/// While alive, HDF5 does not print its error stack to stderr; failures are reported through
/// the exceptions below instead (with the stack's most specific messages).
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

herr_t collect_error(unsigned, const H5E_error2_t* err, void* out) {
  auto& messages = *static_cast<std::vector<std::string>*>(out);
  if (err && err->desc && *err->desc) messages.emplace_back(err->desc);
  return 0;
}

/// The current HDF5 error stack, most specific message first (at most three), then clears it.
std::string hdf5_error_text() {
  std::vector<std::string> messages;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &messages);
  H5Eclear2(H5E_DEFAULT);
  std::string text;
  for (std::size_t i = 0; i < messages.size() && i < 3; ++i) text += (i ? "; " : "") + messages[i];
  return text.empty() ? std::string("unknown HDF5 error") : text;
}

[[noreturn]] void hdf5_fail(const std::string& what) {
  throw std::runtime_error("ParticleFieldWriter: " + what + " failed: " + hdf5_error_text());
}

void check(herr_t status, const std::string& what) {
  if (status < 0) hdf5_fail(what);
}

/// Owns an HDF5 identifier.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer, const std::string& what) : id_(id), closer_(closer) {
    if (id_ < 0) hdf5_fail(what);
  }
  ~Handle() {
    if (id_ >= 0) closer_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  Closer closer_;
};

template <class T>
void write_scalar_attribute(hid_t object, const char* name, hid_t type, T value) {
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose, "H5Screate");
  const Handle attr(H5Acreate2(object, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
                    std::string("creating attribute ") + name);
  check(H5Awrite(attr.get(), type, &value), std::string("writing attribute ") + name);
}

/// Creates dataset `name` in `group` with the given shape and writes `data` (may be null when
/// the dataset is empty).
void write_dataset(hid_t group, const std::string& name, hid_t file_type, hid_t mem_type,
                   const std::vector<hsize_t>& dims, const void* data, int components_attribute) {
  const Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose,
                     "H5Screate_simple for " + name);
  const Handle dset(H5Dcreate2(group, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                    H5Dclose, "creating dataset " + name);
  if (dims.front() > 0) check(H5Dwrite(dset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "writing " + name);
  if (components_attribute > 0) write_scalar_attribute(dset.get(), "components", H5T_NATIVE_INT, components_attribute);
}

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

}  // namespace

// ---- writer --------------------------------------------------------------------------------

struct ParticleFieldWriter::Impl {
  std::string dir;
  int dim = 3;
  hid_t file = H5I_INVALID_HID;
  std::string xdmf_grids;  ///< the <Grid> elements of every complete frame, in order
  std::size_t frames = 0;
  std::set<long> steps;

  std::string h5_path() const { return dir + "/" + kH5Name; }
  std::string xdmf_path() const { return dir + "/" + kXdmfName; }

  ~Impl() {
    if (file >= 0) {
      const QuietHdf5Errors quiet;
      H5Fclose(file);
      H5Eclear2(H5E_DEFAULT);
    }
  }

  void write_xdmf() const {
    const std::string final_path = xdmf_path();
    const std::string partial_path = final_path + ".partial";
    {
      std::ofstream out(partial_path, std::ios::binary | std::ios::trunc);
      out << "<?xml version=\"1.0\" ?>\n"
             "<Xdmf Version=\"3.0\">\n"
             "  <Domain>\n"
             "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n"
          << xdmf_grids
          << "    </Grid>\n"
             "  </Domain>\n"
             "</Xdmf>\n";
      out.close();
      if (!out) throw std::runtime_error("ParticleFieldWriter: cannot write " + partial_path);
    }
    std::error_code ec;
    std::filesystem::rename(partial_path, final_path, ec);
    if (ec) {
      throw std::runtime_error("ParticleFieldWriter: cannot rename " + partial_path + " to " + final_path + ": " +
                               ec.message());
    }
  }

  /// Writes the frame's group; returns its XDMF <Grid> element.
  std::string write_group(const std::string& group_name, double time, long step, std::size_t count,
                          const double* positions, const std::vector<FieldView>& fields) const {
    const std::string path = "/" + group_name;
    const Handle group(H5Gcreate2(file, group_name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                       "creating group " + group_name);
    write_scalar_attribute(group.get(), "time", H5T_NATIVE_DOUBLE, time);
    write_scalar_attribute(group.get(), "step", H5T_NATIVE_INT64, static_cast<std::int64_t>(step));
    write_scalar_attribute(group.get(), "count", H5T_NATIVE_INT64, static_cast<std::int64_t>(count));

    const hsize_t n = count;
    std::string grid;
    grid += "      <Grid Name=\"" + group_name + "\" GridType=\"Uniform\">\n";
    grid += "        <Time Value=\"" + number_text(time) + "\"/>\n";

    // Polyvertex cells: ParaView's Xdmf3 reader builds cells only from an explicit connectivity.
    const bool wide = count > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
    if (wide) {
      std::vector<std::int64_t> ids(count);
      std::iota(ids.begin(), ids.end(), std::int64_t{0});
      write_dataset(group.get(), "connectivity", H5T_STD_I64LE, H5T_NATIVE_INT64, {n}, ids.data(), 0);
    } else {
      std::vector<std::int32_t> ids(count);
      std::iota(ids.begin(), ids.end(), std::int32_t{0});
      write_dataset(group.get(), "connectivity", H5T_STD_I32LE, H5T_NATIVE_INT32, {n}, ids.data(), 0);
    }
    grid += "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" + std::to_string(count) +
            "\" NodesPerElement=\"1\">\n          " + data_item(count, 1, "Int", wide ? 8 : 4, path + "/connectivity") +
            "\n        </Topology>\n";

    // Geometry: always XYZ (z = 0 in 2D), the form every ParaView reader handles.
    std::vector<double> xyz(count * 3, 0.0);
    for (std::size_t p = 0; p < count; ++p)
      for (int c = 0; c < dim; ++c) xyz[3 * p + c] = positions[dim * p + c];
    write_dataset(group.get(), "coordinates", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n, 3}, xyz.data(), dim);
    grid += "        <Geometry GeometryType=\"XYZ\">\n          " +
            data_item(count, 3, "Float", 8, path + "/coordinates") + "\n        </Geometry>\n";

    for (const auto& field : fields) {
      const auto [type, columns] = attribute_layout(field.components);
      if (columns == 1) {
        write_dataset(group.get(), field.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n}, field.data, 1);
      } else if (columns != field.components) {  // padded 2-vector
        std::vector<double> padded(count * columns, 0.0);
        for (std::size_t p = 0; p < count; ++p)
          for (int c = 0; c < field.components; ++c)
            padded[columns * p + c] = field.data[field.components * p + c];
        write_dataset(group.get(), field.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                      {n, static_cast<hsize_t>(columns)}, padded.data(), field.components);
      } else {
        write_dataset(group.get(), field.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                      {n, static_cast<hsize_t>(columns)}, field.data, field.components);
      }
      grid += "        <Attribute Name=\"" + field.name + "\" AttributeType=\"" + type + "\" Center=\"Node\">\n          " +
              data_item(count, columns, "Float", 8, path + "/" + field.name) + "\n        </Attribute>\n";
    }
    grid += "      </Grid>\n";
    return grid;
  }
};

ParticleFieldWriter::ParticleFieldWriter(const std::string& dir, int dim) : impl_(std::make_unique<Impl>()) {
  if (dim != 2 && dim != 3)
    throw std::invalid_argument("ParticleFieldWriter: dim must be 2 or 3, got " + std::to_string(dim));
  impl_->dir = dir.empty() ? std::string(".") : dir;
  impl_->dim = dim;
  std::error_code ec;
  std::filesystem::create_directories(impl_->dir, ec);
  if (ec) throw std::runtime_error("ParticleFieldWriter: cannot create folder " + impl_->dir + ": " + ec.message());

  const QuietHdf5Errors quiet;
  const Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "H5Pcreate");
  // Readers (ParaView, scripts/read_fields.py) may open the file while the run is going on; with
  // HDF5's default file locking they would be refused until the writer closes it.
#if H5_VERSION_GE(1, 10, 7)
  check(H5Pset_file_locking(fapl.get(), 0, 1), "H5Pset_file_locking");
#endif
  // The default (earliest) file format is kept on purpose: newer superblocks mark a file "open
  // for writing" and readers refuse it after a crash until h5clear is run.
  impl_->file = H5Fcreate(impl_->h5_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
  if (impl_->file < 0) hdf5_fail("creating " + impl_->h5_path());
  write_scalar_attribute(impl_->file, "dim", H5T_NATIVE_INT, dim);
  check(H5Fflush(impl_->file, H5F_SCOPE_GLOBAL), "flushing " + impl_->h5_path());
  // Replace any fields.xdmf of an earlier run at once: it would point into the truncated file.
  impl_->write_xdmf();
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
  }
  if (count > 0) {
    require_finite(positions, count, m.dim, "positions", step);
    for (const auto& field : fields) require_finite(field.data, count, field.components, "field '" + field.name + "'", step);
  }

  char name_buffer[32];
  std::snprintf(name_buffer, sizeof name_buffer, "step_%06ld", step);
  const std::string group_name = name_buffer;

  const QuietHdf5Errors quiet;
  std::string grid;
  try {
    grid = m.write_group(group_name, time, step, count, positions, fields);
  } catch (...) {
    // Drop the half-written group (best effort); the XDMF never referenced it.
    if (H5Lexists(m.file, group_name.c_str(), H5P_DEFAULT) > 0) H5Ldelete(m.file, group_name.c_str(), H5P_DEFAULT);
    H5Eclear2(H5E_DEFAULT);
    throw;
  }
  check(H5Fflush(m.file, H5F_SCOPE_GLOBAL), "flushing " + m.h5_path());
  m.steps.insert(step);
  m.xdmf_grids += grid;
  ++m.frames;
  m.write_xdmf();
}

std::size_t ParticleFieldWriter::frames() const { return impl_->frames; }
std::string ParticleFieldWriter::h5_path() const { return impl_->h5_path(); }
std::string ParticleFieldWriter::xdmf_path() const { return impl_->xdmf_path(); }

}  // namespace frostmpm
