#pragma once
// Shared-memory parallel loops (OpenMP, GCC's libgomp) whose results do not depend on the
// thread count. Loops that only write their own index are trivially reproducible; sums use
// fixed chunks (independent of the thread count) added in chunk order, so a total is bitwise
// the same on 1 or N threads. Scatters to grid nodes go through ColouredBlocks.
#include <algorithm>
#include <cstddef>
#include <exception>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace frostmpm {

/// Threads an OpenMP parallel region will use.
inline int thread_count() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/// Below this many iterations a loop runs on the calling thread: waking the team costs more
/// than a small scene's loop (and far more on a loaded machine). Serial and parallel runs of
/// these loops give the same bits, so the threshold changes no result.
inline constexpr std::size_t kParallelMinimum = 4096;

/// f(i) for i in [0, n), statically split over the threads.
template <class F>
void parallel_for(std::size_t n, F&& f) {
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
  for (std::size_t i = 0; i < n; ++i) f(i);
}

/// f(begin, count) over [0, n) cut into chunks of `chunk` indices (fixed, whatever the thread
/// count), which the threads share: for batched model calls (one virtual call per chunk), each
/// chunk on its own. An exception thrown by f is rethrown here, the first chunk's.
template <class F>
void parallel_chunks(std::size_t n, std::size_t chunk, F&& f) {
  const std::size_t chunks = (n + chunk - 1) / chunk;
  std::vector<std::exception_ptr> errors(chunks);
#pragma omp parallel for schedule(static) if (chunks > 1)
  for (std::size_t c = 0; c < chunks; ++c) {
    try {
      f(c * chunk, std::min(chunk, n - c * chunk));
    } catch (...) {
      errors[c] = std::current_exception();
    }
  }
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
}

/// A reduction over [0, n) whose result is bitwise the same whatever the thread count: the
/// range is cut into fixed chunks of 2048 indices; each chunk starts from `init` and takes
/// body(i, acc) for its indices in order; the chunks' results are then folded in chunk order,
/// total = combine(total, chunk) from total = init. For several sums (and maxima) in one pass.
template <class Acc, class Body, class Combine>
Acc ordered_chunk_reduce(std::size_t n, const Acc& init, Body&& body, Combine&& combine) {
  constexpr std::size_t kChunk = 2048;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<Acc> partial(chunks, init);
#pragma omp parallel for schedule(static) if (chunks > 1)
  for (std::size_t c = 0; c < chunks; ++c) {
    Acc acc = init;
    const std::size_t end = std::min(n, (c + 1) * kChunk);
    for (std::size_t i = c * kChunk; i < end; ++i) body(i, acc);
    partial[c] = acc;
  }
  Acc total = init;
  for (const Acc& acc : partial) total = combine(total, acc);
  return total;
}

/// Σ f(i) over [0, n), reproducible bitwise whatever the thread count (ordered_chunk_reduce).
template <class F>
double reproducible_sum(std::size_t n, F&& f) {
  return ordered_chunk_reduce(
      n, 0.0, [&](std::size_t i, double& s) { s += f(i); }, [](double a, double b) { return a + b; });
}

/// max f(i) over [0, n) (exact in any order), or `empty` when n = 0.
template <class F>
double parallel_max(std::size_t n, F&& f, double empty) {
  double m = empty;
#pragma omp parallel for schedule(static) reduction(max : m) if (n >= kParallelMinimum)
  for (std::size_t i = 0; i < n; ++i) m = std::max(m, f(i));
  return m;
}

/// min f(i) over [0, n) (exact in any order), or `empty` when n = 0.
template <class F>
double parallel_min(std::size_t n, F&& f, double empty) {
  return -parallel_max(n, [&](std::size_t i) { return -f(i); }, -empty);  // negation is exact
}

}  // namespace frostmpm
