#pragma once
// `frostmpm test-model KIND/NAME`: a plugin author's contract check of one model.
#include <iosfwd>
#include <string>
#include <vector>

namespace frostmpm::app {

/// Exit code when the model breaks its contract (2 stays bad input, e.g. an unknown model).
inline constexpr int kContractViolationExitCode = 1;

struct TestModelOptions {
  std::string target;                 ///< KIND/NAME
  std::vector<std::string> settings;  ///< parameter=value
  std::vector<std::string> plugin_paths;
  std::vector<double> temperature_range;  ///< [T_min, T_max] for SFCCs; empty: around T_f
  std::size_t samples = 2001;
};

/// Builds the model and prints its parameters and one line per violated rule.
int cmd_test_model(const TestModelOptions& options, std::ostream& out);

}  // namespace frostmpm::app
