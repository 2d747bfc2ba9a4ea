// SparseSystem (Trilinos-backed sparse solver) and MpiSession. These tests never include a
// Trilinos or MPI header: that is the point of the pimpl.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "frostmpm/linalg/mpi_session.hpp"
#include "frostmpm/linalg/sparse_system.hpp"

using frostmpm::PreconditionerSource;
using frostmpm::PreconditionerUpdate;
using frostmpm::SolverOptions;
using frostmpm::SolveStats;
using frostmpm::SparseSystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// 5-point finite-difference operator on an m x m interior grid with Dirichlet boundaries:
/// (4 + sigma + c) on the diagonal, -1 - c for the west neighbour, -1 for the others
/// (c = 0: the symmetric Poisson matrix; c > 0: a nonsymmetric upwinded convection term).
/// Each row lists its diagonal first and its neighbours after it, deliberately unsorted, so
/// the tests also check that values follow the caller's order of column indices.
struct Grid5 {
  int m = 0;
  std::vector<std::size_t> offsets{0};
  std::vector<int> columns;
  std::vector<int> kind;  ///< per entry: 0 diagonal, 1 west, 2 other neighbour

  explicit Grid5(int m_) : m(m_) {
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < m; ++i) {
        const int row = j * m + i;
        columns.push_back(row), kind.push_back(0);
        if (j + 1 < m) columns.push_back(row + m), kind.push_back(2);
        if (i + 1 < m) columns.push_back(row + 1), kind.push_back(2);
        if (i > 0) columns.push_back(row - 1), kind.push_back(1);
        if (j > 0) columns.push_back(row - m), kind.push_back(2);
        offsets.push_back(columns.size());
      }
    }
  }
  std::size_t n() const { return offsets.size() - 1; }

  std::vector<double> values(double sigma, double c = 0.0) const {
    std::vector<double> v(columns.size());
    for (std::size_t k = 0; k < v.size(); ++k) {
      v[k] = kind[k] == 0 ? 4.0 + sigma + c : kind[k] == 1 ? -1.0 - c : -1.0;
    }
    return v;
  }

  /// A smooth manufactured solution (not an eigenvector, so the solver has work to do).
  std::vector<double> exact_solution() const {
    std::vector<double> x(n());
    const double h = 1.0 / (m + 1);
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < m; ++i) {
        const double px = (i + 1) * h, py = (j + 1) * h;
        x[j * m + i] = std::sin(kPi * px) * std::sin(2 * kPi * py) + px * py * (1 - px);
      }
    }
    return x;
  }
};

/// y = A x from CSR arrays, independent of SparseSystem.
std::vector<double> multiply(const std::vector<std::size_t>& offsets,
                             const std::vector<int>& columns, std::span<const double> values,
                             const std::vector<double>& x) {
  std::vector<double> y(offsets.size() - 1, 0.0);
  for (std::size_t r = 0; r + 1 < offsets.size(); ++r) {
    for (std::size_t k = offsets[r]; k < offsets[r + 1]; ++k) y[r] += values[k] * x[columns[k]];
  }
  return y;
}

double norm2(const std::vector<double>& v) {
  double s = 0;
  for (double e : v) s += e * e;
  return std::sqrt(s);
}

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

/// ||b - A x|| / ||b|| computed here, not by the solver.
double true_relative_residual(const Grid5& g, std::span<const double> values,
                              const std::vector<double>& b, const std::vector<double>& x) {
  auto ax = multiply(g.offsets, g.columns, values, x);
  for (std::size_t i = 0; i < ax.size(); ++i) ax[i] = b[i] - ax[i];
  return norm2(ax) / norm2(b);
}

SolverOptions make_options(const std::string& method, const std::string& preconditioner) {
  SolverOptions o;
  o.method = method;
  o.preconditioner = preconditioner;
  o.tolerance = 1e-10;
  o.max_iterations = 2000;
  return o;
}

}  // namespace

