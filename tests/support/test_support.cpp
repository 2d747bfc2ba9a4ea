#include "test_support.hpp"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <chrono>
#include <csignal>
#include <spawn.h>
#include <stdexcept>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "frostmpm/plugin/plugin_loader.hpp"

namespace frostmpm::test {

const Registry& builtin_registry() {
  static Registry registry = [] {
    Registry r;
    PluginLoader loader(r);
    // Only the built-in folder: a user's FROSTMPM_PLUGIN_PATH must not change what tests see.
    const char* user_path = std::getenv("FROSTMPM_PLUGIN_PATH");
    const std::string saved = user_path ? user_path : "";
    unsetenv("FROSTMPM_PLUGIN_PATH");
    for (const auto& dir : PluginLoader::default_search_path()) loader.load_directory(dir);
    if (user_path) setenv("FROSTMPM_PLUGIN_PATH", saved.c_str(), 1);
    return r;
  }();
  return registry;
}

const std::string kFreezingCurvesScene = R"(task: freezing_curves
material:
  porosity: 0.3
  sfcc:
    model: van_genuchten_cc
    lambda: 0.5
    p0: 1.0e5
  relative_permeability: {model: van_genuchten_mualem, m: 0.5}
  absolute_permeability: {model: constant, k0: 1.0e-7}
freezing_curves:
  temperature_range: [-5.0, 1.0]
  samples: 7
)";

std::string source_dir() { return FROSTMPM_SOURCE_DIR; }
std::string binary_dir() { return FROSTMPM_BINARY_DIR; }
std::string frostmpm_exe() { return binary_dir() + "/bin/frostmpm"; }

CommandResult run_command(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

CommandResult run_frostmpm(const std::string& args) { return run_command(frostmpm_exe() + " " + args); }

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "frostmpm-test-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::size_t CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return i;
  throw std::out_of_range("no column '" + name + "' in the CSV");
}

double run_counter(const std::string& out, const std::string& key) {
  const std::string json = read_file(out + "/run.json");
  const std::string quoted = "\"" + key + "\": ";
  const auto at = json.find(quoted);
  if (at == std::string::npos) throw std::out_of_range("run.json in " + out + " has no counter " + key);
  return std::stod(json.substr(at + quoted.size()));
}

std::string run_json(const std::string& out, const std::string& path) {
  const auto py = run_command("/usr/bin/python3 -c \"import json; print(json.load(open('" + out + "/run.json'))" +
                              path + ")\"");
  if (py.exit_code != 0) throw std::runtime_error("run.json in " + out + ": cannot read " + path + ": " + py.output);
  return py.output.substr(0, py.output.find('\n'));
}

CsvTable read_csv(const std::string& path) {
  CsvTable table;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::stringstream header(line);
  for (std::string cell; std::getline(header, cell, ',');) table.header.push_back(cell);
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(std::strtod(cell.c_str(), nullptr));
    table.rows.push_back(row);
  }
  return table;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

BackgroundRun::BackgroundRun(const std::string& args, const std::string& stdout_path, const std::string& stderr_path)
    : stdout_path_(stdout_path), stderr_path_(stderr_path) {
  std::string command = "exec " + frostmpm_exe() + " " + args + " >'" + stdout_path + "' " +
                        (stderr_path.empty() ? std::string("2>&1") : "2>'" + stderr_path + "'");
  char sh[] = "sh", dash_c[] = "-c";
  char* argv[] = {sh, dash_c, command.data(), nullptr};
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t signals;
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attributes, &signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  posix_spawnattr_setsigdefault(&attributes, &signals);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  const int status = posix_spawn(&pid_, "/bin/sh", nullptr, &attributes, argv, environ);
  posix_spawnattr_destroy(&attributes);
  if (status != 0) throw std::runtime_error("posix_spawn failed");
}

BackgroundRun::~BackgroundRun() {
  if (!exit_code_) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

bool BackgroundRun::running() {
  if (exit_code_) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
  exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return false;
}

void BackgroundRun::signal(int number) const { kill(pid_, number); }

int BackgroundRun::wait(double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (running()) {
    if (std::chrono::steady_clock::now() > deadline)
      throw std::runtime_error("frostmpm did not exit within " + std::to_string(seconds) + " s");
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return *exit_code_;
}

std::string BackgroundRun::output() const { return read_file(stdout_path_); }
std::string BackgroundRun::stderr_text() const { return read_file(stderr_path_.empty() ? stdout_path_ : stderr_path_); }

}  // namespace frostmpm::test
