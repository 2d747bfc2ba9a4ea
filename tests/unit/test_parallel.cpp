// Parallel loops: coloured P2G scatter is race-free and bitwise independent of the thread count;
// reproducible sums do not depend on the thread count either, nor do parallel_chunks' chunks.
#include <catch2/catch.hpp>

#include <cmath>
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <omp.h>

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/shape/stencil_cache.hpp"
#include "frostmpm/transfer/coloured_blocks.hpp"

using namespace frostmpm;

namespace {

struct Scatter {
  UniformGrid<2> grid;
  StencilCache<2> stencil;
  ColouredBlocks<2> blocks;
  std::vector<double> values;

  /// periodic: the grid wraps along x and the particles fill it across the seam.
  explicit Scatter(ShapeKind kind, bool periodic = false) {
    grid.spacing = {0.1, 0.1};
    grid.cells = {37, 23};
    grid.ghost_layers = ghost_layers(kind);
    grid.periodic = {periodic, false};
    stencil.configure(kind);
    std::vector<double> pos, half;
    // 3×3 particles per cell, jittered, so sums are not trivially exact; a cell's margin
    // keeps every GIMP support inside the grid (but for x on a periodic grid).
    for (int i = periodic ? 0 : 3; i < (periodic ? 37 : 36) * 3; ++i)
      for (int j = 3; j < 22 * 3; ++j) {
        pos.push_back(grid.wrap_position(0, (i + 0.5 + 0.3 * std::sin(7.0 * i + j)) * 0.1 / 3));
        pos.push_back((j + 0.5 + 0.3 * std::cos(3.0 * i - j)) * 0.1 / 3);
        half.insert(half.end(), {0.1 / 6, 0.1 / 6});
        values.push_back(std::sin(0.37 * i) * std::exp(0.01 * j) + 1e-7 * i * j);
      }
    REQUIRE(stencil.update(grid, pos, half) == -1);
    blocks.build(grid, stencil, support_width(kind));
  }

  std::vector<double> p2g(int threads) const {
    omp_set_num_threads(threads);
    std::vector<double> nodal(grid.node_count(), 0.0);
    const int K = stencil.per_particle();
    blocks.for_each([&](std::size_t p) {
      const auto* n = stencil.nodes(p);
      const auto* w = stencil.weights(p);
      for (int k = 0; k < K; ++k) nodal[n[k]] += w[k] * values[p];
    });
    return nodal;
  }
};

}  // namespace

TEST_CASE("coloured blocks: same-colour blocks share no node, every particle once", "[parallel]") {
  for (const bool periodic : {false, true})
  for (ShapeKind kind : {ShapeKind::Linear, ShapeKind::Gimp, ShapeKind::CubicBSpline}) {
    INFO(to_string(kind) << (periodic ? ", periodic along x" : ""));
    Scatter s(kind, periodic);
    REQUIRE(s.blocks.particles() == s.values.size());
    std::vector<int> visits(s.values.size(), 0);
    const int K = s.stencil.per_particle();
    for (int c = 0; c < ColouredBlocks<2>::kGroups; ++c) {
      std::vector<long> writer(s.grid.node_count(), -1);  // block that wrote each node in colour c
      for (std::uint32_t b = s.blocks.first_block(c); b < s.blocks.first_block(c + 1); ++b)
        for (std::uint32_t p : s.blocks.block(b)) {
          ++visits[p];
          for (int k = 0; k < K; ++k) {
            long& w = writer[s.stencil.nodes(p)[k]];
            REQUIRE((w == -1 || w == long(b)));
            w = long(b);
          }
        }
    }
    for (int v : visits) REQUIRE(v == 1);
    // The stencils across the seam: one serial block, only on a periodic grid.
    const auto seam = s.blocks.first_block(ColouredBlocks<2>::kGroups) - s.blocks.first_block(ColouredBlocks<2>::kColours);
    REQUIRE(seam == (periodic ? 1u : 0u));
    REQUIRE(s.blocks.blocks() > 8);  // enough blocks per colour to keep threads busy
  }
}

TEST_CASE("coloured P2G scatter is bitwise identical on 1, 2 and 4 threads", "[parallel]") {
  for (const bool periodic : {false, true})
  for (ShapeKind kind : {ShapeKind::Linear, ShapeKind::Gimp, ShapeKind::CubicBSpline}) {
    INFO(to_string(kind) << (periodic ? ", periodic along x" : ""));
    Scatter s(kind, periodic);
    const auto one = s.p2g(1);
    for (int threads : {2, 4}) {
      const auto many = s.p2g(threads);
      REQUIRE(std::memcmp(one.data(), many.data(), one.size() * sizeof(double)) == 0);
    }
    // And it is the right sum: total = Σ values (partition of unity), to round-off.
    double total = 0, expected = 0;
    for (double v : one) total += v;
    for (double v : s.values) expected += v;
    REQUIRE(total == Approx(expected).epsilon(1e-12));
  }
  omp_set_num_threads(1);
}

