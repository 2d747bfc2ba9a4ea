// The reference kernel of bench/mechanical_throughput: a minimal explicit elastic MPM step of
// our own (no plugins, no field handles, no kernel services), doing the work of the mechanical
// physics' step on moving particles and nothing else. The scene's particle-steps/s divided by
// this kernel's, measured in the same run, says how close the physics comes to a bare
// implementation — a ratio that survives a noisy, shared machine.
//
// The problem is the benchmark scene's: a block 3 m × 1 m of cells 3n × n, 2 × 2 particles per
// cell in the region sampler's order, E = 1 MPa, ν = 0.3, ρ = 2000 kg/m³, gravity −9.81 m/s²
// switched on at t = 0, the base fixed and the sides on rollers (nodal masks; one ghost node
// layer around the grid), Δt = 0.5 h / c_p, no damping. Plane strain, GIMP (uGIMP on the
// particles' current domains), USF with the symplectic position update, as the scene.
//
// Particle data are a structure of arrays (x, y, v, m, V0, V, l0, l, F as four components —
// plane strain keeps F_zz = 1 — and the stress as six Voigt arrays xx, yy, zz, yz, xz, xy).
// Per step, in loops that mirror the scene's stages (none fused across a stage boundary):
//   1. stencil: V = V0 det F, GIMP half-widths l = l0 |row of F| (held below h/2), the 3 × 3
//      GIMP weights and gradients of every particle from its current position and domain
//      (stored: base node, 9 weights, 18 gradients); the scatter blocks are re-sorted when a
//      particle changed block;
//   2. P2G of mass and momentum (coloured blocks);
//   3. nodal velocity v^k = p / m, zero on the fixed base, v_x zero on the sides;
//   4. stress update at the particles: L = Σ v_i ⊗ ∇S, Δε = sym(L) Δt, the Jaumann rotation
//      by W = skew(L), Hooke (λ tr Δε I + 2G Δε), F ← (I + L Δt) F;
//   5. P2G of the internal force −V σ·∇S and the weight S m g (coloured blocks);
//   6. nodal update v* = v^k + Δt f / m (nodes lighter than 1e-6 of a particle keep v^k), the
//      same conditions; ΔvFLIP = v* − p/m;
//   7. G2P: v_p += Σ S ΔvFLIP (FLIP), x_p += Δt Σ S v^k (symplectic).
//
// The scatter is thread-safe and thread-count independent without atomics: particles are
// grouped by the block of their stencil's base node (3 node rows × ≥ 3 node columns), the
// blocks coloured as a 2 × 2 checkerboard; blocks of one colour share no node and run in
// parallel, the particles of a block in index order. A checksum of the final state is printed;
// it is identical on any thread count.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <CLI/CLI.hpp>

#include "kernel_timing.hpp"

#include "frostmpm/parallel/parallel.hpp"

namespace {

using frostmpm::kParallelMinimum;
using frostmpm::reproducible_sum;
using frostmpm::thread_count;

constexpr int kPerCell = 2;  // particles per cell along each axis, as in the scenes
constexpr int kGhost = 1;    // node layers past the domain on every side
constexpr double kYoung = 1.0e6, kPoisson = 0.3, kDensity = 2000.0, kGravity = -9.81, kCfl = 0.5;

/// uGIMP in one dimension (linear grid basis, hat-shaped particle domain of half-width lp, in
/// cell units): weights and derivatives (per cell) on the three nodes base, base+1, base+2
/// around xi. Returns base.
inline int gimp_1d(double xi, double lp, double* s, double* ds) {
  const int base = static_cast<int>(std::floor(xi + 0.5)) - 1;
  for (int k = 0; k < 3; ++k) {
    const double r = xi - (base + k), a = std::abs(r), sign = r < 0 ? -1.0 : 1.0;
    if (a >= 1.0 + lp) {
      s[k] = ds[k] = 0.0;
    } else if (a > 1.0 - lp) {
      const double t = 1.0 + lp - a;
      s[k] = t * t / (4.0 * lp);
      ds[k] = -sign * t / (2.0 * lp);
    } else if (a > lp) {
      s[k] = 1.0 - a;
      ds[k] = -sign;
    } else {
      s[k] = 1.0 - (r * r + lp * lp) / (2.0 * lp);
      ds[k] = -r / lp;
    }
  }
  return base;
}

struct ElasticKernel {
  // Grid: nodes (i, j) for i in [−1, cells_x + 1], j in [−1, cells_y + 1]; node index
  // (j + 1) · nx + (i + 1).
  int cells_x = 0, cells_y = 0, nx = 0, ny = 0;
  double h = 0, dt = 0;
  double G = 0, lambda = 0;
  double grazing = 0;  // nodes lighter than this take no force
  std::size_t n = 0, nodes = 0;

