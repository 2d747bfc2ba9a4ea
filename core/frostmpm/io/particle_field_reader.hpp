#pragma once
// Reads back what ParticleFieldWriter wrote: a run's fields.h5, its frames in step order, and
// a frame's particle positions and fields (`initial: {temperature: {from: OUT}}` starts a new
// run from another run's output). hdf5.h stays in the .cpp.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace frostmpm {

class ParticleFieldReader {
 public:
  struct Frame {
    std::string group;  ///< HDF5 group name, step_000120
    double time = 0;
    long step = 0;
    std::size_t count = 0;
  };
  /// Opens <dir>/fields.h5. std::runtime_error (one line naming the file) if there is none or
  /// it is not a FrostMPM field file.
  explicit ParticleFieldReader(const std::string& dir);
  /// The complete frames of an open field file (an hdf5::Id), in step order. A frame a crash
  /// cut short (its group, attributes or coordinates unreadable) is left out, and its group
  /// name added to `torn` when given (ParticleFieldWriter::reopen deletes those).
  static std::vector<Frame> list_frames(std::int64_t file, std::vector<std::string>* torn = nullptr);
  ~ParticleFieldReader();
  ParticleFieldReader(const ParticleFieldReader&) = delete;
  ParticleFieldReader& operator=(const ParticleFieldReader&) = delete;

  int dim() const;
  std::string path() const;
  /// The complete frames, in step order.
  const std::vector<Frame>& frames() const;
  /// Positions of a frame: count × dim, row-major.
  std::vector<double> positions(const Frame& frame) const;
  /// The fields a frame holds, in name order.
  std::vector<std::string> field_names(const Frame& frame) const;
  struct Field {
    int components = 1;          ///< as written (before the writer's padding of 2-D vectors to 3)
    std::vector<double> values;  ///< count × components, row-major
  };
  /// A field of a frame. std::runtime_error naming the field and the frame, and listing the
  /// fields it holds, when the frame does not hold it.
  Field field(const Frame& frame, const std::string& name) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace frostmpm
