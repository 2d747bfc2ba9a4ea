#pragma once
// Small helpers over the HDF5 C API shared by the particle field writer and checkpoints:
// owned identifiers, errors as exceptions, attributes, datasets, string lists. Internal to the
// core library (not part of the plugin SDK).
//
// HDF5 identifiers are hid_t, which HDF5 1.10 and later define as int64_t; they are spelled
// hdf5::Id here so that this header does not include hdf5.h (hdf5_support.cpp checks the types
// agree). Every failure throws std::runtime_error("<what> failed: <HDF5's own messages>").
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace frostmpm::hdf5 {

using Id = std::int64_t;

/// While alive, HDF5 does not print its error stack to stderr; the exceptions carry it instead.
class QuietErrors {
 public:
  QuietErrors();
  ~QuietErrors();
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;

 private:
  using Handler = int (*)(Id, void*);  // H5E_auto2_t
  Handler handler_ = nullptr;
  void* data_ = nullptr;
};

/// Throws std::runtime_error(what + " failed: " + the current HDF5 error stack), clearing it.
[[noreturn]] void fail(const std::string& what);
/// fail(what) when status < 0.
void check(int status, const std::string& what);

/// Reserves disk after the end of `file` (stored at `path`) for what HDF5 writes next:
/// `data_bytes` plus room for the headers, B-trees and heaps of `objects` new groups or
/// datasets. Both 0: cuts off what is left of earlier reservations (call it after a flush). A
/// full disk (or quota, or file size limit) then fails here with std::runtime_error(the
/// system's reason) before HDF5 has changed anything: after a failed write HDF5 1.10 may leave
/// the file's earlier contents damaged, and cannot close it (it crashes at exit). File systems
/// without preallocation skip the check.
void reserve(Id file, const std::string& path, std::uintmax_t data_bytes, std::size_t objects);

/// Owns an HDF5 identifier and closes it with `closer` (H5Fclose, H5Gclose, ...).
class Handle {
 public:
  using Closer = int (*)(Id);
  Handle() = default;  ///< owns nothing
  /// fail(what) when id < 0.
  Handle(Id id, Closer closer, const std::string& what);
  ~Handle() { reset(); }
  Handle(Handle&& other) noexcept;
  Handle& operator=(Handle&& other) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Id get() const { return id_; }
  /// Closes now; check(status) so a failed close (e.g. a failed final flush) is reported.
  void close(const std::string& what);

 private:
  Id id_ = -1;
  Closer closer_ = nullptr;
  void reset();
};

/// Creates (truncates) or opens a file without HDF5 file locking, so readers such as ParaView
/// can open it while a run writes it. Files use the earliest (most widely readable) format.
Handle create_file(const std::string& path);
Handle open_file(const std::string& path, bool writable);
Handle create_group(Id parent, const std::string& name);
Handle open_group(Id parent, const std::string& name);
bool exists(Id parent, const std::string& name);
/// Names of the links (groups, datasets) directly in `group`, in name order.
std::vector<std::string> child_names(Id group);
/// Names of the attributes of `object`, in name order.
std::vector<std::string> attribute_names(Id object);

void write_attribute(Id object, const std::string& name, double value);
void write_attribute(Id object, const std::string& name, std::int64_t value);
void write_attribute(Id object, const std::string& name, int value);
/// A variable-length UTF-8 string (h5py reads it as str).
void write_attribute(Id object, const std::string& name, const std::string& value);
double read_real_attribute(Id object, const std::string& name);
std::int64_t read_integer_attribute(Id object, const std::string& name);

/// Creates dataset `name` in `group` with shape `dims` and writes `data` (may be null when the
/// dataset is empty); `file_type` and `mem_type` are HDF5 type ids (H5T_IEEE_F64LE, ...).
/// A positive `components_attribute` is stored as the dataset's "components" attribute, a
/// non-empty `units_attribute` as its "units" attribute.
void write_dataset(Id group, const std::string& name, Id file_type, Id mem_type,
                   const std::vector<std::size_t>& dims, const void* data, int components_attribute = 0,
                   const std::string& units_attribute = {});
/// Shape of dataset `name` in `group`.
std::vector<std::size_t> dataset_shape(Id group, const std::string& name);
/// Size in bytes of one element of dataset `name`.
std::size_t dataset_element_size(Id group, const std::string& name);
/// The "components" attribute of dataset `name`, or `fallback` when it has none.
int dataset_components(Id group, const std::string& name, int fallback);
/// Reads a double dataset into `out`, whose size must equal the dataset's element count.
void read_reals(Id group, const std::string& name, std::span<double> out);
/// Reads an integer dataset of any shape, flattened.
std::vector<std::int64_t> read_integers(Id group, const std::string& name);

/// A 1-D dataset of variable-length UTF-8 strings (any count, 0 included).
void write_strings(Id group, const std::string& name, const std::vector<std::string>& values);
std::vector<std::string> read_strings(Id group, const std::string& name);

}  // namespace frostmpm::hdf5