TEST_CASE("reproducible_sum is bitwise identical on any thread count", "[parallel]") {
  const std::size_t n = 100003;
  auto f = [](std::size_t i) { return std::sin(0.001 * double(i)) * 1e3 + 1e-9 * double(i); };
  omp_set_num_threads(1);
  const double one = reproducible_sum(n, f);
  for (int threads : {2, 3, 8}) {
    omp_set_num_threads(threads);
    const double many = reproducible_sum(n, f);
    REQUIRE(std::memcmp(&one, &many, sizeof one) == 0);
  }
  omp_set_num_threads(1);
  REQUIRE(parallel_max(n, f, -1e300) >= f(1570));
}

TEST_CASE("parallel_chunks covers the range once in fixed chunks and rethrows the first chunk's error",
          "[parallel]") {
  const std::size_t n = 5 * 512 + 7;
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    std::vector<int> seen(n, 0);
    std::vector<std::size_t> firsts(6, 0), counts(6, 0);
    parallel_chunks(n, 512, [&](std::size_t begin, std::size_t count) {
      firsts[begin / 512] = begin;
      counts[begin / 512] = count;
      for (std::size_t i = begin; i < begin + count; ++i) ++seen[i];
    });
    REQUIRE(std::count(seen.begin(), seen.end(), 1) == long(n));
    for (std::size_t c = 0; c < 6; ++c) {
      REQUIRE(firsts[c] == 512 * c);  // the same chunks whatever the thread count
      REQUIRE(counts[c] == (c < 5 ? 512 : 7));
    }
    // Chunks 2 and 4 fail: the error of chunk 2 comes back, whichever thread met it first.
    try {
      parallel_chunks(n, 512, [&](std::size_t begin, std::size_t) {
        if (begin == 2 * 512 || begin == 4 * 512) throw std::runtime_error("chunk " + std::to_string(begin / 512));
      });
      FAIL("no exception");
    } catch (const std::runtime_error& e) {
      REQUIRE(std::string(e.what()) == "chunk 2");
    }
  }
  omp_set_num_threads(1);
  int calls = 0;
  parallel_chunks(0, 512, [&](std::size_t, std::size_t) { ++calls; });
  REQUIRE(calls == 0);
}

TEST_CASE("coloured blocks rebuilt after particles moved are the blocks a fresh build makes", "[parallel]") {
  UniformGrid<2> grid;
  grid.spacing = {0.1, 0.1};
  grid.cells = {80, 12};
  grid.ghost_layers = ghost_layers(ShapeKind::Gimp);
  std::vector<double> pos, half;
  for (int i = 2; i < 70 * 2; ++i)  // room on the right for the moves below
    for (int j = 4; j < 10 * 2; ++j) {
      pos.insert(pos.end(), {(i + 0.5) * 0.05, (j + 0.5) * 0.05});
      half.insert(half.end(), {0.025, 0.025});
    }
  StencilCache<2> stencil;
  stencil.configure(ShapeKind::Gimp);
  ColouredBlocks<2> kept;
  auto same_as_fresh = [&] {
    REQUIRE(stencil.update(grid, pos, half) == -1);
    kept.build(grid, stencil, 3);
    ColouredBlocks<2> fresh;
    fresh.build(grid, stencil, 3);
    REQUIRE(kept.blocks() == fresh.blocks());
    for (int c = 0; c <= ColouredBlocks<2>::kGroups; ++c) REQUIRE(kept.first_block(c) == fresh.first_block(c));
    for (std::uint32_t b = 0; b < fresh.blocks(); ++b) {
      const auto a = kept.block(b), f = fresh.block(b);
      REQUIRE(std::equal(a.begin(), a.end(), f.begin(), f.end()));
    }
  };
  same_as_fresh();
  const std::size_t p = 17 * 16 + 5;  // x = 0.975 m: lowest node 9, inside the first 32-node block
  SECTION("a particle that moved a cell along x inside its block") {
    pos[2 * p] += 0.1;
    same_as_fresh();
  }
  SECTION("particles that moved into the next block along x, then back") {
    for (std::size_t q = 0; q < pos.size() / 2; ++q) pos[2 * q] += 0.3;  // 3 cells: some enter the next block
    same_as_fresh();
    for (std::size_t q = 0; q < pos.size() / 2; ++q) pos[2 * q] -= 0.3;
    same_as_fresh();
  }
  SECTION("one particle that moved into the next block row along y") {
    pos[2 * p + 1] += 0.2;
    same_as_fresh();
  }
  SECTION("two particles of different blocks that swapped places") {
    const std::size_t q = pos.size() / 2 - 1;  // the last one: x = 6.975 m, another block
    std::swap(pos[2 * p], pos[2 * q]);
    std::swap(pos[2 * p + 1], pos[2 * q + 1]);
    same_as_fresh();
  }
  SECTION("the last particles removed (the rest where they were)") {
    pos.resize(pos.size() - 2 * 40);
    half.resize(half.size() - 2 * 40);
    same_as_fresh();
  }
}
