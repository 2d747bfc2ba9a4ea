// Starting a run from another run's output: ParticleFieldReader reads back what
// ParticleFieldWriter wrote, and ScatteredField carries a stored field to new positions
// (exactly at coinciding points, exactly for fields linear in space, the nearest point where a
// fit is impossible, and a refusal outside the cloud).
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "frostmpm/io/particle_field_reader.hpp"
#include "frostmpm/io/particle_field_writer.hpp"
#include "frostmpm/scene/scattered_field.hpp"
#include "test_support.hpp"

namespace {

using Catch::Matchers::Contains;
using frostmpm::FieldView;
using frostmpm::ParticleFieldReader;
using frostmpm::ParticleFieldWriter;
using frostmpm::ScatteredField;

/// The points of an nx × ny lattice of spacing h, centred in its cells (a particle layout).
std::vector<double> lattice(int nx, int ny, double h) {
  std::vector<double> x;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      x.push_back((i + 0.5) * h);
      x.push_back((j + 0.5) * h);
    }
  return x;
}

}  // namespace

TEST_CASE("ParticleFieldReader: frames in step order, positions and fields as written", "[io][initial]") {
  const frostmpm::test::TempDir dir;
  const auto pos = lattice(3, 2, 0.5);
  std::vector<double> T = {1, 2, 3, 4, 5, 6}, v(12);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.1 * double(i);
  {
    ParticleFieldWriter writer(dir.path(), 2);
    writer.write(0.0, 0, 6, pos.data(), {{"temperature", T.data(), 1, "degC"}, {"solid_velocity", v.data(), 2, "m/s"}});
    for (double& t : T) t += 10;
    writer.write(5.0, 50, 6, pos.data(), {{"temperature", T.data(), 1, "degC"}, {"solid_velocity", v.data(), 2, "m/s"}});
  }
  const ParticleFieldReader reader(dir.path());
  REQUIRE(reader.dim() == 2);
  REQUIRE(reader.frames().size() == 2);
  const auto& last = reader.frames().back();
  CHECK(last.step == 50);
  CHECK(last.time == 5.0);
  CHECK(reader.positions(last) == pos);
  CHECK(reader.field(last, "temperature").values == T);
  const auto velocity = reader.field(last, "solid_velocity");
  CHECK(velocity.components == 2);
  CHECK(velocity.values == v);  // the writer's padding to 3 columns dropped
  CHECK_THROWS_WITH(reader.field(last, "pressure"),
                    Contains("the frame at t = 5 s") && Contains("no field 'pressure'; it has: solid_velocity, temperature"));
  CHECK_THROWS_WITH(ParticleFieldReader(dir.path() + "/nothing"), Contains("there is no"));
}

TEST_CASE("ScatteredField: coinciding points exactly, linear fields exactly, edges, refusal outside",
          "[initial]") {
  const double h = 0.1;
  const auto points = lattice(20, 10, h);
  const std::size_t n = points.size() / 2;
  // A linear field and a field that is not (a thaw front's kink): two components.
  std::vector<double> values(2 * n);
  auto linear = [](double x, double y) { return 3.0 - 2.0 * x + 0.5 * y; };
  auto kinked = [](double x, double y) { return std::max(0.0, y - 0.4 - 0.1 * x); };
  for (std::size_t p = 0; p < n; ++p) {
    values[2 * p] = linear(points[2 * p], points[2 * p + 1]);
    values[2 * p + 1] = kinked(points[2 * p], points[2 * p + 1]);
  }
  const ScatteredField<2> field(points, values, 2);
  CHECK(field.spacing() == Approx(h));  // the nearest-neighbour distance of the lattice
  std::array<double, 2> out{};
  SECTION("a query on a stored point returns its values bit for bit") {
    for (std::size_t p = 0; p < n; p += 7) {
      REQUIRE(field.evaluate({points[2 * p], points[2 * p + 1]}, out));
      CHECK(out[0] == values[2 * p]);
      CHECK(out[1] == values[2 * p + 1]);
    }
  }
  SECTION("a linear field is reproduced anywhere inside, at the edges and a little beyond") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(-0.04, 2.04), uy(-0.04, 1.04);
    for (int k = 0; k < 500; ++k) {
      const std::array<double, 2> x = {ux(rng), uy(rng)};
      REQUIRE(field.evaluate(x, out));
      CHECK(out[0] == Approx(linear(x[0], x[1])).margin(1e-12));
    }
  }
  SECTION("a kinked field is off by at most its slope times half a spacing near the kink") {
    for (double y = 0.05; y < 1.0; y += 0.013) {
      REQUIRE(field.evaluate({0.77, y}, out));
      CHECK(std::abs(out[1] - kinked(0.77, y)) <= 0.5 * h);
    }
  }
  SECTION("a point far outside the cloud is refused; its distance is reported") {
    CHECK_FALSE(field.evaluate({2.5, 0.55}, out));
    CHECK(field.nearest_distance({2.5, 0.55}) == Approx(2.5 - 1.95));
  }
}

TEST_CASE("ScatteredField: points in a line fall back to the nearest point, and 3-D works alike", "[initial]") {
  const std::vector<double> row = {0.0, 0.0, 1.0, 0.0, 2.0, 0.0, 3.0, 0.0};
  const std::vector<double> v = {10, 11, 12, 13};
  const ScatteredField<2> line(row, v, 1);
  std::array<double, 1> out{};
  REQUIRE(line.evaluate({1.2, 0.0}, out));
  CHECK(out[0] == 11.0);  // too few points within reach for a fit (and all in a line): the nearest
  std::vector<double> cube, w;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        cube.insert(cube.end(), {0.25 * i, 0.25 * j, 0.25 * k});
        w.push_back(1.0 + 0.25 * i - 0.5 * j + 2.0 * 0.25 * k);
      }
  const ScatteredField<3> field3(cube, w, 1);
  REQUIRE(field3.evaluate({0.3, 0.41, 0.6}, out));
  CHECK(out[0] == Approx(1.0 + 0.3 - 2.0 * 0.41 + 2.0 * 0.6).margin(1e-12));
}