TEST_CASE("SparseSystem solves a 2D Poisson problem with each solver configuration",
          "[linalg]") {
  const Grid5 grid(50);  // 2500 unknowns
  const auto x_exact = grid.exact_solution();
  const auto values = grid.values(0.0);
  const auto b = multiply(grid.offsets, grid.columns, values, x_exact);

  const auto [method, preconditioner] = GENERATE(table<std::string, std::string>(
      {{"cg", "jacobi"}, {"cg", "multigrid"}, {"gmres", "ilu"}}));
  INFO(method << " + " << preconditioner);

  SparseSystem system(grid.offsets, grid.columns, make_options(method, preconditioner));
  REQUIRE(system.rows() == 2500);
  REQUIRE(system.nonzeros() == grid.columns.size());
  system.set_values(values);

  std::vector<double> x(grid.n(), 0.0);
  const SolveStats stats = system.solve(b, x);
  INFO("iterations " << stats.iterations << ", setup " << stats.setup_seconds << " s, solve "
                     << stats.solve_seconds << " s");
  REQUIRE(stats.converged);
  REQUIRE(stats.iterations > 0);
  REQUIRE(stats.relative_residual <= 1e-10);
  REQUIRE_FALSE(stats.preconditioner_reused);
  REQUIRE(true_relative_residual(grid, values, b, x) <= 1.01e-10);
  // cond(A) ~ 1e3, so a 1e-10 residual bounds the error by ~1e-7 relative.
  REQUIRE(max_abs_diff(x, x_exact) < 1e-6);

  SECTION("a warm start at the solution needs no iterations") {
    const SolveStats again = system.solve(b, x, false);
    REQUIRE(again.converged);
    REQUIRE(again.iterations == 0);
    REQUIRE(again.preconditioner_reused);
    REQUIRE(max_abs_diff(x, x_exact) < 1e-6);
  }
}

TEST_CASE("SparseSystem: every method and preconditioner, symmetric and nonsymmetric",
          "[linalg]") {
  const Grid5 grid(20);
  const auto x_exact = grid.exact_solution();
  // CG needs a symmetric matrix; GMRES also gets a nonsymmetric (convective) one.
  const auto [method, preconditioner, convection] =
      GENERATE(table<std::string, std::string, double>({
          {"cg", "none", 0.0},      {"cg", "jacobi", 0.0},      {"cg", "ilu", 0.0},
          {"cg", "multigrid", 0.0}, {"gmres", "none", 0.0},     {"gmres", "jacobi", 0.0},
          {"gmres", "ilu", 0.0},    {"gmres", "multigrid", 0.0}, {"gmres", "none", 2.0},
          {"gmres", "jacobi", 2.0}, {"gmres", "ilu", 2.0},       {"gmres", "multigrid", 2.0},
      }));
  INFO(method << " + " << preconditioner << ", convection " << convection);

  const auto values = grid.values(0.1, convection);
  const auto b = multiply(grid.offsets, grid.columns, values, x_exact);
  SparseSystem system(grid.offsets, grid.columns, make_options(method, preconditioner));
  system.set_values(values);
  std::vector<double> x(grid.n(), 0.0);
  const SolveStats stats = system.solve(b, x);
  INFO("iterations " << stats.iterations);
  REQUIRE(stats.converged);
  REQUIRE(true_relative_residual(grid, values, b, x) <= 1.01e-10);
  REQUIRE(max_abs_diff(x, x_exact) < 1e-7);
}

