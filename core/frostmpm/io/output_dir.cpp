#include "frostmpm/io/output_dir.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace fs = std::filesystem;

namespace frostmpm {

OutputError::OutputError(const std::string& path, const std::string& reason, const std::string& when)
    : InputError("cannot write " + path + when + ": " + reason), reason_(reason) {}

OutputError::~OutputError() = default;

std::string at_step(long step, double time) {
  std::ostringstream text;
  text.precision(10);
  text << " at step " << step << " (t = " << time << " s)";
  return text.str();
}

CheckedFile::CheckedFile(std::string path, bool append) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0666);
  if (fd_ < 0) throw OutputError(path_, std::strerror(errno));
}

CheckedFile::~CheckedFile() {
  if (fd_ >= 0) ::close(fd_);
}

CheckedFile::CheckedFile(CheckedFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)) {}

void CheckedFile::write(std::string_view text, const std::string& when) {
  const off_t start = ::lseek(fd_, 0, SEEK_END);
  while (!text.empty()) {
    const ssize_t n = ::write(fd_, text.data(), text.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      // A full disk may take part of the piece: cut it off (best effort), so readers never
      // see half a row.
      const int cut = start >= 0 ? ::ftruncate(fd_, start) : 0;
      static_cast<void>(cut);
      throw OutputError(path_, std::strerror(error), when);
    }
    text.remove_prefix(static_cast<std::size_t>(n));
  }
}

void CheckedFile::close() {
  const int fd = std::exchange(fd_, -1);
  if (fd >= 0 && ::close(fd) != 0) throw OutputError(path_, std::strerror(errno));
}

void write_file_atomically(const std::string& path, std::string_view text, const std::string& when) {
  const std::string temp_path = path + ".partial";
  try {
    CheckedFile out(temp_path, /*append=*/false);
    out.write(text, when);
    out.close();
    std::error_code ec;
    fs::rename(temp_path, path, ec);
    if (ec) throw OutputError(path, ec.message(), when);
  } catch (const OutputError& e) {
    std::error_code ignored;
    fs::remove(temp_path, ignored);  // no empty or cut-short .partial left behind
    throw OutputError(path, e.reason(), when);  // the file the user knows, not the .partial
  }
}

namespace {
/// fsync of a file or folder.
void sync_to_disk(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) throw std::runtime_error("opening " + path + " for fsync failed: " + std::strerror(errno));
  const int status = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (status != 0) throw std::runtime_error("fsync of " + path + " failed: " + std::strerror(error));
}
}  // namespace

void publish_synced(const std::string& partial_path, const std::string& final_path) {
  sync_to_disk(partial_path, O_RDONLY);
  fs::rename(partial_path, final_path);
  // The rename itself reaches the disk with the folder's metadata; not every file system can
  // fsync a folder, and the file is complete either way.
  try {
    sync_to_disk(fs::path(final_path).parent_path().string(), O_RDONLY | O_DIRECTORY);
  } catch (const std::runtime_error&) {
  }
}

OutputDir::OutputDir(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  fs::create_directories(path_, ec);
  if (ec || !fs::is_directory(path_))
    throw InputError("output folder '" + path_ + "' cannot be created: " +
                     (ec ? ec.message() : std::string("a file with that name exists")));
  if (::access(path_.c_str(), W_OK) != 0)
    throw InputError("output folder '" + path_ + "' is not writable");
  // access() says yes to root everywhere; a real probe catches read-only mounts too.
  const std::string probe = file(".frostmpm-write-probe");
  {
    std::ofstream out(probe);
    if (!out) throw InputError("output folder '" + path_ + "' is not writable");
  }
  fs::remove(probe, ec);
}

void OutputDir::write_text(const std::string& name, const std::function<void(std::ostream&)>& writer) const {
  std::ostringstream text;
  writer(text);
  write_file_atomically(file(name), text.str());
}

void OutputDir::write_text(const std::string& name, const std::string& text) const {
  write_file_atomically(file(name), text);
}

}  // namespace frostmpm
