// The project's only Trilinos-facing translation unit (see sparse_system.hpp).
#include "frostmpm/linalg/sparse_system.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include <mpi.h>

#include <Kokkos_Core.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsGraph.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Map.hpp>
#include <Tpetra_Vector.hpp>

// The solver factory hands out solver managers that libbelostpetra already instantiated for
// Tpetra, so this file does not compile the (large) Belos solver templates itself.
#include <BelosLinearProblem.hpp>
#include <BelosSolverFactory_Tpetra.hpp>
#include <BelosTpetraAdapter.hpp>

#include <Ifpack2_Factory.hpp>
#include <Ifpack2_Preconditioner.hpp>

// Trilinos 13.x's Teuchos_StandardParameterEntryValidators.hpp is not valid C++20: it declares
// a constructor with a template-id, `AbstractArrayValidator<ValidatorType, EntryType>();`
// (ill-formed since C++20, CWG 2237; GCC 12 rejects it; later Teuchos writes
// `AbstractArrayValidator();`). Belos and Ifpack2 above do not include that header; MueLu
// includes it (via MueLu_ParameterListAcceptor.hpp) without using it in what we instantiate, so
// pre-defining its include guard skips it. Anything that did need it would fail to compile
// here, not misbehave. Drop this once Trilinos is upgraded.
#include <Trilinos_version.h>
#if __cplusplus > 201703L && TRILINOS_MAJOR_VERSION <= 13 && \
    !defined(TEUCHOS_STANDARD_PARAMETER_ENTRY_VALIDATORS_H)
#define TEUCHOS_STANDARD_PARAMETER_ENTRY_VALIDATORS_H
#endif
#include <MueLu_CreateTpetraPreconditioner.hpp>
#include <MueLu_Hierarchy.hpp>
#include <MueLu_Level.hpp>
#include <MueLu_TpetraOperator.hpp>
#include <Xpetra_CrsMatrixWrap.hpp>
#include <Xpetra_Matrix.hpp>
#include <Xpetra_TpetraCrsMatrix.hpp>

#include "frostmpm/linalg/conjugate_gradient.hpp"
#include "frostmpm/linalg/csr_matrix.hpp"
#include "frostmpm/linalg/galerkin_product.hpp"
#include "frostmpm/linalg/mpi_session.hpp"
#include "frostmpm/linalg/multigrid_cycle.hpp"
#include "frostmpm/parallel/parallel.hpp"

