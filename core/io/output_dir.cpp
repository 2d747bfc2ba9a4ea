#include "frostmpm/io/output_dir.hpp"

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "frostmpm/config/input_error.hpp"

namespace fs = std::filesystem;

namespace frostmpm {

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
  const std::string final_path = file(name);
  const std::string temp_path = final_path + ".partial";
  {
    std::ofstream out(temp_path);
    if (!out) throw InputError("cannot write '" + final_path + "'");
    writer(out);
    out.flush();
    if (!out) throw InputError("failed while writing '" + final_path + "' (disk full?)");
  }
  fs::rename(temp_path, final_path);
}

void OutputDir::write_text(const std::string& name, const std::string& text) const {
  write_text(name, [&](std::ostream& out) { out << text; });
}

}  // namespace frostmpm
