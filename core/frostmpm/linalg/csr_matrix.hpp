#pragma once
// A compressed-sparse-row matrix with the few threaded operations the project's own Krylov
// solver needs (sparse_system.cpp says why the solver is our own). Rows are independent, so
// every product is bitwise the same on any thread count.
#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

namespace frostmpm {

/// Σ values[k] x[columns[k]] over [begin, min(stop, end)) in four interleaved partial sums, each
/// term in the sum it would take over [begin, end): one running sum is a chain of dependent
/// multiply–adds (4 cycles each), which the Gauss–Seidel sweep, whose next row waits for this one,
/// cannot hide; four chains run at the memory's pace. With stop < end it is bitwise the sum over
/// [begin, end) when the terms from stop on are ±0 (an addend ±0 leaves a sum that started from
/// +0 unchanged): for an x that is zero at the columns of a row's tail, which need not be read.
inline double row_dot_until(const double* values, const int* columns, std::size_t begin, std::size_t end,
                            std::size_t stop, const double* x) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  const std::size_t groups_end = begin + (end - begin) / 4 * 4;  // row_dot's four-wide part
  const std::size_t groups_stop = std::min(stop, groups_end);
  std::size_t k = begin;
  for (; k + 4 <= groups_stop; k += 4) {
    s0 += values[k] * x[columns[k]];
    s1 += values[k + 1] * x[columns[k + 1]];
    s2 += values[k + 2] * x[columns[k + 2]];
    s3 += values[k + 3] * x[columns[k + 3]];
  }
  if (k < groups_stop) {  // a group cut short by stop
    s0 += values[k] * x[columns[k]];
    if (k + 1 < groups_stop) s1 += values[k + 1] * x[columns[k + 1]];
    if (k + 2 < groups_stop) s2 += values[k + 2] * x[columns[k + 2]];
  }
  for (k = groups_end; k < std::min(stop, end); ++k) s0 += values[k] * x[columns[k]];
  return (s0 + s1) + (s2 + s3);
}

/// row_dot_until over the whole of [begin, end).
inline double row_dot(const double* values, const int* columns, std::size_t begin, std::size_t end,
                      const double* x) {
  return row_dot_until(values, columns, begin, end, end, x);
}

struct CsrMatrix {
  std::size_t rows = 0, cols = 0;
  std::vector<std::size_t> offsets;  ///< rows + 1 entries
  std::vector<int> columns;          ///< any order within a row
  std::vector<double> values;

  std::size_t nonzeros() const { return columns.size(); }
  /// y = A x.
  void multiply(std::span<const double> x, std::span<double> y) const;
  /// y += A x.
  void multiply_add(std::span<const double> x, std::span<double> y) const;
  /// r = b − A x.
  void residual(std::span<const double> b, std::span<const double> x, std::span<double> r) const;
  /// Aᵀ, each row's columns ascending.
  CsrMatrix transpose() const;
  /// a_ii (0 where the pattern has no diagonal entry).
  std::vector<double> diagonal() const;
};

}  // namespace frostmpm