namespace frostmpm {
namespace {

using Map = Tpetra::Map<>;
using LO = Map::local_ordinal_type;
using GO = Map::global_ordinal_type;
using NT = Map::node_type;
using SC = double;
using Graph = Tpetra::CrsGraph<LO, GO, NT>;
using Matrix = Tpetra::CrsMatrix<SC, LO, GO, NT>;
using RowMatrix = Tpetra::RowMatrix<SC, LO, GO, NT>;
using Vector = Tpetra::Vector<SC, LO, GO, NT>;
using MV = Tpetra::MultiVector<SC, LO, GO, NT>;
using OP = Tpetra::Operator<SC, LO, GO, NT>;
using Problem = Belos::LinearProblem<SC, MV, OP>;
using Ifpack2Prec = Ifpack2::Preconditioner<SC, LO, GO, NT>;
using MueLuPrec = MueLu::TpetraOperator<SC, LO, GO, NT>;
using Teuchos::RCP;
using Teuchos::rcp;

static_assert(std::is_same_v<LO, int>, "column indices are passed as int");

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Kokkos (needed by Tpetra) initialized once, on first use; finalized at exit only if we
/// initialized it. Constructed after MPI's lazy owner, so it is destroyed before MPI_Finalize.
struct KokkosRuntime {
  bool owns = false;
  KokkosRuntime() {
    if (!Kokkos::is_initialized()) {
      Kokkos::initialize();
      owns = true;
    }
  }
  ~KokkosRuntime() {
    if (owns && Kokkos::is_initialized()) Kokkos::finalize();
  }
  KokkosRuntime(const KokkosRuntime&) = delete;
  KokkosRuntime& operator=(const KokkosRuntime&) = delete;
};

void ensure_runtime() {
  ensure_mpi_initialized();
  static KokkosRuntime kokkos;
  (void)kokkos;
}

void validate_options(const SolverOptions& o) {
  if (o.method != "cg" && o.method != "gmres") {
    throw std::invalid_argument("SparseSystem: unknown solver method '" + o.method +
                                "' (expected cg or gmres)");
  }
  const auto& p = o.preconditioner;
  if (p != "none" && p != "jacobi" && p != "ilu" && p != "multigrid") {
    throw std::invalid_argument("SparseSystem: unknown preconditioner '" + p +
                                "' (expected none, jacobi, ilu or multigrid)");
  }
  if (!(o.tolerance > 0.0) || !std::isfinite(o.tolerance)) {
    throw std::invalid_argument("SparseSystem: tolerance must be positive and finite");
  }
  if (o.max_iterations <= 0) {
    throw std::invalid_argument("SparseSystem: max_iterations must be positive");
  }
  if (o.gmres_restart <= 0) {
    throw std::invalid_argument("SparseSystem: gmres_restart must be positive");
  }
}

using XMatrix = Xpetra::Matrix<SC, LO, GO, NT>;
using XOperator = Xpetra::Operator<SC, LO, GO, NT>;

/// The Tpetra matrix inside a MueLu level's operator.
RCP<const Matrix> tpetra_matrix(const RCP<XOperator>& op) {
  const auto wrap = Teuchos::rcp_dynamic_cast<const Xpetra::CrsMatrixWrap<SC, LO, GO, NT>>(op, true);
  const auto tpetra =
      Teuchos::rcp_dynamic_cast<const Xpetra::TpetraCrsMatrix<SC, LO, GO, NT>>(wrap->getCrsMatrix(), true);
  return tpetra->getTpetra_CrsMatrix();
}

/// A MueLu level matrix as CSR: its rows in the order of `rows` (which must be its row map's
/// order), its columns numbered as the rows of `columns` (the next level's map for a
/// prolongator, its own row map for an operator).
CsrMatrix to_csr(const Matrix& M, const Map& rows, const Map& columns) {
  const auto& row_map = *M.getRowMap();
  const auto& column_map = *M.getColMap();
  CsrMatrix csr;
  csr.rows = row_map.getNodeNumElements();
  csr.cols = columns.getNodeNumElements();
  if (!row_map.isSameAs(rows))
    throw std::logic_error("SparseSystem: a multigrid level's rows are not in its map's order");
  std::vector<int> column_of(column_map.getNodeNumElements());  // column-map index → ours
  for (std::size_t c = 0; c < column_of.size(); ++c) {
    column_of[c] = columns.getLocalElement(column_map.getGlobalElement(LO(c)));
    if (column_of[c] < 0) throw std::logic_error("SparseSystem: a multigrid level's column lies outside its map");
  }
  const auto local = M.getLocalMatrixHost();
  csr.offsets.resize(csr.rows + 1);
  for (std::size_t i = 0; i <= csr.rows; ++i) csr.offsets[i] = std::size_t(local.graph.row_map(i));
  const std::size_t entries = csr.offsets.back();
  csr.columns.resize(entries);
  csr.values.resize(entries);
  for (std::size_t k = 0; k < entries; ++k) {
    csr.columns[k] = column_of[std::size_t(local.graph.entries(k))];
    csr.values[k] = local.values(k);
  }
  return csr;
}

}  // namespace

struct SparseSystem::Impl {
  // ---- pattern and values (host copy, order of the caller's column_indices) ----
  /// The caller's pattern (order of column_indices) with the current values: the matrix our CG
  /// iterates on, and the values every other path copies from. It holds the pattern once;
  /// offsets and columns name its parts.
  CsrMatrix current;
  std::size_t n = 0;
  std::vector<std::size_t>& offsets = current.offsets;
  std::vector<int>& columns = current.columns;  ///< as given
  std::vector<LO> sorted_columns;   ///< per row, ascending
  std::vector<std::size_t> order;   ///< sorted position k -> index into columns/values
  std::vector<std::size_t> storage_position;  ///< caller's entry -> index in Tpetra's values
  static constexpr std::size_t no_entry = std::size_t(-1);
  std::vector<std::size_t> diagonal_position;  ///< row -> its diagonal entry's index, or no_entry
  bool values_dirty = true;         ///< values changed since the last solve
  SolverOptions options;