TEST_CASE("SparseSystem refills values on the same graph and reuses the preconditioner",
          "[linalg]") {
  const Grid5 grid(30);
  const auto x_exact = grid.exact_solution();
  const auto [method, preconditioner] = GENERATE(table<std::string, std::string>(
      {{"cg", "jacobi"}, {"cg", "multigrid"}, {"gmres", "ilu"}}));
  INFO(method << " + " << preconditioner);
  SparseSystem system(grid.offsets, grid.columns, make_options(method, preconditioner));

  auto solve_for = [&](double sigma, bool rebuild) {
    const auto values = grid.values(sigma);
    system.set_values(values);
    REQUIRE(std::equal(values.begin(), values.end(), system.values().begin(),
                       system.values().end()));
    const auto b = multiply(grid.offsets, grid.columns, values, x_exact);
    std::vector<double> x(grid.n(), 0.0);
    const SolveStats stats = system.solve(b, x, rebuild);
    INFO("sigma " << sigma << ", rebuild " << rebuild << ", iterations " << stats.iterations);
    REQUIRE(stats.converged);
    REQUIRE(stats.relative_residual <= 1e-10);
    REQUIRE(true_relative_residual(grid, values, b, x) <= 1.01e-10);
    REQUIRE(max_abs_diff(x, x_exact) < 1e-7);
    return stats;
  };

  // Without a preconditioner yet, "reuse" has to build one.
  REQUIRE_FALSE(solve_for(0.0, false).preconditioner_reused);
  // A + 0.5 I: new values, same graph, fresh preconditioner.
  REQUIRE_FALSE(solve_for(0.5, true).preconditioner_reused);
  // A + 0.6 I with the preconditioner built for A + 0.5 I: still converges to the new solution.
  REQUIRE(solve_for(0.6, false).preconditioner_reused);
  // And back to a large change with a rebuild.
  REQUIRE_FALSE(solve_for(5.0, true).preconditioner_reused);

  SECTION("add_to_entry changes one stored value, in the caller's order") {
    const auto before = std::vector<double>(system.values().begin(), system.values().end());
    system.add_to_entry(0, 1, -0.25);  // east neighbour of row 0: stored third in row 0
    system.add_to_entry(0, 1, -0.25);
    const auto after = system.values();
    REQUIRE(after[2] == Approx(before[2] - 0.5));
    REQUIRE(after[0] == before[0]);
    REQUIRE(after[1] == before[1]);

    // The nonsymmetric change is fine for GMRES; for CG keep A symmetric: A(1,0) too.
    if (method == "cg") system.add_to_entry(1, 0, -0.5);
    const auto b = multiply(grid.offsets, grid.columns, system.values(), x_exact);
    std::vector<double> x(grid.n(), 0.0);
    const SolveStats stats = system.solve(b, x);
    REQUIRE(stats.converged);
    REQUIRE(true_relative_residual(grid, system.values(), b, x) <= 1.01e-10);
    REQUIRE(max_abs_diff(x, x_exact) < 1e-7);
  }

  SECTION("a preconditioner restored from its source solves bit for bit as the one it came from") {
    // A run's checkpoint holds what made its pressure solver's preconditioner: built from one
    // matrix, refreshed from later ones. A system rebuilt from that source must iterate exactly
    // as the original, although the original was refreshed more often.
    solve_for(5.3, false);
    const auto refresh = [&](SparseSystem& s, double sigma) {
      s.set_values(grid.values(sigma));
      const auto b = multiply(grid.offsets, grid.columns, grid.values(sigma), x_exact);
      std::vector<double> x(grid.n(), 0.0);
      s.solve(b, x, PreconditionerUpdate::Refresh);
    };
    refresh(system, 5.5);
    refresh(system, 5.7);
    const PreconditionerSource source = system.preconditioner_source();
    REQUIRE(source.built == grid.values(5.0));
    REQUIRE(source.refreshed == grid.values(5.7));

    SparseSystem restored(grid.offsets, grid.columns, make_options(method, preconditioner));
    REQUIRE(restored.preconditioner_source().built.empty());
    restored.restore_preconditioner(restored.preconditioner_source());  // none to restore: nothing happens
    REQUIRE(restored.preconditioner_source().built.empty());
    restored.set_values(grid.values(9.0));
    restored.restore_preconditioner(source);
    REQUIRE(std::equal(restored.values().begin(), restored.values().end(), grid.values(9.0).begin()));  // kept
    const auto b = multiply(grid.offsets, grid.columns, grid.values(5.9), x_exact);
    std::vector<double> x_original(grid.n(), 0.0), x_restored(grid.n(), 0.0);
    system.set_values(grid.values(5.9));
    restored.set_values(grid.values(5.9));
    const SolveStats a = system.solve(b, x_original, PreconditionerUpdate::Reuse);
    const SolveStats r = restored.solve(b, x_restored, PreconditionerUpdate::Reuse);
    REQUIRE(r.iterations == a.iterations);
    REQUIRE(x_restored == x_original);  // bit for bit

    PreconditionerSource wrong{std::vector<double>(3, 1.0), {}};  // another system's
    REQUIRE_THROWS_AS(restored.restore_preconditioner(wrong), std::invalid_argument);
  }

  SECTION("values written in place solve as set_values' do; a preconditioner not kept restorable has no source") {
    SolverOptions options = make_options(method, preconditioner);
    options.restorable_preconditioner = false;
    SparseSystem quiet(grid.offsets, grid.columns, options);
    const auto values = grid.values(0.5);
    const auto in_place = quiet.mutable_values();
    std::copy(values.begin(), values.end(), in_place.begin());
    system.set_values(values);
    const auto b = multiply(grid.offsets, grid.columns, values, x_exact);
    std::vector<double> x_quiet(grid.n(), 0.0), x(grid.n(), 0.0);
    for (const auto update : {PreconditionerUpdate::Rebuild, PreconditionerUpdate::Refresh}) {
      REQUIRE(quiet.solve(b, x_quiet, update).converged);
      REQUIRE(system.solve(b, x, update).converged);
      REQUIRE(x_quiet == x);
      REQUIRE(quiet.preconditioner_source().built.empty());
      REQUIRE(quiet.preconditioner_source().refreshed.empty());
      REQUIRE_FALSE(system.preconditioner_source().built.empty());
    }
  }

  SECTION("add_to_entry rejects entries outside the pattern") {
    REQUIRE_THROWS_AS(system.add_to_entry(0, 2, 1.0), std::out_of_range);
    REQUIRE_THROWS_AS(system.add_to_entry(0, 900, 1.0), std::out_of_range);
    REQUIRE_THROWS_AS(system.add_to_entry(900, 0, 1.0), std::out_of_range);
  }
}

