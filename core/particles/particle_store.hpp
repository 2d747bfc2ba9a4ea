#pragma once
// Particles as a structure of arrays: each field is one contiguous column of doubles with
// `components` values per particle. A field exists only once something declares it, so a
// thermal-only scene never allocates pressure, velocity or stress.
#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace frostmpm {

/// A contiguous run of particles made by one region, all of one material.
struct ParticleRange {
  std::size_t begin = 0, end = 0;
  int material = 0;
  std::size_t size() const { return end - begin; }
};

class ParticleStore {
 public:
  /// Declares (or returns the existing) field; re-declaring with other components is an error.
  void declare(const std::string& name, int components, double initial = 0.0);
  bool has(const std::string& name) const { return fields_.count(name) != 0; }
  int components(const std::string& name) const;

  std::span<double> field(const std::string& name);
  std::span<const double> field(const std::string& name) const;

  /// Appends `count` particles of `material` (fields get their initial values); returns the range.
  ParticleRange append(std::size_t count, int material);

  std::size_t size() const { return size_; }
  const std::vector<ParticleRange>& ranges() const { return ranges_; }
  std::vector<std::string> field_names() const;
  std::size_t bytes() const;

 private:
  struct Column {
    int components = 1;
    double initial = 0;
    std::vector<double> values;
  };
  std::map<std::string, Column> fields_;
  std::vector<ParticleRange> ranges_;
  std::size_t size_ = 0;
};

}  // namespace frostmpm