  // ---- our own threaded CG (why: the constructor) ----
  bool own_krylov = false;
  std::unique_ptr<LinearPreconditioner> own_preconditioner;
  /// Multigrid: the build's prolongators and the patterns of their coarse operators, finest first.
  std::vector<GalerkinProduct> galerkin;
  /// The cycle's coarse levels have the products' patterns (it was made by a refresh), so a
  /// refresh can load new values into it; a build's cycle holds MueLu's coarse operators.
  bool cycle_on_products = false;
  struct {
    std::vector<double> residual;
    ConjugateGradientWork cg;
  } own_work;  ///< kept between solves

  // ---- Trilinos objects (absent when n == 0) ----
  RCP<const Teuchos::Comm<int>> comm;
  RCP<const Map> map;
  RCP<Matrix> matrix;
  /// The matrix the preconditioner was built from: a copy, refreshed only when the
  /// preconditioner is, so a reused preconditioner is a fixed SPD operator even after the
  /// system's values moved on (smoothers read their matrix when applied).
  RCP<Matrix> preconditioner_matrix;
  RCP<Vector> b, x, r;
  RCP<Problem> problem;
  RCP<Ifpack2Prec> ifpack2;   ///< jacobi / ilu
  RCP<MueLuPrec> muelu;       ///< multigrid
  bool have_preconditioner = false;
  PreconditionerSource source;  ///< the values it was built and refreshed from

  Impl(std::vector<std::size_t> row_offsets, std::vector<int> column_indices, SolverOptions opts)
      : options(std::move(opts)) {
    offsets = std::move(row_offsets);
    columns = std::move(column_indices);
    validate_options(options);
    validate_and_sort_pattern();
    // Debian's Trilinos 13.2 builds Kokkos with its Serial back end only (KokkosCore_config.h
    // leaves KOKKOS_ENABLE_OPENMP undefined), so Belos and every Tpetra kernel run on one core
    // whatever --threads says: in the 9 % frozen inclusion at 0.01 m the pressure and heat solve
    // stages were 152 s of a 166 s run on 2 threads. CG with no, Jacobi or multigrid preconditioning therefore runs here,
    // threaded with OpenMP; MueLu still builds (and refreshes) the multigrid hierarchy, which
    // is set-up work done rarely, and MultigridCycle applies it. GMRES and ILU stay with Belos
    // and Ifpack2.
    own_krylov = options.method == "cg" && options.preconditioner != "ilu";
    current.rows = current.cols = n;
    current.values.assign(columns.size(), 0.0);
    if (n > 0) build_trilinos_objects();
  }

  void validate_and_sort_pattern() {
    if (offsets.empty()) {
      throw std::invalid_argument("SparseSystem: row_offsets needs rows+1 entries (got none)");
    }
    n = offsets.size() - 1;
    if (n > static_cast<std::size_t>(std::numeric_limits<LO>::max())) {
      throw std::invalid_argument("SparseSystem: too many rows for int column indices");
    }
    if (offsets.front() != 0) {
      throw std::invalid_argument("SparseSystem: row_offsets must start at 0");
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (offsets[i + 1] < offsets[i]) {
        throw std::invalid_argument("SparseSystem: row_offsets must be non-decreasing (row " +
                                    std::to_string(i) + ")");
      }
    }
    if (offsets.back() != columns.size()) {
      throw std::invalid_argument("SparseSystem: row_offsets.back() = " +
                                  std::to_string(offsets.back()) + " but there are " +
                                  std::to_string(columns.size()) + " column indices");
    }
    order.resize(columns.size());
    sorted_columns.resize(columns.size());
    diagonal_position.assign(n, no_entry);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t begin = offsets[i], end = offsets[i + 1];
      for (std::size_t k = begin; k < end; ++k) {
        if (columns[k] < 0 || static_cast<std::size_t>(columns[k]) >= n) {
          throw std::invalid_argument("SparseSystem: column index " + std::to_string(columns[k]) +
                                      " in row " + std::to_string(i) + " is outside [0, " +
                                      std::to_string(n) + ")");
        }
      }
      std::iota(order.begin() + begin, order.begin() + end, begin);
      std::sort(order.begin() + begin, order.begin() + end,
                [&](std::size_t a, std::size_t c) { return columns[a] < columns[c]; });
      for (std::size_t k = begin; k < end; ++k) {
        sorted_columns[k] = columns[order[k]];
        if (std::size_t(sorted_columns[k]) == i) diagonal_position[i] = order[k];
        if (k > begin && sorted_columns[k] == sorted_columns[k - 1]) {
          throw std::invalid_argument("SparseSystem: column " + std::to_string(sorted_columns[k]) +
                                      " appears twice in row " + std::to_string(i));
        }
      }
    }
  }

