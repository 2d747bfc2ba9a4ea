// The project's own threaded Krylov pieces (frostmpm/linalg): CsrMatrix, conjugate_gradient and
// MultigridCycle. SparseSystem's tests cover them behind its interface; these check the
// properties CG relies on directly: a symmetric positive definite V-cycle, bitwise the same on
// any thread count, that converges on a coefficient jump of six orders (frozen against thawed
// soil).
#include <catch2/catch.hpp>

#include <omp.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "frostmpm/linalg/conjugate_gradient.hpp"
#include "frostmpm/linalg/csr_matrix.hpp"
#include "frostmpm/linalg/multigrid_cycle.hpp"

using frostmpm::conjugate_gradient;
using frostmpm::CsrMatrix;
using frostmpm::JacobiPreconditioner;
using frostmpm::MultigridCycle;

namespace {

/// Cell-centred 5-point diffusion on an m × m grid, Dirichlet walls, conductivity 1 outside the
/// middle third and 1e-6 inside (harmonic means on the faces).
CsrMatrix jump_matrix(int m) {
  auto k = [&](int i, int j) { return (i >= m / 3 && i < 2 * m / 3 && j >= m / 3 && j < 2 * m / 3) ? 1e-6 : 1.0; };
  CsrMatrix A;
  A.rows = A.cols = std::size_t(m) * m;
  A.offsets.push_back(0);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      double diagonal = 0;
      const int di[] = {1, -1, 0, 0}, dj[] = {0, 0, 1, -1};
      for (int f = 0; f < 4; ++f) {
        const int a = i + di[f], b = j + dj[f];
        const bool inside = a >= 0 && a < m && b >= 0 && b < m;
        const double face = inside ? 2 * k(i, j) * k(a, b) / (k(i, j) + k(a, b)) : 2 * k(i, j);
        diagonal += face;
        if (inside) {
          A.columns.push_back(b * m + a);
          A.values.push_back(-face);
        }
      }
      A.columns.push_back(j * m + i);
      A.values.push_back(diagonal);
      A.offsets.push_back(A.columns.size());
    }
  return A;
}

/// Piecewise-constant prolongation from 2 × 2 aggregates (m even).
CsrMatrix aggregation(int m) {
  CsrMatrix P;
  P.rows = std::size_t(m) * m;
  P.cols = P.rows / 4;
  P.offsets.push_back(0);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      P.columns.push_back((j / 2) * (m / 2) + i / 2);
      P.values.push_back(1.0);
      P.offsets.push_back(P.columns.size());
    }
  return P;
}

/// Pᵀ A P, dense-accumulated per row (small test sizes).
CsrMatrix galerkin(const CsrMatrix& A, const CsrMatrix& P) {
  const CsrMatrix R = P.transpose();
  CsrMatrix C;
  C.rows = C.cols = P.cols;
  C.offsets.push_back(0);
  std::vector<double> row(P.cols, 0.0);
  std::vector<double> ap(A.cols);
  for (std::size_t I = 0; I < R.rows; ++I) {
    std::fill(row.begin(), row.end(), 0.0);
    for (std::size_t k = R.offsets[I]; k < R.offsets[I + 1]; ++k) {
      const auto i = std::size_t(R.columns[k]);  // a fine row of aggregate I
      for (std::size_t l = A.offsets[i]; l < A.offsets[i + 1]; ++l) {
        const auto j = std::size_t(A.columns[l]);
        for (std::size_t m = P.offsets[j]; m < P.offsets[j + 1]; ++m)
          row[std::size_t(P.columns[m])] += R.values[k] * A.values[l] * P.values[m];
      }
    }
    for (std::size_t J = 0; J < P.cols; ++J)
      if (row[J] != 0) {
        C.columns.push_back(int(J));
        C.values.push_back(row[J]);
      }
    C.offsets.push_back(C.columns.size());
  }
  return C;
}

/// Three levels: m² → (m/2)² → (m/4)² (the coarsest solved directly).
MultigridCycle three_levels(const CsrMatrix& A, int m) {
  const CsrMatrix P0 = aggregation(m), A1 = galerkin(A, P0);
  const CsrMatrix P1 = aggregation(m / 2), A2 = galerkin(A1, P1);
  return MultigridCycle({A, A1, A2}, {P0, P1});
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

std::vector<double> wiggly(std::size_t n, double phase) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::sin(0.37 * double(i) + phase) + 0.1 * std::cos(0.011 * double(i));
  return v;
}

}  // namespace

