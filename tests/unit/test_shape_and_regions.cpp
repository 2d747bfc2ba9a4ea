// Shape functions, the stencil cache and particle generation by regions.
#include <catch2/catch.hpp>

#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/physics/boundary_type.hpp"
#include "frostmpm/scene/region.hpp"
#include "frostmpm/shape/stencil_cache.hpp"

using namespace frostmpm;

namespace {
UniformGrid<2> make_grid(ShapeKind kind) {
  UniformGrid<2> g;
  g.origin = {0.0, 0.0};
  g.spacing = {0.1, 0.2};
  g.cells = {10, 5};
  g.ghost_layers = ghost_layers(kind);
  return g;
}
}  // namespace

TEST_CASE("shape functions: partition of unity, zero gradient sum, linear reproduction", "[shape]") {
  for (ShapeKind kind : {ShapeKind::Linear, ShapeKind::Gimp, ShapeKind::CubicBSpline}) {
    INFO(to_string(kind));
    const auto grid = make_grid(kind);
    StencilCache<2> cache;
    cache.configure(kind);
    // Particles away from the domain edge (B-splines are complete only there).
    std::vector<double> pos, half;
    for (double x = 0.23; x < 0.8; x += 0.0371)
      for (double y = 0.31; y < 0.7; y += 0.0533) {
        pos.insert(pos.end(), {x, y});
        half.insert(half.end(), {0.025, 0.05});
      }
    REQUIRE(cache.update(grid, pos, half) == -1);
    const int K = cache.per_particle();
    for (std::size_t p = 0; p < pos.size() / 2; ++p) {
      double sum = 0, gx = 0, gy = 0, rx = 0, ry = 0, drx = 0, dry = 0;
      for (int k = 0; k < K; ++k) {
        const auto xi = grid.node_position(cache.nodes(p)[k]);
        const double w = cache.weights(p)[k];
        sum += w;
        gx += cache.gradients(p)[2 * k];
        gy += cache.gradients(p)[2 * k + 1];
        rx += w * xi[0];
        ry += w * xi[1];
        drx += cache.gradients(p)[2 * k] * xi[0];  // ∇ of the reproduced x: must be (1, 0)
        dry += cache.gradients(p)[2 * k + 1] * xi[1];
      }
      REQUIRE(sum == Approx(1.0).margin(1e-12));
      REQUIRE(gx == Approx(0.0).margin(1e-9));
      REQUIRE(gy == Approx(0.0).margin(1e-9));
      REQUIRE(rx == Approx(pos[2 * p]).margin(1e-12));
      REQUIRE(ry == Approx(pos[2 * p + 1]).margin(1e-12));
      REQUIRE(drx == Approx(1.0).margin(1e-9));
      REQUIRE(dry == Approx(1.0).margin(1e-9));
    }
  }
}

TEST_CASE("GIMP weights match the closed form of Bardenhagen & Kober", "[shape]") {
  double w[3], g[3];
  // Particle at the node (xi = 3), half-width lp = 0.25 cells: S = 1 − lp/2 at the node and
  // (h + lp − |r|)²/(4 h lp) = 0.25²/1 = 0.0625 at the neighbours... ((1.25 − 1)² / (4·0.25)).
  const int base = shape_1d(ShapeKind::Gimp, 3.0, 1.0, 0.25, w, g);
  REQUIRE(base == 2);
  REQUIRE(w[1] == Approx(1 - 0.25 / 2));
  REQUIRE(w[0] == Approx(0.0625));
  REQUIRE(w[2] == Approx(0.0625));
  REQUIRE(g[1] == Approx(0.0));
}

TEST_CASE("a particle outside the grid is reported by the stencil cache", "[shape]") {
  const auto grid = make_grid(ShapeKind::Linear);
  StencilCache<2> cache;
  cache.configure(ShapeKind::Linear);
  std::vector<double> pos = {0.5, 0.5, 1.5, 0.5}, half = {0.025, 0.05, 0.025, 0.05};
  REQUIRE(cache.update(grid, pos, half) == 1);
}

