#include "frostmpm/linalg/multigrid_cycle.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm {

MultigridCycle::MultigridCycle(std::vector<CsrMatrix> operators, std::vector<CsrMatrix> prolongators,
                               std::vector<CsrMatrix> restrictions) {
  if (operators.empty() || prolongators.size() + 1 != operators.size())
    throw std::invalid_argument("MultigridCycle: needs one prolongator fewer than operators (got " +
                                std::to_string(operators.size()) + " and " + std::to_string(prolongators.size()) +
                                ")");
  if (!restrictions.empty() && restrictions.size() != prolongators.size())
    throw std::invalid_argument("MultigridCycle: needs a restriction per prolongator or none (got " +
                                std::to_string(restrictions.size()) + " and " + std::to_string(prolongators.size()) +
                                ")");
  levels_.resize(operators.size());
  for (std::size_t l = 0; l < operators.size(); ++l) {
    Level& level = levels_[l];
    const CsrMatrix& given = operators[l];  // as handed in: A holds its entries reordered (below)
    const std::size_t n = given.rows;
    if (given.cols != n) throw std::invalid_argument("MultigridCycle: operator " + std::to_string(l) + " not square");
    if (l + 1 < operators.size()) {
      level.P = std::move(prolongators[l]);
      if (level.P.rows != n || level.P.cols != operators[l + 1].rows)
        throw std::invalid_argument("MultigridCycle: prolongator " + std::to_string(l) + " is " +
                                    std::to_string(level.P.rows) + " × " + std::to_string(level.P.cols) +
                                    ", levels have " + std::to_string(n) + " and " +
                                    std::to_string(operators[l + 1].rows) + " rows");
      level.R = restrictions.empty() ? level.P.transpose() : std::move(restrictions[l]);
      if (level.R.rows != level.P.cols || level.R.cols != level.P.rows || level.R.nonzeros() != level.P.nonzeros())
        throw std::invalid_argument("MultigridCycle: restriction " + std::to_string(l) +
                                    " is not the prolongator's transpose");
    }
    // Equal blocks, so that 2, 4 or 8 threads share the sweep evenly.
    const std::size_t blocks = std::max<std::size_t>(1, (n + kSmootherBlockRows - 1) / kSmootherBlockRows);
    level.block_rows = std::max<std::size_t>(1, (n + blocks - 1) / blocks);
    // Each row's own-block columns first (a stable partition: the row's sums keep one order);
    // `source` remembers where each stored entry came from, so that a refresh only moves values.
    level.in_block_end.assign(n, 0);
    level.lower_end.assign(n, 0);
    auto& A = level.A;
    A.rows = A.cols = n;
    A.offsets = given.offsets;
    A.columns.resize(given.nonzeros());
    A.values.resize(given.nonzeros());
    level.source.resize(given.nonzeros());
    std::vector<std::size_t> outside;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t block_begin = i / level.block_rows * level.block_rows;
      const std::size_t block_end = std::min(n, block_begin + level.block_rows);
      std::size_t inside = A.offsets[i];
      outside.clear();
      for (std::size_t k = A.offsets[i]; k < A.offsets[i + 1]; ++k) {
        const auto j = std::size_t(given.columns[k]);
        if (j >= block_begin && j < block_end)
          level.source[inside++] = k;
        else
          outside.push_back(k);
      }
      level.in_block_end[i] = inside;
      for (const std::size_t k : outside) level.source[inside++] = k;
      for (std::size_t q = A.offsets[i]; q < A.offsets[i + 1]; ++q) A.columns[q] = given.columns[level.source[q]];
      level.lower_end[i] = A.offsets[i];
      for (std::size_t q = A.offsets[i]; q < level.in_block_end[i]; ++q)
        if (std::size_t(A.columns[q]) < i) level.lower_end[i] = q + 1;
    }
    load_values(level, given);
    for (auto* v : {&level.x, &level.b, &level.r, &level.previous}) v->assign(n, 0.0);
  }
  // A single level small enough is solved directly too: MueLu makes no coarser level for a
  // matrix at or below its coarse size, which its own cycle then solved exactly.
  coarse_direct_ = levels_.back().A.rows <= kDirectCoarseRows;
  factorise_coarsest();
}

void MultigridCycle::load_values(Level& level, const CsrMatrix& given) {
  auto& A = level.A;
  const std::size_t n = A.rows;
  level.inverse_l1_diagonal.resize(n);
  parallel_for(n, [&](std::size_t i) {
    const std::size_t block_begin = i / level.block_rows * level.block_rows;
    const std::size_t block_end = std::min(n, block_begin + level.block_rows);
    // The l1-enlarged diagonal a_ii + Σ |a_ij| over the columns outside the row's block.
    double d = 0;
    for (std::size_t k = given.offsets[i]; k < given.offsets[i + 1]; ++k) {
      const auto j = std::size_t(given.columns[k]);
      if (j < block_begin || j >= block_end)
        d += std::abs(given.values[k]);
      else if (j == i)
        d += given.values[k];
    }
    level.inverse_l1_diagonal[i] = d != 0 ? 1.0 / d : 0.0;
    for (std::size_t q = A.offsets[i]; q < A.offsets[i + 1]; ++q) A.values[q] = given.values[level.source[q]];
  });
}