TEST_CASE("A multigrid V-cycle with hybrid l1 Gauss-Seidel is symmetric, positive and thread-count independent",
          "[linalg]") {
  const int m = 96;  // 9216 rows: three smoother blocks on the finest level
  const CsrMatrix A = jump_matrix(m);
  MultigridCycle cycle = three_levels(A, m);
  REQUIRE(cycle.levels() == 3);
  const std::size_t n = A.rows;
  const auto u = wiggly(n, 0.0), v = wiggly(n, 1.3);
  std::vector<double> Bu(n), Bv(n), Bu_one_thread(n);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  cycle.apply(u, Bu_one_thread);
  omp_set_num_threads(2);
  cycle.apply(u, Bu);
  cycle.apply(v, Bv);
  omp_set_num_threads(threads);
  REQUIRE(Bu == Bu_one_thread);  // bitwise
  const double uBv = dot(u, Bv), vBu = dot(v, Bu);
  INFO("u'Bv " << uBv << ", v'Bu " << vBu);
  REQUIRE(std::abs(uBv - vBu) <= 1e-11 * std::abs(uBv));
  REQUIRE(dot(u, Bu) > 0);
  REQUIRE(dot(v, Bv) > 0);

  // The restrictions handed in (a refresh reuses its build's Pᵀ) give the same cycle bit for bit;
  // one that is not a prolongator's transpose is refused.
  const CsrMatrix P0 = aggregation(m), A1 = galerkin(A, P0), P1 = aggregation(m / 2), A2 = galerkin(A1, P1);
  MultigridCycle given({A, A1, A2}, {P0, P1}, {P0.transpose(), P1.transpose()});
  std::vector<double> Bu_given(n);
  given.apply(u, Bu_given);
  REQUIRE(Bu_given == Bu);
  REQUIRE_THROWS_AS(MultigridCycle({A, A1, A2}, {P0, P1}, {P0.transpose()}), std::invalid_argument);
  REQUIRE_THROWS_AS(MultigridCycle({A, A1, A2}, {P0, P1}, {P1.transpose(), P0.transpose()}), std::invalid_argument);
}

TEST_CASE("CG with the V-cycle converges across a six-order coefficient jump, Jacobi far slower", "[linalg]") {
  for (int m : {48, 96}) {
    const CsrMatrix A = jump_matrix(m);
    MultigridCycle cycle = three_levels(A, m);
    JacobiPreconditioner jacobi(A);
    const auto x_exact = wiggly(A.rows, 0.5);
    std::vector<double> b(A.rows);
    A.multiply(x_exact, b);
    std::vector<double> x(A.rows, 0.0), y(A.rows, 0.0), r(A.rows);
    const int its = conjugate_gradient(A, &cycle, b, x, 1e-10, 500);
    const int jacobi_its = conjugate_gradient(A, &jacobi, b, y, 1e-10, 5000);
    A.residual(b, x, r);
    INFO("m " << m << ": multigrid " << its << ", Jacobi " << jacobi_its << " iterations");
    REQUIRE(std::sqrt(dot(r, r) / dot(b, b)) <= 1e-10);
    REQUIRE(its <= 40);
    REQUIRE(jacobi_its > 4 * its);
    // A warm start at the answer needs no iteration.
    REQUIRE(conjugate_gradient(A, &cycle, b, x, 1e-8, 500) == 0);
  }
}

TEST_CASE("The l1 hybrid smoother alone converges as a stationary iteration", "[linalg]") {
  const int m = 96;
  const CsrMatrix A = jump_matrix(m);
  MultigridCycle smoother({A}, {});  // one level: smoothing only
  const auto x_exact = wiggly(A.rows, 0.2);
  std::vector<double> b(A.rows), x(A.rows, 0.0), r(A.rows), z(A.rows);
  A.multiply(x_exact, b);
  auto energy_error = [&] {
    std::vector<double> e(A.rows), Ae(A.rows);
    for (std::size_t i = 0; i < e.size(); ++i) e[i] = x[i] - x_exact[i];
    A.multiply(e, Ae);
    return dot(e, Ae);
  };
  double previous = energy_error();
  for (int k = 0; k < 20; ++k) {
    A.residual(b, x, r);
    smoother.apply(r, z);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += z[i];
    const double now = energy_error();
    REQUIRE(now < previous);  // the A-norm of the error falls every sweep
    previous = now;
  }
}