TEST_CASE("a GIMP domain clipped at the grid's edge keeps a zero gradient sum however little of it is left",
          "[shape]") {
  // A particle leaving through x_max: its domain [x − lp, x + lp] ends δ cells inside the grid. On
  // its last step δ can be ~1e-11; the gradient sum must stay at round-off (a rigid translation
  // must not strain it) and the two edge nodes take ±1/h (the clipped domain lies in one cell).
  UniformGrid<2> grid;
  grid.spacing = {0.02, 0.02};
  grid.cells = {100, 4};
  grid.ghost_layers = ghost_layers(ShapeKind::Gimp);
  const double h = 0.02, edge = 100 * h, lp = 0.25 * h;
  std::vector<double> deltas = {0.3, 1e-3, 1e-7};
  for (int k = 1; k <= 64; ++k) deltas.push_back(k * 1.37e-12);  // the rounding of x − lp varies with δ
  for (const double delta : deltas) {
    INFO("delta = " << delta << " cells");
    StencilCache<2> cache;
    cache.configure(ShapeKind::Gimp);
    const std::vector<double> pos = {edge + lp - delta * h, 0.035}, half = {lp, lp};
    REQUIRE(cache.update(grid, pos, half) == -1);
    double sum = 0, gx = 0, gy = 0, g_edge = 0, g_inner = 0;
    for (int k = 0; k < cache.per_particle(); ++k) {
      const auto x = grid.node_position(cache.nodes(0)[k]);
      sum += cache.weights(0)[k];
      gx += cache.gradients(0)[2 * k];
      gy += cache.gradients(0)[2 * k + 1];
      if (std::abs(x[0] - edge) < 1e-9) g_edge += cache.gradients(0)[2 * k];
      if (std::abs(x[0] - (edge - h)) < 1e-9) g_inner += cache.gradients(0)[2 * k];
    }
    CHECK(sum == Approx(1.0).margin(1e-14));
    CHECK(std::abs(gx) * h < 1e-14);
    CHECK(std::abs(gy) * h < 1e-14);
    CHECK(g_edge * h == Approx(1.0).epsilon(1e-3));
    CHECK(g_inner * h == Approx(-1.0).epsilon(1e-3));
  }
}

TEST_CASE("GIMP particles filling the grid to its edge stay inside it for any cell size", "[shape]") {
  // Round-off in (x − origin)/h once gave the node past the last one a ~1e-27 weight, so the
  // particle in the last cell counted as outside and lost its whole stencil (bench/stability,
  // freezing at Δx = 0.0237… m; 100 cells of 5 cm or 10 cm too).
  for (const double h : {0.023705193823151, 0.05, 0.1, 0.01, 1e-3, 10.0, 0.3, 0.07}) {
    for (const int n : {7, 100, 333, 1000}) {
      INFO("h = " << h << ", " << n << " cells");
      UniformGrid<2> grid;
      grid.spacing = {h, h};
      grid.cells = {1, n};
      grid.ghost_layers = ghost_layers(ShapeKind::Gimp);
      std::ostringstream yaml;
      yaml << std::setprecision(17) << "box: {min: [0, 0], max: [" << h << ", " << n * h << "]}";
      const auto box = ConfigNode::load_string(yaml.str());
      const auto points = sample_region(grid, read_region_shape(box), 2);
      REQUIRE(points.size() == static_cast<std::size_t>(4 * n));
      std::vector<double> pos, half;
      for (const auto& p : points) {
        pos.insert(pos.end(), {p[0], p[1]});
        half.insert(half.end(), {h / 4, h / 4});
      }
      StencilCache<2> cache;
      cache.configure(ShapeKind::Gimp);
      REQUIRE(cache.update(grid, pos, half) == -1);
      for (std::size_t p = 0; p < points.size(); ++p) {
        double sum = 0;
        for (int k = 0; k < cache.per_particle(); ++k) sum += cache.weights(p)[k];
        REQUIRE(sum == Approx(1.0).margin(1e-12));
      }
    }
  }
}

