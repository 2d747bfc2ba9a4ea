#pragma once
// Small 3×3 tensor helpers for the stress update: symmetric tensors as 6 values in Voigt order
// (xx, yy, zz, yz, xz, xy; tensor shear components), full tensors row-major.
#include <array>
#include <cmath>

namespace frostmpm::tensor3 {

using Sym = std::array<double, 6>;
using Mat = std::array<std::array<double, 3>, 3>;

constexpr int kVoigt[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};

inline Mat to_matrix(const double* s) {
  Mat m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = s[kVoigt[i][j]];
  return m;
}

inline void from_matrix(const Mat& m, double* s) {
  s[0] = m[0][0];
  s[1] = m[1][1];
  s[2] = m[2][2];
  s[3] = 0.5 * (m[1][2] + m[2][1]);
  s[4] = 0.5 * (m[0][2] + m[2][0]);
  s[5] = 0.5 * (m[0][1] + m[1][0]);
}

inline double trace(const double* s) { return s[0] + s[1] + s[2]; }

/// The objective (Jaumann) rotation of a stress over a step: σ + Δt (W σ − σ W) with the spin
/// W = ½(∇v − ∇vᵀ), (∇v)_ij = ∂v_i/∂x_j. For a counter-clockwise spin it turns σ
/// counter-clockwise (σ̇ = Wσ − σW is the rate of R σ Rᵀ with Ṙ = W R).
inline void jaumann_rotate(const Mat& W, double dt, double* s) {
  const Mat S = to_matrix(s);
  Mat out = S;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double ws = 0, sw = 0;
      for (int k = 0; k < 3; ++k) {
        ws += W[i][k] * S[k][j];
        sw += S[i][k] * W[k][j];
      }
      out[i][j] += dt * (ws - sw);
    }
  from_matrix(out, s);
}

/// Isotropic Hooke in rate form: out = start + λ tr(Δε) I + 2G Δε (tensor shear strains).
inline void add_isotropic_increment(double lambda, double G, const double* strain_increment, const double* start,
                                    double* out) {
  const double volumetric = lambda * (strain_increment[0] + strain_increment[1] + strain_increment[2]);
  for (int i = 0; i < 3; ++i) out[i] = start[i] + volumetric + 2.0 * G * strain_increment[i];
  for (int i = 3; i < 6; ++i) out[i] = start[i] + 2.0 * G * strain_increment[i];
}

/// Its tangent, 6 × 6 row-major: λ on the normal block, plus 2G on the diagonal.
inline void isotropic_tangent(double lambda, double G, double* D) {
  for (int k = 0; k < 36; ++k) D[k] = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) D[6 * i + j] = lambda;
  for (int i = 0; i < 6; ++i) D[6 * i + i] += 2.0 * G;
}

/// Mean stress p = tr σ / 3 and the von Mises equivalent q = √(3 J2).
inline double mean(const double* s) { return trace(s) / 3.0; }
inline double von_mises(const double* s) {
  const double p = mean(s);
  const double dx = s[0] - p, dy = s[1] - p, dz = s[2] - p;
  const double J2 = 0.5 * (dx * dx + dy * dy + dz * dz) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
  return std::sqrt(3.0 * J2);
}

}  // namespace frostmpm::tensor3
