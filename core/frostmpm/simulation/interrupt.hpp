#pragma once
// SIGINT and SIGTERM as a request to stop cleanly: while an InterruptGuard is alive, the first
// of them only sets a flag (the handler is async-signal-safe) and restores the default
// actions, so a second one ends the process at once. The run loop polls the flag after each
// step, writes a checkpoint and the current outputs, and stops (Simulation::run throws
// RunInterrupted). A signal that was ignored when the guard was made stays ignored.
namespace frostmpm {

class InterruptGuard {
 public:
  /// Clears the flag and installs the handlers.
  InterruptGuard();
  /// Puts back the handlers that were there before and clears the flag.
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
};

/// The signal that asked the run to stop (SIGINT or SIGTERM), or 0.
int interrupt_signal();

}  // namespace frostmpm
