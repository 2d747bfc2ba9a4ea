// GalerkinProduct (frostmpm/linalg): the coarse operator Pᵀ A P of a kept prolongator for new
// values of A — a multigrid refresh. Checked against the product done densely, for bitwise
// equality with a product set up afresh (a restart refreshes once where the run refreshed many
// times) and on any thread count.
#include <catch2/catch.hpp>

#include <omp.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "frostmpm/linalg/csr_matrix.hpp"
#include "frostmpm/linalg/galerkin_product.hpp"

using frostmpm::CsrMatrix;
using frostmpm::GalerkinProduct;

namespace {

/// 9-point stencil on an m × m node grid (the pattern of bilinear elements), values from `seed`:
/// symmetric, diagonally dominant. Rows list their columns in a scrambled order, as a caller's may.
CsrMatrix stencil_matrix(int m, double seed) {
  CsrMatrix A;
  A.rows = A.cols = std::size_t(m) * m;
  A.offsets.push_back(0);
  auto coupling = [&](int a, int b) {  // symmetric in (a, b)
    const int lo = std::min(a, b), hi = std::max(a, b);
    return -(1.0 + 0.5 * std::sin(seed * (lo + 1) + 0.37 * hi));
  };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const int row = j * m + i;
      double diagonal = 0.1;
      std::vector<std::pair<int, double>> entries;
      for (int dj = 1; dj >= -1; --dj)
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if ((di == 0 && dj == 0) || a < 0 || a >= m || b < 0 || b >= m) continue;
          const double c = coupling(row, b * m + a);
          entries.emplace_back(b * m + a, c);
          diagonal -= c;
        }
      entries.emplace_back(row, diagonal);
      for (const auto& [column, value] : entries) {
        A.columns.push_back(column);
        A.values.push_back(value);
      }
      A.offsets.push_back(A.columns.size());
    }
  return A;
}

/// Aggregates of 3 × 3 nodes, each fine node interpolated from its own aggregate and, with a
/// smaller weight, the next one along x (the overlap a smoothed prolongator has).
CsrMatrix aggregation_prolongator(int m) {
  const int a = (m + 2) / 3;
  CsrMatrix P;
  P.rows = std::size_t(m) * m;
  P.cols = std::size_t(a) * a;
  P.offsets.push_back(0);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const int own = (j / 3) * a + i / 3;
      P.columns.push_back(own);
      P.values.push_back(0.8 + 0.01 * (i % 3));
      if (i / 3 + 1 < a) {
        P.columns.push_back(own + 1);
        P.values.push_back(0.2 - 0.01 * (j % 3));
      }
      P.offsets.push_back(P.columns.size());
    }
  return P;
}

Eigen::MatrixXd dense(const CsrMatrix& M) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(Eigen::Index(M.rows), Eigen::Index(M.cols));
  for (std::size_t i = 0; i < M.rows; ++i)
    for (std::size_t k = M.offsets[i]; k < M.offsets[i + 1]; ++k) D(Eigen::Index(i), M.columns[k]) += M.values[k];
  return D;
}

}  // namespace

TEST_CASE("the Galerkin product is Pᵀ A P, the same bits however often it is refreshed and on any thread count",
          "[linalg]") {
  const int m = 70;  // 4 900 rows: above the size from which the passes run threaded
  const CsrMatrix A = stencil_matrix(m, 1.3), P = aggregation_prolongator(m);
  const GalerkinProduct product(A, P);

  const CsrMatrix coarse = product(A);
  REQUIRE(coarse.rows == P.cols);
  REQUIRE(coarse.cols == P.cols);
  const Eigen::MatrixXd expected = dense(P).transpose() * dense(A) * dense(P);
  const Eigen::MatrixXd got = dense(coarse);
  REQUIRE((got - expected).cwiseAbs().maxCoeff() <= 1e-12 * expected.cwiseAbs().maxCoeff());
  REQUIRE((got - got.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * expected.cwiseAbs().maxCoeff());
  for (std::size_t i = 0; i < coarse.rows; ++i)  // ascending columns in each row
    for (std::size_t k = coarse.offsets[i] + 1; k < coarse.offsets[i + 1]; ++k)
      REQUIRE(coarse.columns[k - 1] < coarse.columns[k]);
  REQUIRE(product.coarse_pattern().columns == coarse.columns);

  // New values on the same pattern, evaluated after others: the same bits as a product set up
  // for them alone (a restart's preconditioner is refreshed once, the run's many times).
  const CsrMatrix later = stencil_matrix(m, 2.9);
  const CsrMatrix refreshed = product(later);
  REQUIRE(refreshed.values == GalerkinProduct(later, P)(later).values);
  REQUIRE(refreshed.values != coarse.values);

  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const CsrMatrix one = product(later);
  omp_set_num_threads(2);
  const CsrMatrix two = product(later);
  omp_set_num_threads(threads);
  REQUIRE(one.values == two.values);
  REQUIRE(one.values == refreshed.values);

  // The chain to the next level works on the coarse pattern.
  const CsrMatrix P2 = aggregation_prolongator(int(std::lround(std::sqrt(double(P.cols)))));
  const GalerkinProduct next(product.coarse_pattern(), P2);
  const Eigen::MatrixXd expected2 = dense(P2).transpose() * got * dense(P2);
  REQUIRE((dense(next(coarse)) - expected2).cwiseAbs().maxCoeff() <= 1e-12 * expected2.cwiseAbs().maxCoeff());

  // Another matrix than the pattern's, or a prolongator of other rows, is refused.
  REQUIRE_THROWS_AS(product(stencil_matrix(m - 1, 1.3)), std::invalid_argument);
  REQUIRE_THROWS_AS(GalerkinProduct(A, aggregation_prolongator(m - 1)), std::invalid_argument);
}
