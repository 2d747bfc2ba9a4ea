#pragma once
// Particles as a structure of arrays: each field is one contiguous column of doubles with
// `components` values per particle. A field exists only once something declares it, so a
// thermal-only scene never allocates pressure, velocity or stress.
//
// A field has a shape (scalar, vector, symmetric 3×3 tensor, full 3×3 tensor) that names its
// components for probes and output ("stress.yy", "water_flux.x"). Stress and strain are
// always 3×3, whatever the dimension (plane strain keeps σ_zz), as MOOSE's RankTwoTensor and
// Uintah's Matrix3 do.
//
// Every field has a unit, given where it is declared (frostmpm/config/units.hpp): the output
// writes it beside the values, and probes derive their columns' units from it.
//
// History: a field declared with history keeps a step-start copy that the kernel refreshes at
// the start of every step, so a retried step or a rejected return mapping starts again from
// the values the step began with (MOOSE's "old" material properties, Uintah's old data
// warehouse).
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "frostmpm/particles/particle_removal.hpp"

namespace frostmpm {

/// How the components of a particle or nodal field are laid out and named.
enum class FieldKind {
  Scalar,           ///< 1 component
  Vector,           ///< Dim components: x, y[, z]
  SymmetricTensor,  ///< 6 components, Voigt order: xx, yy, zz, yz, xz, xy
  Tensor,           ///< 9 components, row-major: xx, xy, xz, yx, yy, yz, zx, zy, zz
  Other,            ///< `components` unnamed values (c0, c1, ...)
};

/// Component names of a field of `kind` with `components` values ("x", "xx", "c3").
std::vector<std::string> component_names(FieldKind kind, int components);
/// Voigt index (0..5) of the symmetric tensor component (i, j), i, j in 0..2.
constexpr int voigt_index(int i, int j) {
  if (i == j) return i;
  return 6 - i - j;  // (1,2)->3 yz, (0,2)->4 xz, (0,1)->5 xy
}
inline constexpr int kSymmetricTensorComponents = 6;
inline constexpr int kTensorComponents = 9;

/// A contiguous run of particles made by one region, all of one material.
struct ParticleRange {
  std::size_t begin = 0, end = 0;
  int material = 0;
  std::size_t size() const { return end - begin; }
};

class ParticleStore {
 public:
  /// Declares (or returns the existing) field; re-declaring with other components or another
  /// unit, or declaring without a valid unit (units::is_output_unit), is an error (std::logic_error). The
  /// kind is taken from the first declaration that gives one other than Other.
  void declare(const std::string& name, const std::string& unit, int components = 1, double initial = 0.0,
               FieldKind kind = FieldKind::Other);
  /// Declares a field with a step-start copy (see the header comment); the copy is the field
  /// history_name(name), internal (not offered to output or probes).
  void declare_history(const std::string& name, const std::string& unit, int components = 1, double initial = 0.0,
                       FieldKind kind = FieldKind::Other);
  static std::string history_name(const std::string& name) { return name + "__step_start"; }
  /// Copies every history field into its step-start copy (the kernel does it before each step).
  void begin_step();
  bool has(const std::string& name) const { return fields_.count(name) != 0; }
  int components(const std::string& name) const;
  FieldKind kind(const std::string& name) const;
  /// The unit it was declared with ("degC", "m/s", "1").
  const std::string& unit(const std::string& name) const;
  /// True for the step-start copies of history fields.
  bool internal(const std::string& name) const;

  std::span<double> field(const std::string& name);
  std::span<const double> field(const std::string& name) const;
  /// The storage itself, for handles that must survive a change in the particle count.
  std::vector<double>& column(const std::string& name);

  /// Appends `count` particles of `material` (fields get their initial values); returns the range.
  ParticleRange append(std::size_t count, int material);

  /// Drops the leaving particles from every field; the others keep their order.
  void remove(const ParticleRemoval& removal);

  std::size_t size() const { return size_; }
  const std::vector<ParticleRange>& ranges() const { return ranges_; }
  std::vector<std::string> field_names() const;  ///< every field, internal ones included
  std::size_t bytes() const;

 private:
  struct Column {
    int components = 1;
    double initial = 0;
    FieldKind kind = FieldKind::Other;
    std::string unit;
    bool internal = false;
    std::vector<double> values;
  };
  const Column& find(const std::string& name) const;
  std::map<std::string, Column> fields_;
  std::vector<std::string> history_;  ///< fields with a step-start copy
  std::vector<ParticleRange> ranges_;
  std::size_t size_ = 0;
};

}  // namespace frostmpm
