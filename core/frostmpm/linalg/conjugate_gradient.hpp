#pragma once
// Preconditioned conjugate gradients on a CsrMatrix, threaded with OpenMP: products by rows,
// dot products in fixed chunks (reproducible_sum), so the iterates are bitwise the same on any
// thread count. sparse_system.cpp says why this exists beside Belos.
#include <cstddef>
#include <span>
#include <vector>

#include "frostmpm/linalg/csr_matrix.hpp"

namespace frostmpm {

/// z ≈ A⁻¹ r: a fixed symmetric positive definite operator (CG needs it).
class LinearPreconditioner {
 public:
  virtual ~LinearPreconditioner() = default;
  virtual void apply(std::span<const double> r, std::span<double> z) = 0;
};

/// z = D⁻¹ r (rows whose diagonal is zero pass r through).
class JacobiPreconditioner final : public LinearPreconditioner {
 public:
  explicit JacobiPreconditioner(const CsrMatrix& A);
  /// From the diagonal a_ii itself (a caller that knows where its diagonal entries are).
  explicit JacobiPreconditioner(std::vector<double> diagonal);
  void apply(std::span<const double> r, std::span<double> z) override;

 private:
  std::vector<double> inverse_diagonal_;
};

/// Iterates on x (the initial guess on entry) until the recursively updated residual satisfies
/// ‖r‖ ≤ tolerance · ‖b‖ or max_iterations have run; returns the iterations taken.
/// `preconditioner` may be null (plain CG). Throws std::runtime_error when pᵀAp ≤ 0 or a
/// value turns non-finite (A not positive definite, or bad data).
int conjugate_gradient(const CsrMatrix& A, LinearPreconditioner* preconditioner, std::span<const double> b,
                       std::span<double> x, double tolerance, int max_iterations);

/// CG's vectors besides x and r, kept by a caller that solves many times (no allocation a solve).
struct ConjugateGradientWork {
  std::vector<double> z, p, q;
};
/// The same, with r = b − A x given on entry (a caller that has just measured the true residual
/// spends no product on it); r holds the updated residual on return.
int conjugate_gradient(const CsrMatrix& A, LinearPreconditioner* preconditioner, std::span<const double> b,
                       std::span<double> x, std::span<double> r, double tolerance, int max_iterations,
                       ConjugateGradientWork& work);

}  // namespace frostmpm