  // Particles (SoA).
  std::vector<double> x, y, vx, vy, mass, V0, V, lx0, ly0, lx, ly;
  std::vector<double> Fxx, Fxy, Fyx, Fyy;
  std::array<std::vector<double>, 6> sigma;  // Voigt: xx, yy, zz, yz, xz, xy
  // Stencil: base node, 9 weights, 18 gradients (x, y per node), node k = base + (k % 3) + (k / 3) · nx.
  std::vector<std::uint32_t> base;
  std::vector<double> w, grad;
  // Scatter blocks.
  int block_cols = 3, blocks_x = 0, blocks_y = 0;
  std::vector<std::uint32_t> block_of, order, block_begin;  // block_begin over blocks sorted by colour
  std::array<std::uint32_t, 5> colour_begin{};
  bool blocks_valid = false;
  // Grid fields.
  std::vector<double> m_i, px_i, py_i, vx_i, vy_i, fx_i, fy_i, dvx_i, dvy_i;
  std::vector<std::uint8_t> fixed_x, fixed_y;  // base row (and the ghost row below): both; sides: x

  ElasticKernel(int cx, int cy, double length_x) : cells_x(cx), cells_y(cy) {
    h = length_x / cells_x;
    nx = cells_x + 1 + 2 * kGhost;
    ny = cells_y + 1 + 2 * kGhost;
    nodes = static_cast<std::size_t>(nx) * ny;
    G = kYoung / (2.0 * (1.0 + kPoisson));
    lambda = kYoung * kPoisson / ((1.0 + kPoisson) * (1.0 - 2.0 * kPoisson));
    dt = kCfl * h / std::sqrt((lambda + 2.0 * G) / kDensity);

    // Row by row like sample_region, so the particle order (and cache behaviour) matches a scene.
    for (int j = 0; j < cells_y; ++j)
      for (int b = 0; b < kPerCell; ++b)
        for (int i = 0; i < cells_x; ++i)
          for (int a = 0; a < kPerCell; ++a) {
            x.push_back((i + (a + 0.5) / kPerCell) * h);
            y.push_back((j + (b + 0.5) / kPerCell) * h);
          }
    n = x.size();
    const double volume = h * h / (kPerCell * kPerCell), half = 0.5 * h / kPerCell;
    vx.assign(n, 0.0);
    vy.assign(n, 0.0);
    mass.assign(n, kDensity * volume);
    V0.assign(n, volume);
    V.assign(n, volume);
    lx0.assign(n, half);
    ly0.assign(n, half);
    lx.assign(n, half);
    ly.assign(n, half);
    Fxx.assign(n, 1.0);
    Fxy.assign(n, 0.0);
    Fyx.assign(n, 0.0);
    Fyy.assign(n, 1.0);
    for (auto& s : sigma) s.assign(n, 0.0);
    base.assign(n, 0);
    w.assign(9 * n, 0.0);
    grad.assign(18 * n, 0.0);
    block_of.assign(n, 0);
    grazing = 1e-6 * kDensity * volume;

    // Blocks: 3 node rows high (the GIMP support), wide enough for ≥ 8 blocks per colour across.
    block_cols = std::max(3, nx / 8);
    blocks_x = (nx + block_cols - 1) / block_cols;
    blocks_y = (ny + 2) / 3;

    for (auto* f : {&m_i, &px_i, &py_i, &vx_i, &vy_i, &fx_i, &fy_i, &dvx_i, &dvy_i}) f->assign(nodes, 0.0);
    fixed_x.assign(nodes, 0);
    fixed_y.assign(nodes, 0);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t node = static_cast<std::size_t>(j) * nx + i;
        fixed_y[node] = j <= kGhost;
        fixed_x[node] = j <= kGhost || i <= kGhost || i >= nx - 1 - kGhost;
      }
  }

