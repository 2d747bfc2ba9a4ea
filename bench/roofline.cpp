// The throughput reference of bench/throughput: a minimal GIMP P2G + G2P round trip over the
// kernel's own StencilCache and ColouredBlocks, with nothing else in the step. A physics step
// does at least this much memory traffic per particle, so the scene's particle-steps/s divided
// by this kernel's, measured in the same run on the same machine, says how close the physics
// comes to what the transfers alone allow — a ratio that survives a noisy, shared machine.
//
// Per step, with 2 × 2 particles per cell on the scene's 3 m × 1 m grid (same cells, same
// particle order as the regions sampler):
//   1. zero five nodal fields;
//   2. P2G: every particle scatters five scalars × its nine GIMP weights (coloured blocks:
//      race-free, parallel, bitwise independent of the thread count);
//   3. nodal update: three nodal fields from the five sums (weighted averages);
//   4. G2P: every particle gathers the three fields' values and 2-D gradients (nine values)
//      and takes the interpolated temperature back as its own (a PIC update), so each step
//      depends on the last and no loop can be dropped.
// A checksum of the final particle state is printed; it is identical on any thread count.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <vector>

#include <CLI/CLI.hpp>

#include "kernel_timing.hpp"

#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/parallel/parallel.hpp"
#include "frostmpm/shape/stencil_cache.hpp"
#include "frostmpm/transfer/coloured_blocks.hpp"

using namespace frostmpm;

namespace {

constexpr int kScattered = 5;  // nodal sums per step
constexpr int kGathered = 3;   // nodal fields read back, each with value + 2-D gradient
constexpr int kPerCell = 2;    // particles per cell along each axis, as in the scenes

struct Kernel {
  UniformGrid<2> grid;
  StencilCache<2> stencil;
  ColouredBlocks<2> blocks;
  std::size_t n = 0;
  // Particle inputs (volume, capacity, conductivity, water), the PIC temperature it updates,
  // and the nine gathered values; all SoA.
  std::vector<double> volume, capacity, conductivity, water, temperature;
  std::array<std::vector<double>, 3 * kGathered> gathered;
  std::array<std::vector<double>, kScattered> nodal_sum;
  std::array<std::vector<double>, kGathered> nodal_field;

  Kernel(int cells_x, int cells_y, double length_x) {
    const double h = length_x / cells_x;
    grid.spacing = {h, h};
    grid.cells = {cells_x, cells_y};
    grid.ghost_layers = ghost_layers(ShapeKind::Gimp);
    stencil.configure(ShapeKind::Gimp);
    // Row by row like sample_region, so the particle order (and cache behaviour) matches a scene.
    std::vector<double> position, half_size;
    for (int j = 0; j < cells_y; ++j)
      for (int b = 0; b < kPerCell; ++b)
        for (int i = 0; i < cells_x; ++i)
          for (int a = 0; a < kPerCell; ++a) {
            position.push_back((i + (a + 0.5) / kPerCell) * h);
            position.push_back((j + (b + 0.5) / kPerCell) * h);
            half_size.insert(half_size.end(), {0.5 * h / kPerCell, 0.5 * h / kPerCell});
          }
    n = position.size() / 2;
    if (stencil.update(grid, position, half_size) >= 0) throw std::logic_error("roofline: particle outside the grid");
    blocks.build(grid, stencil, support_width(ShapeKind::Gimp));

    volume.assign(n, h * h / (kPerCell * kPerCell));
    capacity.resize(n);
    conductivity.resize(n);
    water.resize(n);
    temperature.resize(n);
    // A cold square in a warm box, like the frozen inclusion, with properties varying by particle.
    for (std::size_t p = 0; p < n; ++p) {
      const double x = position[2 * p], y = position[2 * p + 1];
      const bool cold = std::abs(x - 1.0) < 1.0 / 6 && std::abs(y - 0.5) < 1.0 / 6;
      temperature[p] = cold ? -5.0 : 5.0;
      capacity[p] = (cold ? 2.1e6 : 2.9e6) * (1.0 + 0.01 * std::sin(37.0 * x + 11.0 * y));
      conductivity[p] = cold ? 3.5 : 2.2;
      water[p] = cold ? 0.05 : 0.37;
    }
    for (auto& g : gathered) g.assign(n, 0.0);
    for (auto& f : nodal_sum) f.assign(grid.node_count(), 0.0);
    for (auto& f : nodal_field) f.assign(grid.node_count(), 0.0);
  }

