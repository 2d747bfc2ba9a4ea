#pragma once
// One error type for every kind of bad user input. The CLI prints what() on one line and
// exits with code 2; anything else escaping is a bug.
#include <stdexcept>
#include <string>
#include <vector>

namespace frostmpm {

/// Where in the input a value came from: file, YAML path (dotted) and 1-based line/column.
struct SourceLocation {
  std::string file;   ///< scene file, or "--set" for command-line overrides
  std::string path;   ///< dotted YAML path, e.g. "material.sfcc.lambda"
  int line = 0;       ///< 1-based; 0 when unknown
  int column = 0;

  /// "scene.yaml:12:5: at 'material.sfcc.lambda'" (parts omitted when unknown).
  std::string describe() const;
};

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  InputError(const SourceLocation& where, const std::string& message)
      : std::runtime_error(where.describe() + ": " + message) {}
  // Out of line: the vtable then lives in the core library, so an InputError thrown by plugin
  // code stays valid after that plugin's library is released during unwinding.
  ~InputError() override;
};

/// Exit code for every InputError (bad scene, bad option, bad plugin file).
inline constexpr int kInputErrorExitCode = 2;

/// Closest string in `candidates` by edit distance, or "" when nothing is reasonably close.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

/// The end of the first sentence of an "unknown X" message: "; did you mean 'width'?" when a
/// candidate is close, else "." — so that the list of valid ones after it reads as a sentence.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

/// "a, b, c" — used to list valid choices in messages.
std::string join(const std::vector<std::string>& items, const std::string& separator = ", ");

}  // namespace frostmpm