  void build_trilinos_objects() {
    ensure_runtime();
    // Serial data for now: each rank holds the whole system on its own communicator.
    comm = rcp(new Teuchos::MpiComm<int>(MPI_COMM_SELF));
    map = rcp(new Map(static_cast<Tpetra::global_size_t>(n), GO{0}, comm));

    std::vector<std::size_t> counts(n);
    for (std::size_t i = 0; i < n; ++i) counts[i] = offsets[i + 1] - offsets[i];
    // Column map = row map: local column index == global column index on one process.
    auto graph = rcp(new Graph(map, map, Teuchos::ArrayView<const std::size_t>(counts)));
    for (std::size_t i = 0; i < n; ++i) {
      const auto count = static_cast<LO>(counts[i]);
      if (count > 0) {
        graph->insertLocalIndices(static_cast<LO>(i), count, sorted_columns.data() + offsets[i]);
      }
    }
    graph->fillComplete();
    matrix = rcp(new Matrix(RCP<const Graph>(graph)));
    matrix->fillComplete();  // all zeros; allocates the value array in its final layout
    preconditioner_matrix = rcp(new Matrix(RCP<const Graph>(graph)));
    preconditioner_matrix->fillComplete();
    map_storage_positions();

    b = rcp(new Vector(map));
    x = rcp(new Vector(map));
    r = rcp(new Vector(map));
    problem = rcp(new Problem(matrix, x, b));
  }

  /// Where each of the caller's entries lives in the matrix's value array (filled once the
  /// graph is complete; Tpetra keeps each row's columns sorted, as in sorted_columns).
  void map_storage_positions() {
    const auto local_graph = matrix->getCrsGraph()->getLocalGraphHost();
    storage_position.resize(columns.size());
    for (std::size_t i = 0; i < n; ++i) {
      auto pos = static_cast<std::size_t>(local_graph.row_map(i));
      const auto row_end = static_cast<std::size_t>(local_graph.row_map(i + 1));
      for (std::size_t k = offsets[i]; k < offsets[i + 1]; ++k) {
        while (pos < row_end && local_graph.entries(pos) < sorted_columns[k]) ++pos;
        if (pos == row_end || local_graph.entries(pos) != sorted_columns[k]) {
          throw std::logic_error("SparseSystem: Tpetra graph lost entry (" + std::to_string(i) +
                                 ", " + std::to_string(sorted_columns[k]) + ")");
        }
        storage_position[order[k]] = pos;
      }
    }
  }

  /// Copies the host values into a Tpetra matrix on the system's graph (`matrix` or
  /// `preconditioner_matrix`): one pass over the value array instead of per-row index searches.
  void upload_values(Matrix& target) {
    if (target.isFillComplete()) target.resumeFill();
    {
      const auto device_values = target.getLocalValuesView();
      const auto host_values = Kokkos::create_mirror_view(device_values);
      for (std::size_t k = 0; k < current.values.size(); ++k) host_values(storage_position[k]) = current.values[k];
      Kokkos::deep_copy(device_values, host_values);
    }
    target.fillComplete();
  }

  /// The caller's values into the matrix the solver iterates on (ours iterates on `current`,
  /// and Tpetra's `matrix` stays unused).
  void take_values() {
    if (!own_krylov) upload_values(*matrix);
    values_dirty = false;
  }

  void copy_values_to_preconditioner_matrix() {
    preconditioner_matrix->resumeFill();
    Kokkos::deep_copy(preconditioner_matrix->getLocalValuesView(), matrix->getLocalValuesView());
    preconditioner_matrix->fillComplete();
  }

  void build_preconditioner(bool refresh) {
    const auto& kind = options.preconditioner;
    if (own_krylov) {
      build_own_preconditioner(refresh);
      return;
    }
    copy_values_to_preconditioner_matrix();
    if (kind == "jacobi" || kind == "ilu") {
      if (ifpack2.is_null()) {
        // initialize() depends on the graph only, so it runs once; compute() reads the values.
        ifpack2 = Ifpack2::Factory::create<RowMatrix>(kind == "jacobi" ? "RELAXATION" : "RILUK",
                                                      RCP<const RowMatrix>(preconditioner_matrix));
        Teuchos::ParameterList params;
        if (kind == "jacobi") {
          params.set("relaxation: type", "Jacobi");
          params.set("relaxation: sweeps", 1);
          params.set("relaxation: damping factor", 1.0);
        } else {
          params.set("fact: iluk level-of-fill", 0);
        }
        ifpack2->setParameters(params);
        ifpack2->initialize();
      }
      ifpack2->compute();  // from the current values alone
      record_source(refresh);
      problem->setRightPrec(ifpack2);
    } else if (kind == "multigrid") {
      build_muelu(refresh);
      problem->setRightPrec(muelu);
    }
    have_preconditioner = true;
  }

