#pragma once
// The run's output folder. It is checked for writability before any work starts, and every
// file is written to a temporary name and renamed, so a failed run never leaves a
// half-written file behind and never corrupts an earlier complete one.
#include <functional>
#include <iosfwd>
#include <string>

namespace frostmpm {

class OutputDir {
 public:
  /// Creates the folder if needed; an InputError if it cannot be created or written.
  explicit OutputDir(std::string path);

  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

  /// Writes `name` through `writer`, atomically (temp file + rename).
  void write_text(const std::string& name, const std::function<void(std::ostream&)>& writer) const;
  void write_text(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
};

}  // namespace frostmpm
