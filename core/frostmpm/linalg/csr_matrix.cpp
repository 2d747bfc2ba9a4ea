#include "frostmpm/linalg/csr_matrix.hpp"

#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm {

void CsrMatrix::multiply(std::span<const double> x, std::span<double> y) const {
  parallel_for(rows, [&](std::size_t i) {
    y[i] = row_dot(values.data(), columns.data(), offsets[i], offsets[i + 1], x.data());
  });
}

void CsrMatrix::multiply_add(std::span<const double> x, std::span<double> y) const {
  parallel_for(rows, [&](std::size_t i) {
    y[i] += row_dot(values.data(), columns.data(), offsets[i], offsets[i + 1], x.data());
  });
}

void CsrMatrix::residual(std::span<const double> b, std::span<const double> x, std::span<double> r) const {
  parallel_for(rows, [&](std::size_t i) {
    r[i] = b[i] - row_dot(values.data(), columns.data(), offsets[i], offsets[i + 1], x.data());
  });
}

CsrMatrix CsrMatrix::transpose() const {
  CsrMatrix t;
  t.rows = cols;
  t.cols = rows;
  t.offsets.assign(cols + 1, 0);
  for (int c : columns) ++t.offsets[std::size_t(c) + 1];
  for (std::size_t i = 0; i < cols; ++i) t.offsets[i + 1] += t.offsets[i];
  t.columns.resize(columns.size());
  t.values.resize(values.size());
  std::vector<std::size_t> next(t.offsets.begin(), t.offsets.end() - 1);
  for (std::size_t i = 0; i < rows; ++i)  // rows in order: each transposed row's columns ascend
    for (std::size_t k = offsets[i]; k < offsets[i + 1]; ++k) {
      const std::size_t at = next[std::size_t(columns[k])]++;
      t.columns[at] = int(i);
      t.values[at] = values[k];
    }
  return t;
}

std::vector<double> CsrMatrix::diagonal() const {
  std::vector<double> d(rows, 0.0);
  parallel_for(rows, [&](std::size_t i) {
    for (std::size_t k = offsets[i]; k < offsets[i + 1]; ++k)
      if (std::size_t(columns[k]) == i) d[i] += values[k];
  });
  return d;
}

}  // namespace frostmpm
