#pragma once
// The coarse operator Pᵀ A P of a multigrid level, for a prolongator P that is kept while A's
// values change (a preconditioner refresh): the patterns of A P and Pᵀ A P are worked out once,
// and each evaluation is two row-parallel passes of multiply–adds. Every entry sums its terms in
// an order fixed by the patterns (A's rows, then P's), so the result is bitwise the same on any
// thread count, and the same for the same values however often it has been evaluated.
#include <cstddef>

#include "frostmpm/linalg/csr_matrix.hpp"

namespace frostmpm {

class GalerkinProduct {
 public:
  /// For A's pattern (its values are not read; explicit zeros count as entries) and P, whose
  /// rows are A's. Throws std::invalid_argument when the sizes do not fit.
  GalerkinProduct(const CsrMatrix& A, CsrMatrix P);

  /// Pᵀ A P for an A with the pattern the constructor saw (its entries in the same order);
  /// each row's columns ascend.
  CsrMatrix operator()(const CsrMatrix& A) const;

  const CsrMatrix& prolongator() const { return P_; }
  const CsrMatrix& restriction() const { return R_; }  ///< Pᵀ, each row's columns ascending
  /// The pattern of Pᵀ A P (values zero): the fine pattern of the next coarser product.
  const CsrMatrix& coarse_pattern() const { return coarse_; }

 private:
  CsrMatrix P_, R_;       ///< R = Pᵀ
  mutable CsrMatrix AP_;  ///< pattern of A P; values are the evaluation's scratch
  CsrMatrix coarse_;
  std::size_t fine_nonzeros_ = 0;
};

}  // namespace frostmpm