TEST_CASE("SparseSystem special right-hand sides, sizes and moves", "[linalg]") {
  const Grid5 grid(10);
  SparseSystem system(grid.offsets, grid.columns, make_options("cg", "jacobi"));
  system.set_values(grid.values(0.0));

  SECTION("a zero right-hand side gives x = 0 at once") {
    std::vector<double> x(grid.n(), 3.0);
    const std::vector<double> zero(grid.n(), 0.0);
    const SolveStats stats = system.solve(zero, x);
    REQUIRE(stats.converged);
    REQUIRE(stats.iterations == 0);
    REQUIRE(std::all_of(x.begin(), x.end(), [](double v) { return v == 0.0; }));
  }
  SECTION("wrong vector sizes are rejected") {
    std::vector<double> x(grid.n(), 0.0), short_b(grid.n() - 1, 1.0);
    REQUIRE_THROWS_AS(system.solve(short_b, x), std::invalid_argument);
    std::vector<double> b(grid.n(), 1.0), short_x(grid.n() + 1, 0.0);
    REQUIRE_THROWS_AS(system.solve(b, short_x), std::invalid_argument);
    REQUIRE_THROWS_AS(system.set_values(std::vector<double>(3, 1.0)), std::invalid_argument);
  }
  SECTION("a moved system keeps its matrix") {
    SparseSystem moved = std::move(system);
    REQUIRE(moved.rows() == grid.n());
    const auto x_exact = grid.exact_solution();
    const auto b = multiply(grid.offsets, grid.columns, moved.values(), x_exact);
    std::vector<double> x(grid.n(), 0.0);
    REQUIRE(moved.solve(b, x).converged);
    REQUIRE(max_abs_diff(x, x_exact) < 1e-7);
  }
  SECTION("running out of iterations is reported, not thrown") {
    SparseSystem limited(grid.offsets, grid.columns, [] {
      SolverOptions o = make_options("cg", "none");
      o.max_iterations = 3;
      return o;
    }());
    limited.set_values(grid.values(0.0));
    const std::vector<double> b(grid.n(), 1.0);
    std::vector<double> x(grid.n(), 0.0);
    const SolveStats stats = limited.solve(b, x);
    REQUIRE_FALSE(stats.converged);
    REQUIRE(stats.iterations == 3);
    REQUIRE(stats.relative_residual > 1e-10);
    REQUIRE(stats.relative_residual < 1.0);  // but it did make progress
  }
  SECTION("CG breaking down on a negative definite matrix throws; the system stays usable") {
    SparseSystem sys(grid.offsets, grid.columns, make_options("cg", "none"));
    auto negative = grid.values(0.0);
    for (double& v : negative) v = -v;
    sys.set_values(negative);
    const std::vector<double> b(grid.n(), 1.0);
    std::vector<double> x(grid.n(), 0.0);
    REQUIRE_THROWS_AS(sys.solve(b, x), std::runtime_error);
    sys.set_values(grid.values(0.0));
    std::fill(x.begin(), x.end(), 0.0);
    REQUIRE(sys.solve(b, x).converged);
  }
  SECTION("an empty system is trivially solved") {
    SparseSystem empty({0}, {});
    REQUIRE(empty.rows() == 0);
    std::vector<double> none;
    REQUIRE(empty.solve(none, none).converged);
  }
}

