#include "frostmpm/io/log.hpp"

#include <memory>

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

namespace frostmpm::log {
namespace {

spdlog::level::level_enum to_spdlog(Level level) {
  switch (level) {
    case Level::debug: return spdlog::level::debug;
    case Level::info: return spdlog::level::info;
    case Level::warning: return spdlog::level::warn;
    case Level::error: return spdlog::level::err;
  }
  return spdlog::level::info;
}

/// One logger for the process: stderr, the message only, flushed at every line so it keeps
/// its place among lines written with std::cerr.
spdlog::logger& logger() {
  static const std::shared_ptr<spdlog::logger> instance = [] {
    auto made = std::make_shared<spdlog::logger>("frostmpm", std::make_shared<spdlog::sinks::stderr_sink_mt>());
    made->set_pattern("%v");
    made->set_level(spdlog::level::info);
    made->flush_on(spdlog::level::trace);
    return made;
  }();
  return *instance;
}

}  // namespace

void set_level(Level level) { logger().set_level(to_spdlog(level)); }
bool enabled(Level level) { return logger().should_log(to_spdlog(level)); }

void write(Level level, const std::string& text) { logger().log(to_spdlog(level), "{}", text); }
void debug(const std::string& text) { write(Level::debug, text); }
void info(const std::string& text) { write(Level::info, text); }
void warning(const std::string& text) { write(Level::warning, "warning: " + text); }
void error(const std::string& text) { write(Level::error, "error: " + text); }

}  // namespace frostmpm::log