  /// The preconditioner of our own CG, from the current values.
  void build_own_preconditioner(bool refresh) {
    const auto& kind = options.preconditioner;
    if (kind == "jacobi") {
      // The diagonal from its stored positions, not by scanning the rows.
      std::vector<double> diagonal(n);
      parallel_for(n, [&](std::size_t i) {
        diagonal[i] = diagonal_position[i] == no_entry ? 0.0 : current.values[diagonal_position[i]];
      });
      own_preconditioner = std::make_unique<JacobiPreconditioner>(std::move(diagonal));
      record_source(refresh);
    } else if (kind == "multigrid") {
      if (refresh && !muelu.is_null()) {
        // New values on the build's prolongators (what MueLu's "RP" reuse keeps), the coarse
        // operators Pᵀ A P by our own threaded product (MueLu's reuse computes them serially).
        std::vector<CsrMatrix> coarse;
        coarse.reserve(galerkin.size());  // `operators` points into it
        std::vector<const CsrMatrix*> operators{&current};
        for (const auto& product : galerkin) operators.push_back(&coarse.emplace_back(product(*operators.back())));
        if (cycle_on_products) {
          // The cycle's levels have these patterns already: the values moved in place.
          static_cast<MultigridCycle&>(*own_preconditioner).refresh(operators);
        } else {
          // The build's cycle holds MueLu's coarse operators, whose patterns differ: a cycle on
          // the products' patterns, which later refreshes fill in place.
          std::vector<CsrMatrix> levels{current}, prolongators, restrictions;
          for (std::size_t l = 0; l < galerkin.size(); ++l) {
            levels.push_back(std::move(coarse[l]));
            prolongators.push_back(galerkin[l].prolongator());
            restrictions.push_back(galerkin[l].restriction());  // transposed once per build, not per refresh
          }
          own_preconditioner = std::make_unique<MultigridCycle>(std::move(levels), std::move(prolongators),
                                                                std::move(restrictions));
          cycle_on_products = true;
        }
        record_source(true);
      } else {
        std::vector<CsrMatrix> operators{current}, prolongators;
        upload_values(*preconditioner_matrix);  // MueLu's input, straight from `current`
        build_muelu(false);
        extract_hierarchy(operators, prolongators);
        galerkin.clear();
        galerkin.reserve(prolongators.size());  // `pattern` points into it
        const CsrMatrix* pattern = &current;
        for (const auto& P : prolongators) pattern = &galerkin.emplace_back(*pattern, P).coarse_pattern();
        own_preconditioner = std::make_unique<MultigridCycle>(std::move(operators), std::move(prolongators));
        cycle_on_products = false;
      }
    }
    have_preconditioner = true;
  }

  /// MueLu's coarse levels as CSR, appended to operators (whose first, the finest, is `current`:
  /// the values just given to MueLu) and prolongators.
  void extract_hierarchy(std::vector<CsrMatrix>& operators, std::vector<CsrMatrix>& prolongators) const {
    const auto hierarchy = muelu->GetHierarchy();
    RCP<const Map> fine_rows = map;  // level 0: our rows 0 … n − 1 in order
    for (int l = 1; l < hierarchy->GetNumLevels(); ++l) {
      const auto level = hierarchy->GetLevel(l);
      const auto A = tpetra_matrix(level->template Get<RCP<XOperator>>("A"));
      const auto P = tpetra_matrix(level->template Get<RCP<XOperator>>("P"));
      operators.push_back(to_csr(*A, *A->getRowMap(), *A->getRowMap()));
      prolongators.push_back(to_csr(*P, *fine_rows, *A->getRowMap()));
      fine_rows = A->getRowMap();
    }
  }

  void record_source(bool refreshed) {
    if (!options.restorable_preconditioner) return;
    if (refreshed)
      source.refreshed = current.values;
    else
      source = {current.values, {}};
  }