TEST_CASE("SparseSystem rejects invalid patterns and options", "[linalg]") {
  using V = std::vector<std::size_t>;
  using C = std::vector<int>;
  // A valid 3x3 pattern for reference.
  REQUIRE_NOTHROW(SparseSystem(V{0, 2, 4, 5}, C{0, 1, 1, 0, 2}));

  REQUIRE_THROWS_AS(SparseSystem(V{0, 3, 2, 5}, C{0, 1, 2, 0, 2}), std::invalid_argument);  // not monotone
  REQUIRE_THROWS_AS(SparseSystem(V{0, 2, 4, 5}, C{0, 1, 1, 3, 2}), std::invalid_argument);  // column >= rows
  REQUIRE_THROWS_AS(SparseSystem(V{0, 2, 4, 5}, C{0, 1, 1, -1, 2}), std::invalid_argument); // negative column
  REQUIRE_THROWS_AS(SparseSystem(V{0, 2, 4, 6}, C{0, 1, 1, 0, 2}), std::invalid_argument);  // back() != nnz
  REQUIRE_THROWS_AS(SparseSystem(V{1, 2, 4, 5}, C{0, 1, 1, 0, 2}), std::invalid_argument);  // front() != 0
  REQUIRE_THROWS_AS(SparseSystem(V{0, 2, 4, 5}, C{0, 0, 1, 0, 2}), std::invalid_argument);  // duplicate
  REQUIRE_THROWS_AS(SparseSystem(V{}, C{}), std::invalid_argument);                          // no offsets

  auto with = [](auto change) {
    SolverOptions o;
    change(o);
    return o;
  };
  const V offsets{0, 1, 2};
  const C columns{0, 1};
  REQUIRE_THROWS_AS(SparseSystem(offsets, columns, with([](auto& o) { o.method = "bicg"; })),
                    std::invalid_argument);
  REQUIRE_THROWS_AS(
      SparseSystem(offsets, columns, with([](auto& o) { o.preconditioner = "amg"; })),
      std::invalid_argument);
  REQUIRE_THROWS_AS(SparseSystem(offsets, columns, with([](auto& o) { o.tolerance = 0; })),
                    std::invalid_argument);
  REQUIRE_THROWS_AS(SparseSystem(offsets, columns, with([](auto& o) { o.max_iterations = 0; })),
                    std::invalid_argument);
}

TEST_CASE("MpiSession never finalizes MPI it did not initialize", "[linalg]") {
  frostmpm::ensure_mpi_initialized();
  REQUIRE(frostmpm::mpi_is_active());
  {
    frostmpm::MpiSession session;
    REQUIRE_FALSE(session.owns_mpi());
    REQUIRE(session.size() >= 1);
    REQUIRE(session.rank() >= 0);
    REQUIRE(session.rank() < session.size());
  }
  REQUIRE(frostmpm::mpi_is_active());  // still usable by later solves
  frostmpm::ensure_mpi_initialized();  // idempotent
  REQUIRE(frostmpm::mpi_is_active());
}