  void step() {
    const int K = stencil.per_particle();
    const std::size_t nodes = grid.node_count();
    parallel_for(nodes, [&](std::size_t i) {
      for (auto& f : nodal_sum) f[i] = 0.0;
    });

    double* sum0 = nodal_sum[0].data();
    double* sum1 = nodal_sum[1].data();
    double* sum2 = nodal_sum[2].data();
    double* sum3 = nodal_sum[3].data();
    double* sum4 = nodal_sum[4].data();
    blocks.for_each([&](std::size_t p) {
      const std::uint32_t* node = stencil.nodes(p);
      const double* w = stencil.weights(p);
      const double v = volume[p], vc = v * capacity[p];
      const double s0 = v, s1 = vc, s2 = vc * temperature[p], s3 = v * conductivity[p], s4 = v * water[p];
      for (int k = 0; k < K; ++k) {
        const std::uint32_t i = node[k];
        sum0[i] += w[k] * s0;
        sum1[i] += w[k] * s1;
        sum2[i] += w[k] * s2;
        sum3[i] += w[k] * s3;
        sum4[i] += w[k] * s4;
      }
    });

    // Nodal temperature (capacity-weighted), conductivity and water content (volume-weighted).
    double* temperature_i = nodal_field[0].data();
    double* conductivity_i = nodal_field[1].data();
    double* water_i = nodal_field[2].data();
    parallel_for(nodes, [&](std::size_t i) {
      const bool touched = sum0[i] > 0;
      temperature_i[i] = touched ? sum2[i] / sum1[i] : 0.0;
      conductivity_i[i] = touched ? sum3[i] / sum0[i] : 0.0;
      water_i[i] = touched ? sum4[i] / sum0[i] : 0.0;
    });

    parallel_for(n, [&](std::size_t p) {
      const std::uint32_t* node = stencil.nodes(p);
      const double* w = stencil.weights(p);
      const double* grad = stencil.gradients(p);
      std::array<double, 3 * kGathered> acc{};
      for (int k = 0; k < K; ++k) {
        const std::uint32_t i = node[k];
        const double gx = grad[2 * k], gy = grad[2 * k + 1];
        const std::array<double, kGathered> f{temperature_i[i], conductivity_i[i], water_i[i]};
        for (int m = 0; m < kGathered; ++m) {
          acc[3 * m] += w[k] * f[m];
          acc[3 * m + 1] += gx * f[m];
          acc[3 * m + 2] += gy * f[m];
        }
      }
      for (int m = 0; m < 3 * kGathered; ++m) gathered[m][p] = acc[m];
      temperature[p] = acc[0];
    });
  }

  /// Sum of every particle's state and gathered values: uses all results, thread-count independent.
  double checksum() const {
    return reproducible_sum(n, [&](std::size_t p) {
      double s = temperature[p];
      for (int m = 0; m < 3 * kGathered; ++m) s += (m + 1) * gathered[m][p];
      return s;
    });
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"GIMP P2G (5 fields) + G2P (3 fields with gradients) reference kernel for bench/throughput"};
  frostmpm::bench::TimingOptions o;
  frostmpm::bench::add_timing_options(cli, o);
  CLI11_PARSE(cli, argc, argv);
  if (o.threads > 0) omp_set_num_threads(o.threads);

  const int cells_y = frostmpm::bench::block_cells_y(o.particles);
  Kernel kernel(3 * cells_y, cells_y, 3.0);
  const auto t = frostmpm::bench::time_steps(kernel, o);
  const double checksum = kernel.checksum();

  if (o.json) {
    std::printf(
        "{\"particles\": %zu, \"cells\": [%d, %d], \"threads\": %d, \"steps_per_repetition\": %d, "
        "\"repetitions\": %d, \"particle_steps_per_s\": %.6e, \"particle_steps_per_s_best\": %.6e, "
        "\"cpu_share\": %.3f, \"checksum\": %.17g}\n",
        kernel.n, kernel.grid.cells[0], kernel.grid.cells[1], thread_count(), t.steps, t.repetitions, t.median, t.best,
        t.cpu_share, checksum);
  } else {
    std::printf("roofline: GIMP P2G of %d fields + G2P of %d fields with gradients, %zu particles on %d x %d cells\n",
                kScattered, kGathered, kernel.n, kernel.grid.cells[0], kernel.grid.cells[1]);
    frostmpm::bench::print_timing(t, o);
    std::printf("checksum %.17g\n", checksum);
  }
  return std::isfinite(checksum) ? 0 : 1;
}