TEST_CASE("CG refuses an indefinite matrix", "[linalg]") {
  CsrMatrix A;
  A.rows = A.cols = 2;
  A.offsets = {0, 1, 2};
  A.columns = {0, 1};
  A.values = {1.0, -1.0};
  std::vector<double> b{1.0, 1.0}, x{0.0, 0.0};
  REQUIRE_THROWS_AS(conjugate_gradient(A, nullptr, b, x, 1e-10, 10), std::runtime_error);
}

TEST_CASE("row_dot_until gives row_dot's bits when the terms it leaves out are zero", "[linalg]") {
  // Rows of every length up to 13 (whole groups of four, a tail, both) cut at every position:
  // the values past the cut multiply x = 0 (of either sign), which row_dot adds and
  // row_dot_until does not read.
  for (std::size_t length = 0; length <= 13; ++length)
    for (std::size_t stop = 0; stop <= length; ++stop) {
      std::vector<double> values(length), x(length);
      std::vector<int> columns(length);
      for (std::size_t k = 0; k < length; ++k) {
        values[k] = std::sin(1.7 * double(k) + 0.3 * double(length)) * 1e3;
        columns[k] = int((k * 7 + 3) % length);  // any order
      }
      for (std::size_t k = 0; k < length; ++k)
        x[std::size_t(columns[k])] = k < stop ? std::cos(0.9 * double(k)) : (k % 2 ? -0.0 : 0.0);
      // Four interleaved partial sums, the leftover terms in the first: the order every product
      // of the project's matrices has always summed in.
      double s[4] = {0, 0, 0, 0};
      std::size_t k = 0;
      for (; k + 4 <= length; k += 4)
        for (std::size_t lane = 0; lane < 4; ++lane) s[lane] += values[k + lane] * x[std::size_t(columns[k + lane])];
      for (; k < length; ++k) s[0] += values[k] * x[std::size_t(columns[k])];
      const double reference = (s[0] + s[1]) + (s[2] + s[3]);
      const double full = frostmpm::row_dot(values.data(), columns.data(), 0, length, x.data());
      REQUIRE(std::memcmp(&full, &reference, sizeof full) == 0);
      const double cut = frostmpm::row_dot_until(values.data(), columns.data(), 0, length, stop, x.data());
      INFO("length " << length << ", stop " << stop);
      REQUIRE(std::memcmp(&full, &cut, sizeof full) == 0);
    }
}

TEST_CASE("A refreshed V-cycle is the cycle built from the new values, bit for bit", "[linalg]") {
  const int m = 96;  // three smoother blocks on the finest level
  CsrMatrix A = jump_matrix(m);
  const CsrMatrix P0 = aggregation(m), P1 = aggregation(m / 2);
  MultigridCycle cycle({A, galerkin(A, P0), galerkin(galerkin(A, P0), P1)}, {P0, P1});
  // New values on the same patterns: the jump moved by scaling every other row's couplings.
  for (std::size_t i = 0; i < A.rows; ++i)
    for (std::size_t k = A.offsets[i]; k < A.offsets[i + 1]; ++k) A.values[k] *= 1.0 + 0.25 * std::sin(double(i + std::size_t(A.columns[k])));
  const CsrMatrix A1 = galerkin(A, P0), A2 = galerkin(A1, P1);
  const CsrMatrix* levels[] = {&A, &A1, &A2};
  cycle.refresh(levels);
  MultigridCycle fresh({A, A1, A2}, {P0, P1});
  const auto u = wiggly(A.rows, 0.4);
  std::vector<double> refreshed(A.rows), built(A.rows);
  cycle.apply(u, refreshed);
  fresh.apply(u, built);
  REQUIRE(refreshed == built);  // bitwise

  const CsrMatrix* too_few[] = {&A, &A1};
  REQUIRE_THROWS_AS(cycle.refresh(too_few), std::invalid_argument);
  const CsrMatrix* wrong_level[] = {&A, &A2, &A1};
  REQUIRE_THROWS_AS(cycle.refresh(wrong_level), std::invalid_argument);
}
