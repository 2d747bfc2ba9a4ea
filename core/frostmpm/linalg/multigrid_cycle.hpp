#pragma once
// One symmetric multigrid V-cycle as a preconditioner, applied by our own threaded code on a
// hierarchy someone else built (MueLu's smoothed aggregation, in sparse_system.cpp).
//
// Smoother: hybrid symmetric Gauss–Seidel with the l1 correction (Baker, Falgout, Kolev & Yang
// 2011, SIAM J. Sci. Comput. 33:2864): rows split into ceil(rows / kSmootherBlockRows) blocks
// as equal as can be, Gauss–Seidel inside a block, the previous sweep's values across blocks,
// and each row's diagonal enlarged by the sum of |a_ij| over columns outside its block, which
// keeps the smoother convergent for any symmetric positive definite A however it is blocked.
// The blocks depend on the row count only, so the cycle is bitwise the same on any thread
// count. A forward sweep before the coarse correction and a backward one after it (V(1,1)) keep
// the cycle symmetric, as CG needs: the backward sweep's splitting is the transpose of the
// forward one's. The coarsest level is solved exactly (dense LDLᵀ).
#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "frostmpm/linalg/conjugate_gradient.hpp"
#include "frostmpm/linalg/csr_matrix.hpp"

namespace frostmpm {

class MultigridCycle final : public LinearPreconditioner {
 public:
  static constexpr std::size_t kSmootherBlockRows = 4096;
  /// A coarsest level (or a single one) above this many rows is smoothed, not factorised.
  static constexpr std::size_t kDirectCoarseRows = 3000;

  /// operators[0] is the finest matrix, operators[l + 1] = Rₗ Aₗ Pₗ its coarser ones;
  /// prolongators[l] maps level l + 1 to level l (one fewer than the operators). The restriction
  /// is Pₗᵀ: given in `restrictions` (as CsrMatrix::transpose makes it) or, when that is empty,
  /// transposed here. Throws std::invalid_argument for sizes that do not chain.
  MultigridCycle(std::vector<CsrMatrix> operators, std::vector<CsrMatrix> prolongators,
                 std::vector<CsrMatrix> restrictions = {});

  /// New values on the same patterns: operators[l] has the pattern (entries in the same order)
  /// of the l-th operator the cycle was built with. The same cycle, bit for bit, as one built
  /// from these operators, without its allocations and reordering. Throws std::invalid_argument
  /// when the count or a level's rows do not fit (row lengths are checked, columns are not).
  void refresh(std::span<const CsrMatrix* const> operators);

  /// z = one V-cycle applied to r from a zero guess.
  void apply(std::span<const double> r, std::span<double> z) override;
  std::size_t levels() const { return levels_.size(); }

 private:
  struct Level {
    CsrMatrix A, P, R;  ///< P, R: to and from the next coarser level (empty on the coarsest)
    std::size_t block_rows = 0;  ///< rows per smoother block (the last may hold fewer)
    /// Each row of A holds its block's columns first; they end here (the rest lie in other blocks).
    std::vector<std::size_t> in_block_end;
    /// Just past the row's last own-block column below the diagonal: a sweep from x = 0 reads
    /// nothing beyond it (every later column, and every other block's, still holds 0).
    std::vector<std::size_t> lower_end;
    std::vector<std::size_t> source;  ///< stored entry -> its position in the operator as given
    std::vector<double> inverse_l1_diagonal;
    std::vector<double> x, b, r, previous;
  };
  /// A's values and the l1 diagonal from `given` (the operator in its given entry order).
  static void load_values(Level& level, const CsrMatrix& given);
  void factorise_coarsest();
  void cycle(std::size_t l);
  /// forward from x = 0 (the cycle's first sweep on each level) or backward from the current x.
  void sweep(Level& level, bool forward);
  std::vector<Level> levels_;
  Eigen::LDLT<Eigen::MatrixXd> coarse_;
  bool coarse_direct_ = false;
};

}  // namespace frostmpm