void MultigridCycle::factorise_coarsest() {
  if (!coarse_direct_) return;
  const Level& coarsest = levels_.back();
  const std::size_t n = coarsest.A.rows;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(Eigen::Index(n), Eigen::Index(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = coarsest.A.offsets[i]; k < coarsest.A.offsets[i + 1]; ++k)
      dense(Eigen::Index(i), coarsest.A.columns[k]) += coarsest.A.values[k];
  coarse_.compute(dense);
}

void MultigridCycle::refresh(std::span<const CsrMatrix* const> operators) {
  if (operators.size() != levels_.size())
    throw std::invalid_argument("MultigridCycle::refresh: " + std::to_string(operators.size()) + " operators for " +
                                std::to_string(levels_.size()) + " levels");
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    const CsrMatrix& given = *operators[l];
    if (given.rows != levels_[l].A.rows || given.offsets != levels_[l].A.offsets)
      throw std::invalid_argument("MultigridCycle::refresh: operator " + std::to_string(l) +
                                  " does not have the pattern the cycle was built with");
    load_values(levels_[l], given);
  }
  factorise_coarsest();
}

void MultigridCycle::apply(std::span<const double> r, std::span<double> z) {
  std::copy(r.begin(), r.end(), levels_[0].b.begin());
  cycle(0);
  std::copy(levels_[0].x.begin(), levels_[0].x.end(), z.begin());
}

void MultigridCycle::cycle(std::size_t l) {
  Level& level = levels_[l];
  const bool coarsest = l + 1 == levels_.size();
  if (coarsest && coarse_direct_) {
    const Eigen::Map<const Eigen::VectorXd> b(level.b.data(), Eigen::Index(level.b.size()));
    Eigen::Map<Eigen::VectorXd>(level.x.data(), Eigen::Index(level.x.size())) = coarse_.solve(b);
    return;
  }
  std::fill(level.x.begin(), level.x.end(), 0.0);
  sweep(level, true);
  if (coarsest) {  // a single level, or a coarsest too large to factorise: smoothing only
    sweep(level, false);
    return;
  }
  Level& coarse = levels_[l + 1];
  level.A.residual(level.b, level.x, level.r);
  level.R.multiply(level.r, coarse.b);
  cycle(l + 1);
  level.P.multiply_add(coarse.x, level.x);
  // One sweep each side, not two: four passes over the finest matrix per CG iteration instead
  // of six, for 25 % more iterations (9 % frozen inclusion at 0.02 m: 10.6 -> 13.2 a step).
  sweep(level, false);
}

void MultigridCycle::sweep(Level& level, bool forward) {
  const std::size_t n = level.A.rows;
  const std::size_t blocks = (n + level.block_rows - 1) / level.block_rows;
  // Backward: the other blocks' values as the sweep found them. Forward (from x = 0) they are 0.
  if (blocks > 1 && !forward) std::copy(level.x.begin(), level.x.end(), level.previous.begin());
  const auto& A = level.A;
  double* x = level.x.data();
  const double* previous = level.previous.data();
  const double* b = level.b.data();
  const double* inverse = level.inverse_l1_diagonal.data();
  const double* values = A.values.data();
  const int* columns = A.columns.data();
  const std::size_t* in_block_end = level.in_block_end.data();
  const std::size_t* lower_end = level.lower_end.data();
  // From x = 0 (forward) only the own block's columns below the diagonal hold values yet, and
  // the other blocks' sum (the previous sweep's values, all 0) is +0: the same bits as the full
  // rows, with about half of the matrix read.
  auto relax_forward = [&](std::size_t i) {
    const double own = row_dot_until(values, columns, A.offsets[i], in_block_end[i], lower_end[i], x);
    x[i] += (b[i] - own - 0.0) * inverse[i];
  };
  auto relax_backward = [&](std::size_t i) {
    const double own = row_dot(values, columns, A.offsets[i], in_block_end[i], x);
    const double others = row_dot(values, columns, in_block_end[i], A.offsets[i + 1], previous);
    x[i] += (b[i] - own - others) * inverse[i];
  };
#pragma omp parallel for schedule(static) if (blocks > 1)
  for (std::size_t block = 0; block < blocks; ++block) {
    const std::size_t begin = block * level.block_rows, end = std::min(n, begin + level.block_rows);
    if (forward)
      for (std::size_t i = begin; i < end; ++i) relax_forward(i);
    else
      for (std::size_t i = end; i-- > begin;) relax_backward(i);
  }
}

}  // namespace frostmpm
