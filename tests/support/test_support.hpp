#pragma once
// Shared helpers for tests: the registry with the built-in plugins loaded, paths into the
// source and build trees, and running the frostmpm CLI as a user would.
#include <optional>
#include <string>
#include <vector>

#include <sys/types.h>

#include "frostmpm/plugin/registry.hpp"

namespace frostmpm::test {

/// Registry with every built-in plugin loaded (once per test binary).
const Registry& builtin_registry();

std::string source_dir();   ///< repository root
std::string binary_dir();   ///< CMake build folder
std::string frostmpm_exe(); ///< path of the built `frostmpm` program

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};
/// Runs a shell command, capturing its output (stderr merged into stdout).
CommandResult run_command(const std::string& command);
/// Runs `frostmpm <args>`.
CommandResult run_frostmpm(const std::string& args);

/// A fresh empty temporary folder, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

/// A small valid freezing-curves scene (its van Genuchten-CC SFCC on lines 4-7) for
/// CLI tests to run, break or extend.
extern const std::string kFreezingCurvesScene;

/// A numeric CSV file with a header line (metrics.csv, freezing_curves.csv).
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  /// Index of a column; throws std::out_of_range naming it when absent.
  std::size_t column(const std::string& name) const;
};
CsvTable read_csv(const std::string& path);

/// A counter of OUT/run.json's `run.counters` ("thermal.energy_balance_error_relative", ...);
/// throws std::out_of_range naming it when absent.
double run_counter(const std::string& out, const std::string& key);
/// One value of OUT/run.json as Python prints it, `path` a subscript chain ("['run']['steps']"):
/// a JSON integer prints without a decimal point.
std::string run_json(const std::string& out, const std::string& path);

/// `frostmpm ARGS` running in the background with default signal dispositions (whatever the
/// test runner inherited), stdout into `stdout_path` and stderr into `stderr_path` (or with
/// stdout when empty). A run still going when the object dies is killed.
class BackgroundRun {
 public:
  BackgroundRun(const std::string& args, const std::string& stdout_path, const std::string& stderr_path = "");
  ~BackgroundRun();
  BackgroundRun(const BackgroundRun&) = delete;
  BackgroundRun& operator=(const BackgroundRun&) = delete;

  bool running();
  void signal(int number) const;
  /// Exit code, 128 + N when ended by signal N; throws std::runtime_error after `seconds`.
  int wait(double seconds = 300);
  std::string output() const;       ///< what it wrote to stdout (and stderr, when together)
  std::string stderr_text() const;  ///< what it wrote to stderr

 private:
  pid_t pid_ = -1;
  std::optional<int> exit_code_;
  std::string stdout_path_, stderr_path_;
};

/// Writes `text` to `path`.
void write_file(const std::string& path, const std::string& text);
std::string read_file(const std::string& path);

}  // namespace frostmpm::test