TEST_CASE("regions: box, disk, half-disk and polygon fill their area with n×n particles per cell", "[regions]") {
  UniformGrid<2> grid;
  grid.spacing = {0.01, 0.01};
  grid.cells = {200, 200};
  const double particle_area = 0.01 * 0.01 / 4;  // 2×2 per cell
  struct Case {
    std::string yaml;
    double area;
  };
  const double pi = std::acos(-1.0);
  for (const Case& c : {Case{"box: {min: [0.2, 0.3], max: [1.2, 0.8]}", 0.5},
                        Case{"disk: {center: [1.0, 1.0], radius: 0.5}", pi * 0.25},
                        Case{"half_disk: {center: [1.0, 1.0], radius: 0.5, side: top}", pi * 0.125},
                        Case{"polygon: [[0.1, 0.1], [1.1, 0.1], [0.1, 1.1]]", 0.5}}) {
    INFO(c.yaml);
    const auto node = ConfigNode::load_string(c.yaml);
    const auto shape = read_region_shape(node);
    const auto points = sample_region(grid, shape, 2);
    // Area within one row of particles along the boundary.
    REQUIRE(points.size() * particle_area == Approx(c.area).epsilon(0.02));
    for (const auto& p : points) REQUIRE(shape.contains(p));
  }
}

TEST_CASE("regions: a bad shape names the YAML path and the valid shapes", "[regions]") {
  const auto node = ConfigNode::load_string("circle: {center: [0, 0], radius: 1}");
  try {
    read_region_shape(node);
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    REQUIRE(std::string(e.what()).find("box, disk, half_disk, polygon") != std::string::npos);
  }
}

TEST_CASE("a periodic axis wraps the stencil: the weights of a particle next to the seam are those of its "
          "image one period inside, on nodes one period round",
          "[shape][periodic]") {
  for (ShapeKind kind : {ShapeKind::Linear, ShapeKind::Gimp, ShapeKind::CubicBSpline}) {
    INFO(to_string(kind));
    auto grid = make_grid(kind);
    grid.periodic = {true, false};
    const double period = grid.cells[0] * grid.spacing[0];
    // Near x = 0 and x = L, every part of the support reaches past the seam; at mid-height.
    for (const double x : {0.0, 0.004, 0.03, 0.05, 0.97, 0.999, 0.9999999}) {
      INFO("x = " << x);
      StencilCache<2> wrapped, inner;
      wrapped.configure(kind);
      inner.configure(kind);
      // The image: the same particle on a wide, non-periodic grid, half a period further in.
      auto wide = make_grid(kind);
      wide.cells[0] = 3 * grid.cells[0];
      const std::vector<double> half = {0.025, 0.05};
      const std::vector<double> pos = {x, 0.5}, image = {x + period, 0.5};
      REQUIRE(wrapped.update(grid, pos, half) == -1);
      REQUIRE(inner.update(wide, image, half) == -1);
      double sum = 0;
      for (int k = 0; k < wrapped.per_particle(); ++k) {
        const auto ijk = grid.node_lattice(wrapped.nodes(0)[k]);
        const auto far = wide.node_lattice(inner.nodes(0)[k]);
        REQUIRE(ijk[0] >= 0);
        REQUIRE(ijk[0] < grid.cells[0]);  // node `cells` is node 0
        REQUIRE(ijk[0] == (far[0] - grid.cells[0] + 2 * grid.cells[0]) % grid.cells[0]);
        REQUIRE(ijk[1] == far[1]);
        REQUIRE(wrapped.weights(0)[k] == Approx(inner.weights(0)[k]).margin(1e-12));
        REQUIRE(wrapped.gradients(0)[2 * k] == Approx(inner.gradients(0)[2 * k]).margin(1e-9));
        sum += wrapped.weights(0)[k];
      }
      REQUIRE(sum == Approx(1.0).margin(1e-12));
    }
    // Positions wrap into [origin, origin + L), also from just below the origin.
    REQUIRE(grid.wrap_position(0, -1e-17) < period);
    REQUIRE(grid.wrap_position(0, -0.25) == Approx(period - 0.25));
    REQUIRE(grid.wrap_position(0, 2 * period + 0.3) == Approx(0.3));
    REQUIRE(grid.wrap_position(1, -0.25) == -0.25);  // y is not periodic
  }
}

