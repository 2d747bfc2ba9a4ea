#pragma once
// The run's output folder. It is checked for writability before any work starts, and every
// file is written to a temporary name and renamed, so a failed run never leaves a
// half-written file behind and never corrupts an earlier complete one.
//
// Write faults (disk full, quota, file size limit, I/O error) are OutputErrors: one line naming
// the file (and the step), exit code 2 like bad input, since the user has to act, not us.
#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>

#include "frostmpm/config/input_error.hpp"

namespace frostmpm {

class OutputError : public InputError {
 public:
  /// "cannot write PATH[ at step S (t = T s)]: REASON".
  OutputError(const std::string& path, const std::string& reason, const std::string& when = "");
  ~OutputError() override;
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

/// " at step S (t = T s)", the `when` of an OutputError during a run.
std::string at_step(long step, double time);

/// A file written in whole pieces (metrics.csv rows, a .partial): every write is checked, and
/// a piece that does not land completely is cut off again, so the file never ends mid-row.
class CheckedFile {
 public:
  /// Opens for writing, truncating or appending; OutputError if that fails.
  CheckedFile(std::string path, bool append);
  ~CheckedFile();
  CheckedFile(CheckedFile&& other) noexcept;
  CheckedFile& operator=(CheckedFile&&) = delete;
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;

  /// Writes all of `text` or throws OutputError(path, errno text, when) with the file as before.
  void write(std::string_view text, const std::string& when = "");
  /// Closes now, reporting a failed close (some file systems report a full disk only here).
  void close();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

/// Writes `text` to `path` atomically (path.partial, then rename); on failure the .partial is
/// removed and an earlier `path` stays as it was. `when` as for OutputError.
void write_file_atomically(const std::string& path, std::string_view text, const std::string& when = "");

/// Publishes a finished file written as `partial_path` under `final_path`: its data synced to
/// disk, then the rename (atomic), then the folder synced where the file system allows it. A
/// crash at any point leaves either the earlier `final_path` or the new one, whole.
/// std::runtime_error if the sync or the rename fails (the .partial is then still there).
void publish_synced(const std::string& partial_path, const std::string& final_path);

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
