#include "frostmpm/io/hdf5_support.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <stdexcept>
#include <type_traits>
#include <utility>

namespace frostmpm::hdf5 {

static_assert(std::is_same_v<Id, hid_t>, "hdf5::Id must be hid_t (HDF5 >= 1.10)");
static_assert(std::is_same_v<Handle::Closer, herr_t (*)(hid_t)>);

namespace {

herr_t collect_error(unsigned, const H5E_error2_t* err, void* out) {
  auto& messages = *static_cast<std::vector<std::string>*>(out);
  if (!err || !err->desc || !*err->desc) return 0;
  // A failed system call (sec2 driver) is a long line of addresses and sizes around
  // "error message = 'No space left on device'": keep only that text.
  const std::string desc = err->desc;
  const std::string marker = "error message = '";
  const auto at = desc.find(marker);
  const auto end = at == std::string::npos ? at : desc.find('\'', at + marker.size());
  messages.push_back(end == std::string::npos ? desc : desc.substr(at + marker.size(), end - at - marker.size()));
  return 0;
}

/// The current HDF5 error stack, most specific message first (at most three), then clears it.
std::string error_text() {
  std::vector<std::string> messages;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &messages);
  H5Eclear2(H5E_DEFAULT);
  std::string text;
  for (std::size_t i = 0; i < messages.size() && i < 3; ++i) text += (i ? "; " : "") + messages[i];
  return text.empty() ? std::string("unknown HDF5 error") : text;
}

herr_t collect_name(hid_t, const char* name, const void*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}
herr_t collect_link(hid_t group, const char* name, const H5L_info_t* info, void* out) {
  return collect_name(group, name, info, out);
}
herr_t collect_attribute(hid_t object, const char* name, const H5A_info_t* info, void* out) {
  return collect_name(object, name, info, out);
}

Handle file_access() {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "H5Pcreate");
#if H5_VERSION_GE(1, 10, 7)
  check(H5Pset_file_locking(fapl.get(), 0, 1), "H5Pset_file_locking");
#endif
  return fapl;
}

template <class T>
void write_scalar_attribute(hid_t object, const std::string& name, hid_t type, T value) {
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose, "H5Screate");
  const Handle attr(H5Acreate2(object, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
                    "creating attribute " + name);
  check(H5Awrite(attr.get(), type, &value), "writing attribute " + name);
}

template <class T>
T read_scalar_attribute(hid_t object, const std::string& name, hid_t type) {
  const Handle attr(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose, "opening attribute " + name);
  const Handle space(H5Aget_space(attr.get()), H5Sclose, "H5Aget_space");
  if (H5Sget_simple_extent_npoints(space.get()) != 1)
    throw std::runtime_error("reading attribute " + name + " failed: not a single value");
  T value{};
  check(H5Aread(attr.get(), type, &value), "reading attribute " + name);
  return value;
}

Handle open_dataset(hid_t group, const std::string& name) {
  return Handle(H5Dopen2(group, name.c_str(), H5P_DEFAULT), H5Dclose, "opening dataset " + name);
}

std::size_t element_count(hid_t dataset, const std::string& name) {
  const Handle space(H5Dget_space(dataset), H5Sclose, "H5Dget_space for " + name);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) fail("counting the elements of " + name);
  return static_cast<std::size_t>(n);
}

Handle vl_string_type() {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
  check(H5Tset_size(type.get(), H5T_VARIABLE), "H5Tset_size");
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "H5Tset_cset");
  return type;
}

}  // namespace

QuietErrors::QuietErrors() {
  H5Eget_auto2(H5E_DEFAULT, &handler_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

QuietErrors::~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, handler_, data_); }

void fail(const std::string& what) { throw std::runtime_error(what + " failed: " + error_text()); }

void check(int status, const std::string& what) {
  if (status < 0) fail(what);
}

void reserve(Id file, const std::string& path, std::uintmax_t data_bytes, std::size_t objects) {
  // Generous: only reserved, the file ends up as large as HDF5 needs.
  const std::uintmax_t bytes = data_bytes + objects * 2048 + (data_bytes + objects > 0 ? 16 << 10 : 0);
  hsize_t end = 0;  // where HDF5 allocates next
  check(H5Fget_filesize(file, &end), "H5Fget_filesize");
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(std::strerror(errno));
  const int error = bytes > 0 ? ::posix_fallocate(fd, static_cast<off_t>(end), static_cast<off_t>(bytes)) : 0;
  if (bytes == 0 || error != 0) {
    const int cut = ::ftruncate(fd, static_cast<off_t>(end));  // best effort
    static_cast<void>(cut);
  }
  ::close(fd);
  if (error != 0 && error != EOPNOTSUPP && error != EINVAL) throw std::runtime_error(std::strerror(error));
}

Handle::Handle(Id id, Closer closer, const std::string& what) : id_(id), closer_(closer) {
  if (id_ < 0) fail(what);
}

Handle::Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, -1)), closer_(other.closer_) {}

Handle& Handle::operator=(Handle&& other) noexcept {
  if (this != &other) {
    reset();
    id_ = std::exchange(other.id_, -1);
    closer_ = other.closer_;
  }
  return *this;
}

void Handle::reset() {
  if (id_ >= 0) closer_(id_);
  id_ = -1;
}

void Handle::close(const std::string& what) {
  const herr_t status = id_ >= 0 ? closer_(id_) : 0;
  id_ = -1;
  check(status, what);
}

Handle create_file(const std::string& path) {
  const Handle fapl = file_access();
  // The default (earliest) file format is kept on purpose: newer superblocks mark a file "open
  // for writing" and readers refuse it after a crash until h5clear is run.
  return Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose, "creating " + path);
}