  /// MueLu's hierarchy from preconditioner_matrix, refreshed ("RP" reuse) when asked and
  /// possible; records what it was made from in `source`.
  void build_muelu(bool refresh) {
    Teuchos::ParameterList params;
    params.set("verbosity", "none");
    params.set("multigrid algorithm", "sa");
    params.set("coarse: max size", 200);
    // Aggregates follow the strong couplings only (|a_ij| ≥ 0.02 √(a_ii a_jj)): across a
    // permeability jump of orders of magnitude (frozen against thawed soil) an aggregate
    // that straddles the jump interpolates the stiff side from the soft one. With it the 9 %
    // frozen inclusion needs 12–15 CG iterations per step instead of 18–24 (0.04–0.01 m).
    params.set("aggregation: drop tol", 0.02);
    // Symmetric smoothing keeps the V-cycle symmetric, as CG needs (Belos's path; our own
    // cycle smooths with its own, see multigrid_cycle.hpp).
    params.set("smoother: type", "RELAXATION");
    params.sublist("smoother: params").set("relaxation: type", "Symmetric Gauss-Seidel");
    params.sublist("smoother: params").set("relaxation: sweeps", 1);
    if (own_krylov) params.set("smoother: pre or post", "none");  // MultigridCycle smooths
    // The coarsest level (≤ 200 unknowns) solved exactly (KLU2 through Amesos2, which gathers
    // a distributed coarse matrix itself): an inexact coarse solve lets the iteration count
    // grow with refinement.
    params.set("coarse: type", "KLU2");
    // A refresh keeps the aggregates and prolongators and recomputes the coarse operators and
    // smoothers from the new values (MueLu's "RP" reuse).
    params.set("reuse: type", "RP");
    bool refreshed = false;
    if (!muelu.is_null() && refresh) {
      // The reuse keeps the coarse operators' graphs, which MueLu built from the nonzero
      // values: an entry that was zero then (a row fixed as a boundary or a dry node, which
      // may become free when particles move or ice melts) does not fit, and MueLu throws.
      // Then the preconditioner is built anew.
      try {
        MueLu::ReuseTpetraPreconditioner(preconditioner_matrix, *muelu);
        refreshed = true;
      } catch (const std::exception&) {
        refreshed = false;
      }
    }
    if (!refreshed)
      muelu = MueLu::CreateTpetraPreconditioner<SC, LO, GO, NT>(RCP<OP>(preconditioner_matrix), params);
    // A refresh depends on the aggregates and prolongators of the build and on the new values.
    record_source(refreshed);
  }

  double relative_residual(double b_norm) {
    matrix->apply(*x, *r);
    r->update(1.0, *b, -1.0);  // r = b - A x
    return r->norm2() / b_norm;
  }

  /// One Belos run from the current x; returns the iterations it took.
  int run_krylov(int max_iterations, double tolerance) {
    auto params = rcp(new Teuchos::ParameterList);
    params->set("Convergence Tolerance", tolerance);
    params->set("Maximum Iterations", max_iterations);
    params->set("Implicit Residual Scaling", "Norm of RHS");
    params->set("Verbosity", static_cast<int>(Belos::Errors));
    if (!problem->setProblem(x, b)) {
      throw std::runtime_error("SparseSystem: Belos could not set up the linear problem");
    }
    if (options.method == "gmres") {
      const int restart = std::min(options.gmres_restart, max_iterations);
      params->set("Num Blocks", restart);
      params->set("Maximum Restarts", max_iterations / restart + 1);
      params->set("Explicit Residual Scaling", "Norm of RHS");
    }
    Belos::SolverFactory<SC, MV, OP> factory;
    const RCP<Belos::SolverManager<SC, MV, OP>> solver =
        factory.create(options.method == "cg" ? "PSEUDOBLOCK CG" : "PSEUDOBLOCK GMRES", params);
    solver->setProblem(problem);
    try {
      solver->solve();
    } catch (const std::exception& e) {
      throw std::runtime_error("SparseSystem: " + options.method + " solve failed: " + e.what());
    }
    return solver->getNumIters();
  }