TEST_CASE("faces of a periodic grid: the face across the periodic axis has one node per cell, each a whole cell",
          "[shape][periodic]") {
  auto grid = make_grid(ShapeKind::Gimp);
  grid.periodic = {true, false};
  std::vector<std::size_t> nodes;
  std::vector<double> areas;
  face_nodes(grid, GridFace{1, -1}, nodes, areas);
  REQUIRE(nodes.size() == std::size_t(grid.cells[0]));
  double length = 0;
  for (double a : areas) length += a;
  REQUIRE(length == Approx(grid.cells[0] * grid.spacing[0]));
  REQUIRE(box_nodes<2>(grid, {0.0, 0.0}, {1.0, 0.0}).size() == std::size_t(grid.cells[0]));
}

TEST_CASE("a condition on a surface layer of particles holds the same nodes whatever the round-off and small "
          "strains", "[shape][conditions]") {
  // Four 0.1 m cells tall, two wide, 2×2 GIMP particles a cell. The layer is the top cell's two
  // particle rows (all of the node row y = 0.4 and exactly half of y = 0.3, its lower edge) or its
  // top particle row alone (three quarters of y = 0.4, an eighth of y = 0.3).
  const double h = 0.1;
  UniformGrid<2> grid;
  grid.spacing = {h, h};
  grid.cells = {2, 4};
  grid.ghost_layers = ghost_layers(ShapeKind::Gimp);
  const auto box = ConfigNode::load_string("box: {min: [0, 0], max: [0.2, 0.4]}");
  const auto points = sample_region(grid, read_region_shape(box), 2);
  auto held_rows = [&](double layer_bottom, double layer_strain, double shift) {
    std::vector<double> pos, half, volume;
    std::vector<std::size_t> layer;
    for (std::size_t p = 0; p < points.size(); ++p) {
      const bool in_layer = points[p][1] > layer_bottom;
      // The layer a little strained and moved against the rest, as a load or a heave leaves it.
      pos.insert(pos.end(), {points[p][0], points[p][1] + (in_layer ? shift : 0.0)});
      half.insert(half.end(), {h / 4, h / 4});
      volume.push_back(h * h / 4 * (in_layer ? 1.0 + layer_strain : 1.0));
      if (in_layer) layer.push_back(p);
    }
    StencilCache<2> cache;
    cache.configure(ShapeKind::Gimp);
    REQUIRE(cache.update(grid, pos, half) == -1);
    std::vector<double> node_volume(grid.node_count(), 0.0), share;
    for (std::size_t p = 0; p < points.size(); ++p)
      for (int k = 0; k < cache.per_particle(); ++k) node_volume[cache.nodes(p)[k]] += volume[p] * cache.weights(p)[k];
    std::set<long> rows;  // node rows, counted in cells from y = 0
    for (const std::size_t i : nodes_made_up_by(layer, cache, volume, node_volume, share))
      rows.insert(std::lround(grid.node_position(i)[1] / h));
    return std::vector<long>(rows.begin(), rows.end());
  };
  const std::vector<long> full_cell = {3, 4};
  for (const double strain : {0.0, 1e-12, -1e-12, 1e-4, -1e-4, 0.02, -0.02})
    for (const double shift : {0.0, 1e-6, -1e-6, 3e-4, -3e-4}) {
      INFO("layer strain " << strain << ", shift " << shift << " m");
      CHECK(held_rows(0.3, strain, shift) == full_cell);
      CHECK(held_rows(0.35, strain, shift) == std::vector<long>{4});
    }
}
