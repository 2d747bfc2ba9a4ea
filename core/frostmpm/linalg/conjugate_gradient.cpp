#include "frostmpm/linalg/conjugate_gradient.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm {

JacobiPreconditioner::JacobiPreconditioner(const CsrMatrix& A) : JacobiPreconditioner(A.diagonal()) {}

JacobiPreconditioner::JacobiPreconditioner(std::vector<double> diagonal) : inverse_diagonal_(std::move(diagonal)) {
  for (double& d : inverse_diagonal_) d = d != 0 ? 1.0 / d : 1.0;
}

void JacobiPreconditioner::apply(std::span<const double> r, std::span<double> z) {
  parallel_for(r.size(), [&](std::size_t i) { z[i] = inverse_diagonal_[i] * r[i]; });
}

int conjugate_gradient(const CsrMatrix& A, LinearPreconditioner* preconditioner, std::span<const double> b,
                       std::span<double> x, double tolerance, int max_iterations) {
  std::vector<double> r(A.rows);
  A.residual(b, x, r);
  ConjugateGradientWork work;
  return conjugate_gradient(A, preconditioner, b, x, r, tolerance, max_iterations, work);
}

int conjugate_gradient(const CsrMatrix& A, LinearPreconditioner* preconditioner, std::span<const double> b,
                       std::span<double> x, std::span<double> r, double tolerance, int max_iterations,
                       ConjugateGradientWork& work) {
  const std::size_t n = A.rows;
  for (auto* v : {&work.z, &work.p, &work.q}) v->resize(n);
  auto &z = work.z, &p = work.p, &q = work.q;
  const double b_norm = std::sqrt(reproducible_sum(n, [&](std::size_t i) { return b[i] * b[i]; }));
  const double target = tolerance * b_norm;
  double r_norm2 = reproducible_sum(n, [&](std::size_t i) { return r[i] * r[i]; });
  if (std::sqrt(r_norm2) <= target) return 0;
  auto precondition = [&] {
    if (preconditioner)
      preconditioner->apply(r, z);
    else
      parallel_for(n, [&](std::size_t i) { z[i] = r[i]; });
  };
  precondition();
  std::copy(z.begin(), z.end(), p.begin());
  double rz = reproducible_sum(n, [&](std::size_t i) { return r[i] * z[i]; });
  int iteration = 0;
  while (iteration < max_iterations) {
    A.multiply(p, q);
    const double pq = reproducible_sum(n, [&](std::size_t i) { return p[i] * q[i]; });
    if (!(pq > 0) || !std::isfinite(pq) || !std::isfinite(rz))
      throw std::runtime_error("conjugate gradients broke down at iteration " + std::to_string(iteration) +
                               " (pᵀAp = " + std::to_string(pq) + "): the matrix is not positive definite");
    const double alpha = rz / pq;
    // x and r updated and ‖r‖² summed in one pass.
    r_norm2 = reproducible_sum(n, [&](std::size_t i) {
      x[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      return r[i] * r[i];
    });
    ++iteration;
    if (std::sqrt(r_norm2) <= target) break;
    precondition();
    const double rz_new = reproducible_sum(n, [&](std::size_t i) { return r[i] * z[i]; });
    const double beta = rz_new / rz;
    rz = rz_new;
    parallel_for(n, [&](std::size_t i) { p[i] = z[i] + beta * p[i]; });
  }
  return iteration;
}

}  // namespace frostmpm
