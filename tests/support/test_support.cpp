#include "test_support.hpp"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

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

}  // namespace frostmpm::test