  SolveStats solve(std::span<const double> rhs, std::span<double> x_io, PreconditionerUpdate update,
                   double tolerance) {
    if (!(tolerance > 0)) tolerance = options.tolerance;
    if (rhs.size() != n || x_io.size() != n) {
      throw std::invalid_argument("SparseSystem::solve: rhs and x need " + std::to_string(n) +
                                  " entries (got " + std::to_string(rhs.size()) + " and " +
                                  std::to_string(x_io.size()) + ")");
    }
    SolveStats stats;
    if (n == 0) {
      stats.converged = true;
      return stats;
    }

    const auto setup_start = Clock::now();
    if (values_dirty) take_values();
    if (options.preconditioner != "none") {
      if (update != PreconditionerUpdate::Reuse || !have_preconditioner) {
        build_preconditioner(have_preconditioner && update == PreconditionerUpdate::Refresh);
      } else {
        stats.preconditioner_reused = true;
      }
    }
    stats.setup_seconds = seconds_since(setup_start);
    if (own_krylov) return solve_own(rhs, x_io, tolerance, stats);

    const auto solve_start = Clock::now();
    {
      auto bv = b->getLocalViewHost(Tpetra::Access::OverwriteAll);
      auto xv = x->getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < n; ++i) {
        bv(i, 0) = rhs[i];
        xv(i, 0) = x_io[i];
      }
    }
    const double b_norm = b->norm2();
    if (b_norm == 0.0) {
      std::fill(x_io.begin(), x_io.end(), 0.0);  // A x = 0 has the solution 0
      stats.converged = true;
      stats.solve_seconds = seconds_since(solve_start);
      return stats;
    }
    if (!std::isfinite(b_norm)) {
      throw std::invalid_argument("SparseSystem::solve: rhs contains inf or NaN");
    }

    // Belos judges convergence on its recursive residual, we on the true one.
    iterate_to_tolerance(stats, tolerance, [&](int remaining) { return run_krylov(remaining, tolerance); },
                         [&] { return relative_residual(b_norm); });
    {
      auto xv = x->getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t i = 0; i < n; ++i) x_io[i] = xv(i, 0);
    }
    stats.solve_seconds = seconds_since(solve_start);
    return stats;
  }

  /// Krylov passes (`krylov(iterations left)` returns the iterations it took) from the current x
  /// until the true relative residual (`residual()`) meets the tolerance: a Krylov method judges
  /// convergence on its recursively updated residual, which rounding can leave below the true
  /// one. At most four passes, and none once an iteration budget is spent or a pass stalls. Each
  /// pass starts from the x that residual() was last called at (our CG takes that residual over).
  template <class Krylov, class Residual>
  void iterate_to_tolerance(SolveStats& stats, double tolerance, Krylov&& krylov, Residual&& residual) const {
    double rel = residual();
    for (int pass = 0; pass < 4 && rel > tolerance; ++pass) {
      const int remaining = options.max_iterations - stats.iterations;
      if (remaining <= 0) break;
      const int its = krylov(remaining);
      stats.iterations += its;
      rel = residual();
      if (its == 0) break;  // no progress possible
    }
    stats.relative_residual = rel;
    stats.converged = std::isfinite(rel) && rel <= tolerance;
  }

  /// solve()'s Krylov part on our own CG: the same contract (convergence judged on the true
  /// residual, up to four passes from the current x).
  SolveStats solve_own(std::span<const double> rhs, std::span<double> x_io, double tolerance, SolveStats stats) {
    const auto solve_start = Clock::now();
    const double b_norm = std::sqrt(reproducible_sum(n, [&](std::size_t i) { return rhs[i] * rhs[i]; }));
    if (b_norm == 0.0) {
      std::fill(x_io.begin(), x_io.end(), 0.0);  // A x = 0 has the solution 0
      stats.converged = true;
      stats.solve_seconds = seconds_since(solve_start);
      return stats;
    }
    if (!std::isfinite(b_norm)) throw std::invalid_argument("SparseSystem::solve: rhs contains inf or NaN");
    auto& residual = own_work.residual;
    residual.resize(n);
    auto true_residual = [&] {
      current.residual(rhs, x_io, residual);
      return std::sqrt(reproducible_sum(n, [&](std::size_t i) { return residual[i] * residual[i]; })) / b_norm;
    };
    iterate_to_tolerance(
        stats, tolerance,
        [&](int remaining) {
          try {  // from the true residual just measured for this x
            return conjugate_gradient(current, own_preconditioner.get(), rhs, x_io, residual, tolerance, remaining,
                                      own_work.cg);
          } catch (const std::exception& e) {
            throw std::runtime_error(std::string("SparseSystem: cg solve failed: ") + e.what());
          }
        },
        true_residual);
    stats.solve_seconds = seconds_since(solve_start);
    return stats;
  }

  void mark_values_changed() { values_dirty = true; }

  void add_to_entry(std::size_t row, std::size_t col, double delta) {
    if (row >= n || col >= n) {
      throw std::out_of_range("SparseSystem::add_to_entry: (" + std::to_string(row) + ", " +
                              std::to_string(col) + ") is outside the " + std::to_string(n) +
                              "x" + std::to_string(n) + " matrix");
    }
    const auto first = sorted_columns.begin() + static_cast<std::ptrdiff_t>(offsets[row]);
    const auto last = sorted_columns.begin() + static_cast<std::ptrdiff_t>(offsets[row + 1]);
    const auto it = std::lower_bound(first, last, static_cast<LO>(col));
    if (it == last || *it != static_cast<LO>(col)) {
      throw std::out_of_range("SparseSystem::add_to_entry: (" + std::to_string(row) + ", " +
                              std::to_string(col) + ") is not in the sparsity pattern");
    }
    current.values[order[static_cast<std::size_t>(it - sorted_columns.begin())]] += delta;
    mark_values_changed();
  }
};

