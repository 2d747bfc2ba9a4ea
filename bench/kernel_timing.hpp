#pragma once
// The timing harness the reference kernels share (roofline.cpp, elastic_kernel.cpp): their
// command-line options, one untimed warm-up step, repetitions of a step count that depends on
// the size only (so a command line's checksum is the same on any thread count), the median and
// best particle-steps/s, and the CPU share of the threads while timed.
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm::bench {

struct TimingOptions {
  long particles = 120000;
  int threads = 0, repeat = 5, steps = 0;
  double work = 2e6, max_seconds = 5.0;
  bool json = false;
};

/// --particles, --threads, --repeat, --steps, --work, --max-seconds, --json.
inline void add_timing_options(CLI::App& cli, TimingOptions& o) {
  cli.add_option("--particles", o.particles,
                 "particle count on a 3 m x 1 m block of cells 3n x n, 2 x 2 per cell (rounded to 12 n^2)")
      ->check(CLI::PositiveNumber);
  cli.add_option("--threads", o.threads, "OpenMP threads (default: OMP_NUM_THREADS or all cores)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--repeat", o.repeat, "timed repetitions; the median and best are reported")
      ->check(CLI::PositiveNumber);
  cli.add_option("--steps", o.steps, "steps per repetition (default: --work / particles)")
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--work", o.work, "particle-steps per repetition when --steps is not given")
      ->check(CLI::PositiveNumber);
  cli.add_option("--max-seconds", o.max_seconds,
                 "stop repeating once the timed repetitions took this long (a loaded machine can make a "
                 "2-thread run 50x slower); at least one repetition runs")
      ->check(CLI::PositiveNumber);
  cli.add_flag("--json", o.json, "print one JSON object instead of lines");
}

/// Cells along y of the scenes' 3 m x 1 m block (cells 3n x n, 4 particles per cell: 12 n²).
inline int block_cells_y(long particles) {
  return std::max(1, static_cast<int>(std::lround(std::sqrt(particles / 12.0))));
}

struct Timing {
  int steps = 0, repetitions = 0;
  double median = 0, best = 0;  ///< particle-steps/s
  double cpu_share = 0;         ///< near 1 when every thread had a core to itself
};

/// CPU seconds of every thread of this process so far (user + system).
inline double process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

/// Times kernel.step() (kernel.n particles) as the options say.
template <class Kernel>
Timing time_steps(Kernel& kernel, const TimingOptions& o) {
  using Clock = std::chrono::steady_clock;
  Timing t;
  t.steps = o.steps > 0 ? o.steps : std::max(1, static_cast<int>(std::ceil(o.work / static_cast<double>(kernel.n))));
  kernel.step();  // warm-up, not timed: first touch of every array, thread start-up
  std::vector<double> rates;
  double timed_seconds = 0;
  const double cpu_start = process_cpu_seconds();
  for (int r = 0; r < o.repeat && timed_seconds < o.max_seconds; ++r) {
    const auto start = Clock::now();
    for (int s = 0; s < t.steps; ++s) kernel.step();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    timed_seconds += seconds;
    rates.push_back(static_cast<double>(kernel.n) * t.steps / seconds);
  }
  t.repetitions = static_cast<int>(rates.size());
  // Waiting threads that sleep use no CPU; spinning ones still count.
  t.cpu_share = (process_cpu_seconds() - cpu_start) / (timed_seconds * thread_count());
  std::sort(rates.begin(), rates.end());
  t.median = rates.size() % 2 ? rates[rates.size() / 2] : 0.5 * (rates[rates.size() / 2 - 1] + rates[rates.size() / 2]);
  t.best = rates.back();
  return t;
}

/// The lines every kernel prints about its timing.
inline void print_timing(const Timing& t, const TimingOptions& o) {
  std::printf("threads %d, %d repetitions of %d steps after one warm-up step%s\n", thread_count(), t.repetitions,
              t.steps, t.repetitions < o.repeat ? " (cut by --max-seconds)" : "");
  std::printf("particle-steps/s  median %.4g  best %.4g\n", t.median, t.best);
  std::printf("CPU share of the threads while timed %.2f\n", t.cpu_share);
}

}  // namespace frostmpm::bench