Handle open_file(const std::string& path, bool writable) {
  const Handle fapl = file_access();
  return Handle(H5Fopen(path.c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl.get()), H5Fclose,
                "opening " + path);
}

Handle create_group(Id parent, const std::string& name) {
  return Handle(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                "creating group " + name);
}

Handle open_group(Id parent, const std::string& name) {
  return Handle(H5Gopen2(parent, name.c_str(), H5P_DEFAULT), H5Gclose, "opening group " + name);
}

bool exists(Id parent, const std::string& name) {
  const htri_t found = H5Lexists(parent, name.c_str(), H5P_DEFAULT);
  if (found < 0) fail("looking up " + name);
  return found > 0;
}

std::vector<std::string> child_names(Id group) {
  std::vector<std::string> names;
  hsize_t index = 0;
  check(H5Literate(group, H5_INDEX_NAME, H5_ITER_INC, &index, collect_link, &names), "listing a group");
  return names;
}

std::vector<std::string> attribute_names(Id object) {
  std::vector<std::string> names;
  hsize_t index = 0;
  check(H5Aiterate2(object, H5_INDEX_NAME, H5_ITER_INC, &index, collect_attribute, &names), "listing attributes");
  return names;
}

void write_attribute(Id object, const std::string& name, double value) {
  write_scalar_attribute(object, name, H5T_NATIVE_DOUBLE, value);
}
void write_attribute(Id object, const std::string& name, std::int64_t value) {
  write_scalar_attribute(object, name, H5T_NATIVE_INT64, value);
}
void write_attribute(Id object, const std::string& name, int value) {
  write_scalar_attribute(object, name, H5T_NATIVE_INT, value);
}
void write_attribute(Id object, const std::string& name, const std::string& value) {
  const Handle type = vl_string_type();
  write_scalar_attribute(object, name, type.get(), value.c_str());
}
double read_real_attribute(Id object, const std::string& name) {
  return read_scalar_attribute<double>(object, name, H5T_NATIVE_DOUBLE);
}
std::int64_t read_integer_attribute(Id object, const std::string& name) {
  return read_scalar_attribute<std::int64_t>(object, name, H5T_NATIVE_INT64);
}

void write_dataset(Id group, const std::string& name, Id file_type, Id mem_type, const std::vector<std::size_t>& dims,
                   const void* data, int components_attribute, const std::string& units_attribute) {
  const std::vector<hsize_t> shape(dims.begin(), dims.end());
  const Handle space(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), H5Sclose,
                     "H5Screate_simple for " + name);
  const Handle dset(H5Dcreate2(group, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                    H5Dclose, "creating dataset " + name);
  if (H5Sget_simple_extent_npoints(space.get()) > 0)
    check(H5Dwrite(dset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "writing " + name);
  if (components_attribute > 0) write_attribute(dset.get(), "components", components_attribute);
  if (!units_attribute.empty()) write_attribute(dset.get(), "units", units_attribute);
}

std::vector<std::size_t> dataset_shape(Id group, const std::string& name) {
  const Handle dset = open_dataset(group, name);
  const Handle space(H5Dget_space(dset.get()), H5Sclose, "H5Dget_space for " + name);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) fail("reading the shape of " + name);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), "reading the shape of " + name);
  return {dims.begin(), dims.end()};
}

std::size_t dataset_element_size(Id group, const std::string& name) {
  const Handle dset = open_dataset(group, name);
  const Handle type(H5Dget_type(dset.get()), H5Tclose, "H5Dget_type for " + name);
  return H5Tget_size(type.get());
}

int dataset_components(Id group, const std::string& name, int fallback) {
  const Handle dset = open_dataset(group, name);
  if (H5Aexists(dset.get(), "components") <= 0) return fallback;
  return static_cast<int>(read_integer_attribute(dset.get(), "components"));
}

void read_reals(Id group, const std::string& name, std::span<double> out) {
  const Handle dset = open_dataset(group, name);
  const std::size_t n = element_count(dset.get(), name);
  if (n != out.size())
    throw std::runtime_error("reading " + name + " failed: it holds " + std::to_string(n) + " values, expected " +
                             std::to_string(out.size()));
  if (n > 0) check(H5Dread(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), "reading " + name);
}

std::vector<std::int64_t> read_integers(Id group, const std::string& name) {
  const Handle dset = open_dataset(group, name);
  std::vector<std::int64_t> values(element_count(dset.get(), name));
  if (!values.empty())
    check(H5Dread(dset.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), "reading " + name);
  return values;
}

void write_strings(Id group, const std::string& name, const std::vector<std::string>& values) {
  const Handle type = vl_string_type();
  std::vector<const char*> pointers;
  for (const auto& v : values) pointers.push_back(v.c_str());
  write_dataset(group, name, type.get(), type.get(), {values.size()}, pointers.data());
}

std::vector<std::string> read_strings(Id group, const std::string& name) {
  const Handle dset = open_dataset(group, name);
  const Handle type = vl_string_type();
  std::vector<char*> pointers(element_count(dset.get(), name), nullptr);
  if (pointers.empty()) return {};
  check(H5Dread(dset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, pointers.data()), "reading " + name);
  std::vector<std::string> values;
  for (const char* p : pointers) values.emplace_back(p ? p : "");
  const Handle space(H5Dget_space(dset.get()), H5Sclose, "H5Dget_space for " + name);
#if H5_VERSION_GE(1, 12, 0)
  H5Treclaim(type.get(), space.get(), H5P_DEFAULT, pointers.data());
#else
  H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, pointers.data());
#endif
  return values;
}

}  // namespace frostmpm::hdf5
