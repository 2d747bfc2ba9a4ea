// GradientGram: Σ_p c_p ∇S_ip·∇S_jp kept up to date row by row must equal a full assembly bit
// for bit, whichever coefficients changed.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/transfer/gradient_gram.hpp"
#include "frostmpm/transfer/stencil_graph.hpp"
#include "frostmpm/transfer/transfer.hpp"

using namespace frostmpm;

namespace {
struct Scene {
  UniformGrid<2> grid;
  Transfer<2> transfer;
  StencilGraph graph;
  std::vector<double> coefficient;

  Scene() {
    grid.origin = {0.0, 0.0};
    grid.spacing = {0.1, 0.1};
    grid.cells = {24, 16};
    grid.ghost_layers = ghost_layers(ShapeKind::Gimp);
    transfer.configure(ShapeKind::Gimp);
    std::vector<double> x, half;
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 48; ++i) {
        x.insert(x.end(), {0.025 + 0.05 * i, 0.025 + 0.05 * j});
        half.insert(half.end(), {0.025, 0.025});
      }
    transfer.set_materials(std::vector<std::uint16_t>(x.size() / 2, 0));
    REQUIRE(transfer.update(grid, x, half) == -1);
    graph.build(transfer.stencil(), grid.node_count());
    for (std::size_t p = 0; p < x.size() / 2; ++p) coefficient.push_back(1.0 + 0.37 * std::sin(0.1 * double(p)));
  }
  std::vector<double> full_assembly() const {
    GradientGram<2> fresh;
    fresh.update(transfer, graph, [&](std::size_t p) { return coefficient[p]; });
    return fresh.values();
  }
};
}  // namespace

TEST_CASE("GradientGram: an incremental update is bitwise a full assembly, and the full one is the particle sum",
          "[transfer]") {
  Scene s;
  GradientGram<2> gram;
  auto c = [&](std::size_t p) { return s.coefficient[p]; };
  REQUIRE(gram.update(s.transfer, s.graph, c));
  REQUIRE(gram.values() == s.full_assembly());
  REQUIRE_FALSE(gram.update(s.transfer, s.graph, c));  // nothing changed: no row rebuilt

  // The sum itself, entry by entry, and its symmetry.
  const auto& st = s.transfer.stencil();
  const int K = st.per_particle();
  std::vector<double> direct(s.graph.nonzeros(), 0.0);
  for (std::size_t p = 0; p < st.particles(); ++p)
    for (int a = 0; a < K; ++a)
      for (int b = 0; b < K; ++b) {
        const double* g = st.gradients(p);
        direct[s.graph.position(st.nodes(p)[a], int(st.nodes(p)[b]))] +=
            s.coefficient[p] * (g[2 * a] * g[2 * b] + g[2 * a + 1] * g[2 * b + 1]);
      }
  double largest = 0;
  for (double v : direct) largest = std::max(largest, std::abs(v));
  for (std::size_t e = 0; e < direct.size(); ++e) {
    REQUIRE(gram.values()[e] == Approx(direct[e]).margin(1e-13 * largest));
    REQUIRE(gram.values()[e] == Approx(gram.values()[s.graph.transpose[e]]).margin(1e-13 * largest));
  }

  // A front: a band of particles changes its coefficient, then another, then one particle.
  for (const auto& [first, last] : std::vector<std::pair<std::size_t, std::size_t>>{{300, 420}, {401, 402}, {0, 1}, {1500, 1536}}) {
    for (std::size_t p = first; p < last; ++p) s.coefficient[p] *= 1e-3;
    REQUIRE(gram.update(s.transfer, s.graph, c));
    REQUIRE(gram.values() == s.full_assembly());
  }

  // G x: the row products of the kept values.
  std::vector<double> x(s.grid.node_count()), y(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::cos(0.3 * double(i));
  gram.multiply(s.graph, x, y);
  for (std::size_t i = 0; i < x.size(); i += 37) {
    double expected = 0;
    for (std::size_t e = s.graph.offsets[i]; e < s.graph.offsets[i + 1]; ++e)
      expected += gram.values()[e] * x[std::size_t(s.graph.columns[e])];
    REQUIRE(y[i] == expected);
  }
}

TEST_CASE("GradientGram: invalidate() and a new stencil version assemble in full", "[transfer]") {
  Scene s;
  GradientGram<2> gram;
  auto c = [&](std::size_t p) { return s.coefficient[p]; };
  gram.update(s.transfer, s.graph, c);
  gram.invalidate();
  REQUIRE(gram.update(s.transfer, s.graph, c));  // the same coefficients, yet rebuilt
  REQUIRE(gram.values() == s.full_assembly());
}