  std::uint32_t node_of(std::size_t p, int k) const { return base[p] + (k % 3) + (k / 3) * nx; }

  /// 1. Geometry and stencils of the current positions; blocks re-sorted if any particle moved to another.
  void update_stencil() {
    const double inv_h = 1.0 / h, limit = 0.5 * h * (1 - 1e-9);
    int moved = 0, outside = 0;
#pragma omp parallel for schedule(static) reduction(| : moved, outside) if (n >= kParallelMinimum)
    for (std::size_t p = 0; p < n; ++p) {
      V[p] = V0[p] * (Fxx[p] * Fyy[p] - Fxy[p] * Fyx[p]);
      lx[p] = std::min(lx0[p] * std::sqrt(Fxx[p] * Fxx[p] + Fxy[p] * Fxy[p]), limit);
      ly[p] = std::min(ly0[p] * std::sqrt(Fyx[p] * Fyx[p] + Fyy[p] * Fyy[p]), limit);
      double sx[3], dsx[3], sy[3], dsy[3];
      const int bi = gimp_1d(x[p] * inv_h, lx[p] * inv_h, sx, dsx) + kGhost;
      const int bj = gimp_1d(y[p] * inv_h, ly[p] * inv_h, sy, dsy) + kGhost;
      if (bi < 0 || bj < 0 || bi + 2 >= nx || bj + 2 >= ny) {
        outside = 1;
        continue;
      }
      base[p] = static_cast<std::uint32_t>(bj * nx + bi);
      double* wp = w.data() + 9 * p;
      double* gp = grad.data() + 18 * p;
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) {
          const int k = 3 * b + a;
          wp[k] = sx[a] * sy[b];
          gp[2 * k] = dsx[a] * inv_h * sy[b];
          gp[2 * k + 1] = sx[a] * dsy[b] * inv_h;
        }
      const std::uint32_t block = static_cast<std::uint32_t>((bj / 3) * blocks_x + bi / block_cols);
      if (block != block_of[p]) {
        block_of[p] = block;
        moved = 1;
      }
    }
    if (outside) throw std::runtime_error("elastic_kernel: a particle left the grid");
    if (moved || !blocks_valid) build_blocks();
  }

  /// Counting sort of the particles by block, blocks ordered by colour (2 × 2 checkerboard).
  void build_blocks() {
    const std::size_t count = static_cast<std::size_t>(blocks_x) * blocks_y;
    std::vector<std::uint32_t> rank(count);  // block → position in colour order
    std::uint32_t next = 0;
    for (int c = 0; c < 4; ++c) {
      colour_begin[c] = next;
      for (int by = c / 2; by < blocks_y; by += 2)
        for (int bx = c % 2; bx < blocks_x; bx += 2) rank[static_cast<std::size_t>(by) * blocks_x + bx] = next++;
    }
    colour_begin[4] = next;
    block_begin.assign(count + 1, 0);
    for (std::size_t p = 0; p < n; ++p) ++block_begin[rank[block_of[p]] + 1];
    for (std::size_t b = 0; b < count; ++b) block_begin[b + 1] += block_begin[b];
    std::vector<std::uint32_t> fill(block_begin.begin(), block_begin.end() - 1);
    order.resize(n);
    for (std::size_t p = 0; p < n; ++p) order[fill[rank[block_of[p]]]++] = static_cast<std::uint32_t>(p);
    blocks_valid = true;
  }

  /// f(p) for every particle, colour by colour, the blocks of a colour in parallel.
  template <class F>
  void scatter(F&& f) const {
    const bool parallel = n >= kParallelMinimum;
    for (int c = 0; c < 4; ++c) {
      const std::uint32_t first = colour_begin[c], last = colour_begin[c + 1];
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
      for (std::uint32_t b = first; b < last; ++b)
        for (std::uint32_t k = block_begin[b]; k < block_begin[b + 1]; ++k) f(std::size_t{order[k]});
    }
  }

  void step() {
    update_stencil();

    // 2. P2G of mass and momentum.
    std::fill(m_i.begin(), m_i.end(), 0.0);
    std::fill(px_i.begin(), px_i.end(), 0.0);
    std::fill(py_i.begin(), py_i.end(), 0.0);
    scatter([&](std::size_t p) {
      const double* wp = w.data() + 9 * p;
      const double m = mass[p], mvx = m * vx[p], mvy = m * vy[p];
      for (int k = 0; k < 9; ++k) {
        const std::uint32_t i = node_of(p, k);
        m_i[i] += wp[k] * m;
        px_i[i] += wp[k] * mvx;
        py_i[i] += wp[k] * mvy;
      }
    });

    // 3. Nodal velocity, the base fixed, the sides on rollers.
    frostmpm::parallel_for(nodes, [&](std::size_t i) {
      vx_i[i] = m_i[i] > 0 && !fixed_x[i] ? px_i[i] / m_i[i] : 0.0;
      vy_i[i] = m_i[i] > 0 && !fixed_y[i] ? py_i[i] / m_i[i] : 0.0;
    });

    // 4. Stress update at the particles (USF): L, Jaumann, Hooke, F.
    frostmpm::parallel_for(n, [&](std::size_t p) {
      const double* gp = grad.data() + 18 * p;
      double Lxx = 0, Lxy = 0, Lyx = 0, Lyy = 0;
      for (int k = 0; k < 9; ++k) {
        const std::uint32_t i = node_of(p, k);
        const double gx = gp[2 * k], gy = gp[2 * k + 1];
        Lxx += vx_i[i] * gx;
        Lxy += vx_i[i] * gy;
        Lyx += vy_i[i] * gx;
        Lyy += vy_i[i] * gy;
      }
      // Strain increment (plane strain: zz, yz, xz zero) and spin W_xy = −W_yx = ½(L_xy − L_yx).
      const double exx = Lxx * dt, eyy = Lyy * dt, exy = 0.5 * (Lxy + Lyx) * dt;
      const double spin = 0.5 * (Lxy - Lyx) * dt;
      double s[6];
      for (int c = 0; c < 6; ++c) s[c] = sigma[c][p];
      // Jaumann: σ + Δt (Wσ − σW) with W in the x–y plane.
      const double rxx = s[0] + 2.0 * spin * s[5], ryy = s[1] - 2.0 * spin * s[5];
      const double rxy = s[5] + spin * (s[1] - s[0]);
      const double ryz = s[3] - spin * s[4], rxz = s[4] + spin * s[3];
      const double volumetric = lambda * (exx + eyy);
      sigma[0][p] = rxx + volumetric + 2.0 * G * exx;
      sigma[1][p] = ryy + volumetric + 2.0 * G * eyy;
      sigma[2][p] = s[2] + volumetric;
      sigma[3][p] = ryz;
      sigma[4][p] = rxz;
      sigma[5][p] = rxy + 2.0 * G * exy;
      // F ← (I + L Δt) F.
      const double fxx = Fxx[p], fxy = Fxy[p], fyx = Fyx[p], fyy = Fyy[p];
      Fxx[p] = fxx + dt * (Lxx * fxx + Lxy * fyx);
      Fxy[p] = fxy + dt * (Lxx * fxy + Lxy * fyy);
      Fyx[p] = fyx + dt * (Lyx * fxx + Lyy * fyx);
      Fyy[p] = fyy + dt * (Lyx * fxy + Lyy * fyy);
    });

    // 5. P2G of the internal force and the weight.
    std::fill(fx_i.begin(), fx_i.end(), 0.0);
    std::fill(fy_i.begin(), fy_i.end(), 0.0);
    scatter([&](std::size_t p) {
      const double* wp = w.data() + 9 * p;
      const double* gp = grad.data() + 18 * p;
      const double Vp = V[p], sxx = Vp * sigma[0][p], syy = Vp * sigma[1][p], sxy = Vp * sigma[5][p];
      const double weight = mass[p] * kGravity;
      for (int k = 0; k < 9; ++k) {
        const std::uint32_t i = node_of(p, k);
        const double gx = gp[2 * k], gy = gp[2 * k + 1];
        fx_i[i] -= sxx * gx + sxy * gy;
        fy_i[i] += wp[k] * weight - (sxy * gx + syy * gy);
      }
    });

    // 6. Nodal update and the FLIP increment.
    frostmpm::parallel_for(nodes, [&](std::size_t i) {
      const double m = m_i[i];
      double ux = vx_i[i], uy = vy_i[i];
      if (m > grazing) {
        if (!fixed_x[i]) ux += dt * fx_i[i] / m;
        if (!fixed_y[i]) uy += dt * fy_i[i] / m;
      }
      dvx_i[i] = m > 0 ? ux - px_i[i] / m : 0.0;
      dvy_i[i] = m > 0 ? uy - py_i[i] / m : 0.0;
    });

    // 7. G2P: FLIP velocity, symplectic position.
    frostmpm::parallel_for(n, [&](std::size_t p) {
      const double* wp = w.data() + 9 * p;
      double dvx = 0, dvy = 0, ux = 0, uy = 0;
      for (int k = 0; k < 9; ++k) {
        const std::uint32_t i = node_of(p, k);
        dvx += wp[k] * dvx_i[i];
        dvy += wp[k] * dvy_i[i];
        ux += wp[k] * vx_i[i];
        uy += wp[k] * vy_i[i];
      }
      vx[p] += dvx;
      vy[p] += dvy;
      x[p] += dt * ux;
      y[p] += dt * uy;
    });
  }

  /// Uses every part of the state; thread-count independent.
  double checksum() const {
    return reproducible_sum(n, [&](std::size_t p) {
      return x[p] + 2 * y[p] + 3 * vx[p] + 5 * vy[p] + 1e-4 * (sigma[0][p] + 2 * sigma[1][p] + 3 * sigma[2][p] +
                                                             5 * sigma[5][p]) +
             Fxx[p] + Fyy[p] + 7 * Fxy[p] + 11 * Fyx[p];
    });
  }

  /// Settlement of the block's top (mean over the top particle row) [m]: shows the physics ran.
  double top_settlement() const {
    const std::size_t row = static_cast<std::size_t>(cells_x) * kPerCell;
    double s = 0;
    for (std::size_t p = n - row; p < n; ++p) s += (cells_y * h - 0.5 * h / kPerCell) - y[p];
    return s / row;
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"minimal explicit elastic MPM step (GIMP, USF, FLIP) as the reference kernel of "
               "bench/mechanical_throughput"};
  frostmpm::bench::TimingOptions o;
  frostmpm::bench::add_timing_options(cli, o);
  CLI11_PARSE(cli, argc, argv);
  if (o.threads > 0) omp_set_num_threads(o.threads);

  const int cells_y = frostmpm::bench::block_cells_y(o.particles);
  ElasticKernel kernel(3 * cells_y, cells_y, 3.0);
  const auto t = frostmpm::bench::time_steps(kernel, o);
  const double checksum = kernel.checksum();
  const int total_steps = 1 + t.repetitions * t.steps;

  if (o.json) {
    std::printf(
        "{\"particles\": %zu, \"cells\": [%d, %d], \"threads\": %d, \"steps_per_repetition\": %d, "
        "\"repetitions\": %d, \"dt\": %.6e, \"particle_steps_per_s\": %.6e, \"particle_steps_per_s_best\": %.6e, "
        "\"cpu_share\": %.3f, \"settlement\": %.6e, \"checksum\": %.17g}\n",
        kernel.n, kernel.cells_x, kernel.cells_y, thread_count(), t.steps, t.repetitions, kernel.dt, t.median, t.best,
        t.cpu_share, kernel.top_settlement(), checksum);
  } else {
    std::printf("elastic_kernel: explicit elastic MPM step (GIMP, USF, FLIP), %zu particles on %d x %d cells, "
                "dt %.4g s\n",
                kernel.n, kernel.cells_x, kernel.cells_y, kernel.dt);
    frostmpm::bench::print_timing(t, o);
    std::printf("top settlement after %d steps (%.4g s) %.4g m\n", total_steps, total_steps * kernel.dt,
                kernel.top_settlement());
    std::printf("checksum %.17g\n", checksum);
  }
  return std::isfinite(checksum) ? 0 : 1;
}
