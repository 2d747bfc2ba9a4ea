#include "frostmpm/simulation/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace frostmpm {

namespace {

std::atomic<int> requested{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free flag");

constexpr int kSignals[] = {SIGINT, SIGTERM};
struct sigaction previous[2];
bool handled[2] = {false, false};

extern "C" void request_stop(int signal) {
  int none = 0;
  requested.compare_exchange_strong(none, signal);
  // sigaction is async-signal-safe: a second signal now takes the default action.
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  for (int i = 0; i < 2; ++i)
    if (handled[i]) sigaction(kSignals[i], &fallback, nullptr);
}

}  // namespace

InterruptGuard::InterruptGuard() {
  requested = 0;
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // file writes in progress are resumed, not failed with EINTR
  for (int i = 0; i < 2; ++i) {
    sigaction(kSignals[i], nullptr, &previous[i]);
    // A signal ignored on entry stays ignored (as for any program, e.g. SIGINT of a background
    // job started by a script).
    handled[i] = previous[i].sa_handler != SIG_IGN;
    if (handled[i]) sigaction(kSignals[i], &action, nullptr);
  }
}

InterruptGuard::~InterruptGuard() {
  for (int i = 0; i < 2; ++i)
    if (handled[i]) sigaction(kSignals[i], &previous[i], nullptr);
  requested = 0;  // a later run in this process starts without a stop request
}

int interrupt_signal() { return requested.load(); }

}  // namespace frostmpm
