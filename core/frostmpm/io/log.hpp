#pragma once
// Messages of a run (warnings, info and progress lines, debug detail), through spdlog with a
// plain pattern: a line is exactly the text given, "warning: " or "error: " in front of
// warnings and errors, on stderr. spdlog stays private to the core library.
//
// Errors that end a run (InputError, exit code 2) are printed by the program itself, never
// through here, so --quiet cannot hide them.
#include <string>

namespace frostmpm::log {

enum class Level { debug, info, warning, error };

/// Messages below `level` are dropped (default: info). `frostmpm run --quiet` sets warning,
/// `--verbose` debug.
void set_level(Level level);
bool enabled(Level level);

void debug(const std::string& text);
void info(const std::string& text);
void warning(const std::string& text);  ///< "warning: <text>"
void error(const std::string& text);    ///< "error: <text>"
/// `text` as it is, at `level` (for a line that carries its own wording).
void write(Level level, const std::string& text);

}  // namespace frostmpm::log
