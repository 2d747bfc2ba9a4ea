#pragma once
// Particle field output that ParaView opens as is: `fields.h5` holds the numbers, `fields.xdmf`
// (XDMF 3) describes them as a time series of point clouds, one Polyvertex grid per output time.
//
// HDF5 layout (one group per frame, named after the step number):
//   /step_000120/                attributes: time (double), step (int64), count (int64)
//       coordinates  count x 3   positions; z = 0 for 2D runs   attributes components = dim, units = "m"
//       connectivity count       0..count-1 (the Polyvertex cells ParaView needs to draw points)
//       <field>      count       one component  -> XDMF Scalar
//                    count x 3   2 or 3 components (2 padded with zeros) -> Vector
//                    count x 6   -> Tensor6;  count x 9 -> Tensor;  count x c otherwise -> Matrix
//                                every field dataset has attributes components = c as given and
//                                units (a UDUNITS-2 string, variable-length UTF-8: "degC", "m/s")
//   root attribute dim (int).
//
// Restart: reopen() keeps the first frames of an existing fields.h5 (those a checkpoint knows
// about), deletes later ones and rebuilds fields.xdmf from the frames present, listing each
// frame's fields in name order; new frames are appended after them.
//
// Crash safety: after every frame the HDF5 file is flushed and fields.xdmf is rewritten
// atomically (fields.xdmf.partial, then rename), so the XDMF only ever lists complete frames and
// a run that dies later leaves every earlier frame readable. The HDF5 file is written without
// file locking, so ParaView or scripts/read_fields.py can open it while the run goes on.
// Disk space for a frame is reserved before HDF5 writes it, so a full disk stops the run before
// HDF5 has touched the file: an OutputError (one line: file, step, reason), earlier frames intact.
//
// hdf5.h is included by the .cpp only; nothing that includes this header parses it.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace frostmpm {

/// One named per-particle field: `data` holds count*components doubles, row-major per particle.
struct FieldView {
  std::string name;  ///< letters, digits, '_', '-', '.' (not first); not "coordinates"/"connectivity"
  const double* data = nullptr;
  int components = 1;
  std::string unit;  ///< "degC", "m/s", "1" (frostmpm/config/units.hpp)
};

class ParticleFieldWriter {
 public:
  /// Creates (truncates) <dir>/fields.h5 and <dir>/fields.xdmf (the folder is created if
  /// needed). dim = 2 or 3, else std::invalid_argument; std::runtime_error if the files cannot
  /// be created.
  ParticleFieldWriter(const std::string& dir, int dim);
  /// Opens <dir>/fields.h5 written by an earlier writer for appending: keeps its first
  /// `keep_frames` frames in step order, deletes the rest (their space is not reclaimed) and
  /// rewrites fields.xdmf. std::runtime_error if the file cannot be opened, holds frames of
  /// another dimension, or fewer than `keep_frames` frames.
  static ParticleFieldWriter reopen(const std::string& dir, int dim, std::size_t keep_frames);
  ~ParticleFieldWriter();
  ParticleFieldWriter(const ParticleFieldWriter&) = delete;
  ParticleFieldWriter& operator=(const ParticleFieldWriter&) = delete;
  ParticleFieldWriter(ParticleFieldWriter&&) noexcept;
  ParticleFieldWriter& operator=(ParticleFieldWriter&&) noexcept;

  /// Appends one output time: positions (count*dim) and fields. The particle count may change
  /// between writes. Throws std::runtime_error naming the array ("positions" or the field name)
  /// if a value is not finite, and std::invalid_argument for a bad field name/components/unit, a
  /// repeated field name, a step already written, a negative step or a non-finite time. Nothing
  /// is written when it throws, and the writer stays usable. A failed write (full disk) is an
  /// OutputError naming the file and step; the frames before it stay readable.
  void write(double time, long step, std::size_t count, const double* positions,
             const std::vector<FieldView>& fields);

  /// Number of frames written so far (kept frames included after reopen()).
  std::size_t frames() const;

  std::string h5_path() const;    ///< <dir>/fields.h5
  std::string xdmf_path() const;  ///< <dir>/fields.xdmf

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  explicit ParticleFieldWriter(std::unique_ptr<Impl> impl);
};

}  // namespace frostmpm
