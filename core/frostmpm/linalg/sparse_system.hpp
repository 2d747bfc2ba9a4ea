#pragma once
// Sparse linear solver for A x = b, backed by Trilinos (Tpetra matrices, Belos Krylov solvers,
// Ifpack2 / MueLu preconditioners). This header includes no Trilinos or MPI header: the whole
// Trilinos dependency lives in sparse_system.cpp, so plugins and apps never parse it.
//
// Parallelism: for now the data are serial. Every MPI rank owns a complete copy of the system
// and solves it on its own communicator (MPI_COMM_SELF), so the class works the same in a plain
// executable and under `mpirun -np N` (each rank gets the same answer). Distributing rows over
// ranks comes later and will keep this interface (a row range per rank).
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace frostmpm {

struct SolverOptions {
  std::string method = "cg";              ///< "cg" (symmetric positive definite A) or "gmres"
  /// "none", "jacobi" (Ifpack2 RELAXATION), "ilu" (Ifpack2 RILUK, ILU(0)) or
  /// "multigrid" (MueLu smoothed aggregation; relaxation coarse solver, MPI-safe)
  std::string preconditioner = "jacobi";
  double tolerance = 1e-10;               ///< on the true relative residual ||b - A x|| / ||b||
  int max_iterations = 1000;              ///< total Krylov iterations per solve()
  int gmres_restart = 100;                ///< Krylov basis size before GMRES restarts
  /// Keep the values each preconditioner was built and refreshed from (preconditioner_source(),
  /// for checkpoints): a copy of the matrix per build or refresh. A caller that builds its
  /// preconditioner anew after a restart anyway turns it off.
  bool restorable_preconditioner = true;
};

struct SolveStats {
  int iterations = 0;              ///< Krylov iterations of this solve()
  double relative_residual = 0;    ///< true ||b - A x|| / ||b|| of the returned x (0 when b = 0)
  bool converged = false;          ///< relative_residual <= tolerance
  double setup_seconds = 0;        ///< uploading changed values + (re)building the preconditioner
  double solve_seconds = 0;        ///< Krylov iterations + residual checks
  bool preconditioner_reused = false;  ///< an existing preconditioner was used unchanged
};

/// What solve() does with the preconditioner of the previous solve.
enum class PreconditionerUpdate {
  Reuse,    ///< apply it as it is (cheapest): built from a private copy of the values at its
            ///< last refresh, it stays a fixed symmetric operator however much A changed since
            ///< (only the iteration count suffers)
  Refresh,  ///< recompute it from the current values, keeping what depends only on the graph
            ///< (Ifpack2: compute(); MueLu: aggregates and prolongators kept, "RP" reuse)
  Rebuild,  ///< build it from scratch
};

/// The matrix values a preconditioner was built from and last refreshed from, in the order of
/// the caller's column_indices (`refreshed` empty: not refreshed since it was built). They fix
/// the preconditioner: SparseSystem::restore_preconditioner() builds the same one again, so a
/// run resumed from a checkpoint that holds them solves as the uninterrupted run did.
struct PreconditionerSource {
  std::vector<double> built, refreshed;
};

/// Square sparse system A x = b with a fixed sparsity pattern: CSR, 0-based, global indices
/// (local = global while the data are serial, see above).
///
/// The graph is built once, in the constructor. set_values() / add_to_entry() change values
/// without rebuilding the graph; the new values reach the solver at the next solve(). The
/// preconditioner is rebuilt when solve() is asked to (values changed a lot) and reused
/// otherwise; the Krylov solver always uses the current values of A, so a reused, slightly
/// stale preconditioner only costs iterations, never accuracy.
///
/// Not thread-safe; one object per thread. A moved-from object may only be destroyed or
/// assigned to.
class SparseSystem {
 public:
  /// row_offsets has rows()+1 entries: non-decreasing, starting at 0, ending at
  /// column_indices.size(). Column indices lie in [0, rows()), at most once per row, in any
  /// order. Throws std::invalid_argument otherwise (or for invalid options). All values start
  /// at 0. Initializes MPI (if nobody has) and Kokkos on first use.
  SparseSystem(std::vector<std::size_t> row_offsets, std::vector<int> column_indices,
               SolverOptions options = {});
  ~SparseSystem();
  SparseSystem(SparseSystem&&) noexcept;
  SparseSystem& operator=(SparseSystem&&) noexcept;
  SparseSystem(const SparseSystem&) = delete;
  SparseSystem& operator=(const SparseSystem&) = delete;

  std::size_t rows() const;
  std::size_t nonzeros() const;
  const SolverOptions& options() const;

  /// All values, in the order of column_indices. Throws std::invalid_argument if
  /// values.size() != nonzeros().
  void set_values(std::span<const double> values);
  /// Current values, in the order of column_indices.
  std::span<const double> values() const;
  /// The values to write in place (no copy, unlike set_values); counts as a change of them.
  std::span<double> mutable_values();
  /// A(row, col) += delta for an entry of the pattern; throws std::out_of_range for an entry
  /// outside the pattern. O(log(entries in row)).
  void add_to_entry(std::size_t row, std::size_t col, double delta);

  /// Solves A x = rhs. On input x is the initial guess (warm start), on output the solution.
  /// rebuild_preconditioner = false reuses the preconditioner of the previous solve (one is
  /// built if none exists yet). Convergence is judged on the true residual; not converging
  /// within max_iterations is reported in the stats, not thrown. Throws std::invalid_argument
  /// for wrong sizes and std::runtime_error when the solver breaks down (e.g. CG on a matrix
  /// that is not positive definite).
  SolveStats solve(std::span<const double> rhs, std::span<double> x,
                   bool rebuild_preconditioner = true);
  /// The same, with a finer choice of what happens to the preconditioner and, when tolerance
  /// > 0, a relative residual for this solve only (an inexact Newton method asks for less
  /// while far from its solution).
  SolveStats solve(std::span<const double> rhs, std::span<double> x, PreconditionerUpdate update,
                   double tolerance = 0.0);

  /// What the current preconditioner was made from (both empty when there is none, or when
  /// options().restorable_preconditioner is off).
  PreconditionerSource preconditioner_source() const;
  /// Builds the preconditioner from source.built and refreshes it from source.refreshed (if
  /// given), as the solves that made it did; the system's current values stay as they are. An
  /// empty source (no preconditioner was built) does nothing. Throws std::invalid_argument for
  /// arrays of the wrong size.
  void restore_preconditioner(const PreconditionerSource& source);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace frostmpm
