#include "frostmpm/linalg/galerkin_product.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm {

namespace {

/// The pattern of the product L · Q: row i holds every column of Q's rows that L's row i names,
/// ascending.
CsrMatrix product_pattern(const CsrMatrix& L, const CsrMatrix& Q) {
  CsrMatrix out;
  out.rows = L.rows;
  out.cols = Q.cols;
  out.offsets.assign(L.rows + 1, 0);
  std::vector<std::size_t> marker(Q.cols, std::size_t(-1));
  std::vector<int> row;
  for (std::size_t i = 0; i < L.rows; ++i) {
    row.clear();
    for (std::size_t k = L.offsets[i]; k < L.offsets[i + 1]; ++k) {
      const auto j = std::size_t(L.columns[k]);
      for (std::size_t q = Q.offsets[j]; q < Q.offsets[j + 1]; ++q) {
        const auto c = std::size_t(Q.columns[q]);
        if (marker[c] != i) {
          marker[c] = i;
          row.push_back(int(c));
        }
      }
    }
    std::sort(row.begin(), row.end());
    out.columns.insert(out.columns.end(), row.begin(), row.end());
    out.offsets[i + 1] = out.columns.size();
  }
  out.values.assign(out.columns.size(), 0.0);
  return out;
}

/// out's values = L · Q on out's pattern (product_pattern(L, Q)). Each row accumulates in a dense
/// array of the thread's, in the order of L's entries and then Q's, and is gathered from it.
void multiply_into(const CsrMatrix& L, const CsrMatrix& Q, CsrMatrix& out) {
  const std::size_t rows = L.rows;
#pragma omp parallel if (rows >= kParallelMinimum)
  {
    std::vector<double> sum(Q.cols, 0.0);
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < rows; ++i) {
      for (std::size_t k = L.offsets[i]; k < L.offsets[i + 1]; ++k) {
        const double l = L.values[k];
        const auto j = std::size_t(L.columns[k]);
        for (std::size_t q = Q.offsets[j]; q < Q.offsets[j + 1]; ++q) sum[std::size_t(Q.columns[q])] += l * Q.values[q];
      }
      for (std::size_t e = out.offsets[i]; e < out.offsets[i + 1]; ++e) {
        double& s = sum[std::size_t(out.columns[e])];
        out.values[e] = s;
        s = 0.0;
      }
    }
  }
}

}  // namespace

GalerkinProduct::GalerkinProduct(const CsrMatrix& A, CsrMatrix P) : P_(std::move(P)) {
  if (A.rows != A.cols || P_.rows != A.rows || A.offsets.size() != A.rows + 1)
    throw std::invalid_argument("GalerkinProduct: A is " + std::to_string(A.rows) + " × " + std::to_string(A.cols) +
                                " and P has " + std::to_string(P_.rows) + " rows");
  R_ = P_.transpose();
  AP_ = product_pattern(A, P_);
  coarse_ = product_pattern(R_, AP_);
  fine_nonzeros_ = A.nonzeros();
}

CsrMatrix GalerkinProduct::operator()(const CsrMatrix& A) const {
  if (A.rows != P_.rows || A.nonzeros() != fine_nonzeros_)
    throw std::invalid_argument("GalerkinProduct: A has " + std::to_string(A.rows) + " rows and " +
                                std::to_string(A.nonzeros()) + " entries, its pattern had " +
                                std::to_string(P_.rows) + " and " + std::to_string(fine_nonzeros_));
  multiply_into(A, P_, AP_);
  CsrMatrix coarse = coarse_;
  multiply_into(R_, AP_, coarse);
  return coarse;
}

}  // namespace frostmpm
