// Every bad input refused: each case of tests/corpus/bad_input.txt, a shipped
// scene broken one way, must exit 2 with one `error:` line naming the file and the YAML path.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <sstream>

#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

/// The scenes the corpus breaks, by the alias its lines use.
const std::map<std::string, std::string> kScenes = {
    {"FI", "configs/tutorials/frozen_inclusion.yaml"},   {"FC", "configs/tutorials/freezing_curves.yaml"},
    {"HF", "configs/verification/heat_flux.yaml"},       {"CV", "configs/verification/convective_surface.yaml"},
    {"DC", "configs/verification/darcy_column.yaml"},    {"NF", "configs/verification/neumann_freezing.yaml"},
    {"KA", "configs/verification/kurylyk_advection.yaml"}, {"P1", "configs/paper/frozen_inclusion_case1.yaml"},
    {"SW", "configs/verification/self_weight_column.yaml"}, {"VB", "configs/verification/vibrating_bar.yaml"},
    {"TC", "configs/verification/terzaghi_consolidation.yaml"}, {"MA", "configs/verification/mandel.yaml"},
    {"RF", "configs/paper/rock_freezing.yaml"},          {"PF", "configs/verification/prandtl_footing.yaml"},
    {"RS", "configs/verification/reissner_footing.yaml"}, {"IS", "configs/verification/infinite_slope.yaml"},
    {"GC", "configs/verification/granular_collapse.yaml"}, {"TS", "configs/paper/thaw_slump.yaml"}};

struct Case {
  int line = 0;
  std::string scene, expected_path, arguments, expected_text;
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::vector<Case> read_corpus() {
  std::ifstream in(source_dir() + "/tests/corpus/bad_input.txt");
  std::vector<Case> cases;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    const auto a = line.find(" | "), b = line.find(" | ", a + 3), c = line.find(" | ", b + 3);
    REQUIRE(b != std::string::npos);
    const std::string arguments = line.substr(b + 3, c == std::string::npos ? std::string::npos : c - b - 3);
    const std::string text = c == std::string::npos ? std::string() : trim(line.substr(c + 3));
    cases.push_back({number, trim(line.substr(0, a)), trim(line.substr(a + 3, b - a - 3)), arguments, text});
  }
  return cases;
}

std::string unescape(std::string s) {
  for (auto p = s.find("\\n"); p != std::string::npos; p = s.find("\\n", p + 1)) s.replace(p, 2, "\n");
  return s;
}

/// The command line of one case, writing an edited copy of the scene into `dir` when asked.
std::string command_of(const Case& c, const TempDir& dir) {
  std::string scene = source_dir() + "/" + kScenes.at(c.scene), args = c.arguments;
  std::string verb = "check ";
  if (args.rfind("run ", 0) == 0) {
    verb = "run -q -o " + dir.file("out") + " ";
    args = args.substr(4);
  }
  if (args.rfind("edit ", 0) == 0) {
    const auto arrow = args.find(" => ");
    REQUIRE(arrow != std::string::npos);
    const std::string from = unescape(args.substr(5, arrow - 5)), to = unescape(args.substr(arrow + 4));
    std::string text = read_file(scene);
    const auto at = text.find(from);
    INFO("the text to edit is not in " << scene << ": " << from);
    REQUIRE(at != std::string::npos);
    scene = dir.file("scene.yaml");
    write_file(scene, text.replace(at, from.size(), to));
    args.clear();
  }
  return verb + scene + " " + args;
}

}  // namespace

TEST_CASE("bad-input corpus: every case exits 2 with one error line naming file and YAML path",
          "[cli][bad-input][corpus]") {
  const auto cases = read_corpus();
  REQUIRE(cases.size() >= 150);
  for (const auto& c : cases) {
    TempDir dir;
    const std::string command = command_of(c, dir);
    const CommandResult r = run_frostmpm(command);
    INFO("tests/corpus/bad_input.txt:" << c.line << ": frostmpm " << command << "\n" << r.output);
    CHECK(r.exit_code == 2);
    std::istringstream lines(r.output);
    int errors = 0;
    std::string error;
    for (std::string line; std::getline(lines, line);)
      if (line.rfind("error: ", 0) == 0) {
        ++errors;
        error = line;
      }
    CHECK(errors == 1);
    // The file (the scene, its edited copy, or the --set that gave the value) and the path.
    const bool names_file = error.find(".yaml") != std::string::npos || error.find("--set ") != std::string::npos;
    CHECK(names_file);
    const auto at = error.find("at '");
    const std::string path = at == std::string::npos ? "" : error.substr(at + 4, error.find('\'', at + 4) - at - 4);
    CHECK(path.find(c.expected_path) != std::string::npos);
    CHECK(error.find(c.expected_text) != std::string::npos);
  }
}

TEST_CASE("bad input: a scene that is a device or over 16 MB is refused before it is read", "[cli][bad-input]") {
  const CommandResult device = run_frostmpm("check /dev/zero");
  INFO(device.output);
  CHECK(device.exit_code == 2);
  CHECK(device.output.find("error: /dev/zero: is not a regular file") != std::string::npos);

  TempDir dir;
  write_file(dir.file("huge.yaml"), "task: simulation\n# " + std::string(17u << 20, 'x') + "\n");
  const CommandResult huge = run_frostmpm("check " + dir.file("huge.yaml"));
  INFO(huge.output);
  CHECK(huge.exit_code == 2);
  CHECK(huge.output.find("larger than 16 MB") != std::string::npos);
}