SparseSystem::SparseSystem(std::vector<std::size_t> row_offsets, std::vector<int> column_indices,
                           SolverOptions options)
    : impl_(std::make_unique<Impl>(std::move(row_offsets), std::move(column_indices),
                                   std::move(options))) {}

SparseSystem::~SparseSystem() = default;
SparseSystem::SparseSystem(SparseSystem&&) noexcept = default;
SparseSystem& SparseSystem::operator=(SparseSystem&&) noexcept = default;

std::size_t SparseSystem::rows() const { return impl_->n; }
std::size_t SparseSystem::nonzeros() const { return impl_->columns.size(); }
const SolverOptions& SparseSystem::options() const { return impl_->options; }

void SparseSystem::set_values(std::span<const double> values) {
  if (values.size() != impl_->current.values.size()) {
    throw std::invalid_argument("SparseSystem::set_values: expected " +
                                std::to_string(impl_->current.values.size()) + " values, got " +
                                std::to_string(values.size()));
  }
  double* to = impl_->current.values.data();
  parallel_for(values.size(), [&](std::size_t e) { to[e] = values[e]; });
  impl_->mark_values_changed();
}

std::span<const double> SparseSystem::values() const { return impl_->current.values; }

std::span<double> SparseSystem::mutable_values() {
  impl_->mark_values_changed();
  return impl_->current.values;
}

void SparseSystem::add_to_entry(std::size_t row, std::size_t col, double delta) {
  impl_->add_to_entry(row, col, delta);
}

SolveStats SparseSystem::solve(std::span<const double> rhs, std::span<double> x,
                               bool rebuild_preconditioner) {
  return impl_->solve(rhs, x, rebuild_preconditioner ? PreconditionerUpdate::Rebuild : PreconditionerUpdate::Reuse,
                      0.0);
}

SolveStats SparseSystem::solve(std::span<const double> rhs, std::span<double> x, PreconditionerUpdate update,
                               double tolerance) {
  return impl_->solve(rhs, x, update, tolerance);
}

PreconditionerSource SparseSystem::preconditioner_source() const {
  return impl_->have_preconditioner ? impl_->source : PreconditionerSource{};
}

void SparseSystem::restore_preconditioner(const PreconditionerSource& source) {
  Impl& s = *impl_;
  if (source.built.empty() && source.refreshed.empty()) return;  // there was none ("none", or no solve yet)
  const std::size_t nnz = s.current.values.size();
  if (source.built.size() != nnz || (!source.refreshed.empty() && source.refreshed.size() != nnz))
    throw std::invalid_argument("SparseSystem::restore_preconditioner: expected " + std::to_string(nnz) +
                                " values built from and none or as many refreshed from, got " +
                                std::to_string(source.built.size()) + " and " +
                                std::to_string(source.refreshed.size()));
  if (s.n == 0 || s.options.preconditioner == "none") return;
  const std::vector<double> kept = s.current.values;
  s.current.values = source.built;
  s.mark_values_changed();
  s.take_values();
  s.build_preconditioner(false);
  if (!source.refreshed.empty()) {
    s.current.values = source.refreshed;
    s.mark_values_changed();
    s.take_values();
    s.build_preconditioner(true);
  }
  s.current.values = kept;
  s.mark_values_changed();
}

}  // namespace frostmpm
