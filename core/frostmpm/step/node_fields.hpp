#pragma once
// Nodal fields shared between physics: one contiguous column per field, `components` values
// per grid node, allocated by the kernel only when a stage of the scene reads or writes it.
#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace frostmpm {

class NodeFields {
 public:
  /// Allocates (zero-filled) or returns the existing field; other components is an error.
  void allocate(const std::string& name, int components, std::size_t nodes);
  bool has(const std::string& name) const { return fields_.count(name) != 0; }
  int components(const std::string& name) const;

  /// The field's values; throws std::logic_error naming the field when the scene has none.
  std::span<double> field(const std::string& name);
  std::span<const double> field(const std::string& name) const;
  /// The same storage as a vector, for code that hands it to routines taking vectors.
  std::vector<double>& values(const std::string& name);

  std::vector<std::string> names() const;
  std::size_t bytes() const;

 private:
  struct Column {
    int components = 1;
    std::vector<double> values;
  };
  const Column& column(const std::string& name) const;
  std::map<std::string, Column> fields_;
};

}  // namespace frostmpm
