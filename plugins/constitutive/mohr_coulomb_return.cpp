#include "mohr_coulomb_return.hpp"

#include "frostmpm/models/tensor3.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cmath>
#include <vector>

namespace frostmpm::mohr_coulomb {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A yield plane n·σ ≤ k in principal stresses, with the flow direction g of its potential.
struct Plane {
  Vec3 n, g;
  double k = 0;
  double dilatancy = 0;  ///< tr g, exactly 2 sin ψ (0 for ψ = 0, so isochoric flow stays so to the bit)
};

/// The planes of the sextant σ1 ≥ σ2 ≥ σ3: 0 the main Mohr–Coulomb plane, 1 and 2 the planes
/// that meet it at the edges σ1 = σ2 and σ2 = σ3, 3–5 the cut-offs σ_i ≤ σ_t (when it acts).
struct Planes {
  std::array<Plane, 6> plane;
  int count = 3;
};

Planes planes_of(const Strength& s) {
  const double sf = s.sin_friction, sp = s.sin_dilation, k = 2 * s.cohesion * s.cos_friction;
  Planes P;
  P.plane[0] = {Vec3(1 + sf, 0, -(1 - sf)), Vec3(1 + sp, 0, -(1 - sp)), k, 2 * sp};
  P.plane[1] = {Vec3(0, 1 + sf, -(1 - sf)), Vec3(0, 1 + sp, -(1 - sp)), k, 2 * sp};
  P.plane[2] = {Vec3(1 + sf, -(1 - sf), 0), Vec3(1 + sp, -(1 - sp), 0), k, 2 * sp};
  const double T = s.tension_cutoff();
  if (T < s.apex()) {
    for (int i = 0; i < 3; ++i) P.plane[3 + i] = {Vec3::Unit(i), Vec3::Unit(i), T, 1.0};
    P.count = 6;
  }
  return P;
}

Mat3 principal_elasticity(const Elasticity& e) { return Mat3::Constant(e.lambda()) + 2.0 * e.G * Mat3::Identity(); }

struct ActiveSet {
  std::array<int, 3> planes;
  int size;
  ReturnKind kind;
};
// The cone is tried first: its main plane, then its two edges.
constexpr ActiveSet kCone[] = {
    {{0, 0, 0}, 1, ReturnKind::plane}, {{0, 1, 0}, 2, ReturnKind::edge}, {{0, 2, 0}, 2, ReturnKind::edge}};

/// With a cut-off below the apex: every set of one to three planes that holds a cut-off plane,
/// smallest first (the corners where the cut-off meets the cone's edges need three planes).
/// 34 sets, tried only for the rare trial stress the cone alone cannot return.
std::vector<ActiveSet> tension_sets() {
  constexpr unsigned kCutOffPlanes = 0b111000, kConePlanes = 0b000111;
  std::vector<ActiveSet> sets;
  for (int size = 1; size <= 3; ++size)
    for (unsigned mask = 1; mask < 64; ++mask) {
      if (std::popcount(mask) != size || !(mask & kCutOffPlanes)) continue;
      ActiveSet set{{0, 0, 0}, size, mask & kConePlanes ? ReturnKind::cone_and_tension : ReturnKind::tension};
      std::size_t k = 0;
      for (int i = 0; i < 6; ++i)
        if (mask >> i & 1u) set.planes[k++] = i;
      sets.push_back(set);
    }
  return sets;
}
const std::vector<ActiveSet> kTension = tension_sets();

/// σ = σ_tr − Σ Δγ_j D g_j with F_i(σ) = 0 on the set: accepted when every Δγ ≥ 0 and every
/// plane is ≤ 0 (which also keeps the order of the principal stresses). A = dσ/dσ_tr; the
/// plastic strain is Σ Δγ_j g_j, exact where the flow rule is (no volume change for ψ = 0).
bool try_set(const ActiveSet& set, const Planes& P, const Mat3& D, const Vec3& trial, double tol_f, double tol_g,
             Vec3& sigma, Mat3& A, Vec3& plastic, double& volumetric) {
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
  using Columns = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
  const int m = set.size;
  Columns DG(3, m), N(3, m);
  Vector r(m);
  for (int j = 0; j < m; ++j) {
    const Plane& plane = P.plane[std::size_t(set.planes[std::size_t(j)])];
    DG.col(j) = D * plane.g;
    N.col(j) = plane.n;
    r(j) = plane.n.dot(trial) - plane.k;
  }
  const Small J = N.transpose() * DG;
  const Eigen::FullPivLU<Small> lu(J);
  if (!lu.isInvertible()) return false;
  const Vector gamma = lu.solve(r);
  if ((gamma.array() < -tol_g).any()) return false;
  plastic.setZero();
  volumetric = 0;
  for (int j = 0; j < m; ++j) {
    const Plane& plane = P.plane[std::size_t(set.planes[std::size_t(j)])];
    plastic += gamma(j) * plane.g;
    volumetric += gamma(j) * plane.dilatancy;
  }
  sigma = trial - DG * gamma;
  for (int i = 0; i < P.count; ++i)
    if (P.plane[std::size_t(i)].n.dot(sigma) - P.plane[std::size_t(i)].k > tol_f) return false;
  A = Mat3::Identity() - DG * lu.inverse() * N.transpose();
  return true;
}

/// The return of ordered principal trial stresses; C = dσ/dε in principal values, `plastic` the
/// principal plastic strain increment.
ReturnKind return_principal(const Vec3& trial, const Strength& s, const Elasticity& e, double scale, Vec3& sigma,
                            Mat3& C, Vec3& plastic, double& volumetric) {
  const Planes P = planes_of(s);
  const Mat3 D = principal_elasticity(e);
  const double tol_f = 1e-10 * scale, tol_g = 1e-10 * scale / e.G;
  Mat3 A;
  for (const auto& set : kCone)
    if (try_set(set, P, D, trial, tol_f, tol_g, sigma, A, plastic, volumetric)) {
      C = A * D;
      return set.kind;
    }
  if (P.count == 6) {
    for (const auto& set : kTension)
      if (try_set(set, P, D, trial, tol_f, tol_g, sigma, A, plastic, volumetric)) {
        C = A * D;
        return set.kind;
      }
    return ReturnKind::failed;
  }
  // The apex: hydrostatic at c cot φ, whatever the trial's deviator (perfectly plastic).
  const double apex = s.apex();
  if (!std::isfinite(apex)) return ReturnKind::failed;
  sigma = Vec3::Constant(apex);
  C.setZero();
  // Δε^p = C_e (σ_tr − σ): the deviatoric drop over 2G, the mean drop over K (in the trace).
  const Vec3 drop = trial - sigma;
  plastic = (drop.array() - drop.mean()).matrix() / (2 * e.G) + Vec3::Constant(drop.mean() / (3 * e.K));
  volumetric = drop.mean() / e.K;
  return ReturnKind::apex;
}

Mat3 to_matrix(const double* v) {
  Mat3 m;
  m << v[0], v[5], v[4], v[5], v[1], v[3], v[4], v[3], v[2];
  return m;
}

void to_voigt(const Mat3& m, double* v) {
  v[0] = m(0, 0);
  v[1] = m(1, 1);
  v[2] = m(2, 2);
  v[3] = 0.5 * (m(1, 2) + m(2, 1));
  v[4] = 0.5 * (m(0, 2) + m(2, 0));
  v[5] = 0.5 * (m(0, 1) + m(1, 0));
}

void elastic_tangent(const Elasticity& e, double* D) { tensor3::isotropic_tangent(e.lambda(), e.G, D); }

}  // namespace

Strength Strength::make(double cohesion, double friction, double dilation, double tension) {
  return {cohesion, friction, dilation, tension, std::sin(friction), std::cos(friction), std::sin(dilation)};
}

double Strength::apex() const { return friction > 0 ? cohesion * cos_friction / sin_friction : kInf; }

double Strength::tension_cutoff() const { return std::min(tension, apex()); }

double yield_value(std::array<double, 3> p, const Strength& s) {
  std::sort(p.begin(), p.end(), std::greater<>());
  const double sf = s.sin_friction;
  const double cone = p[0] * (1 + sf) - p[2] * (1 - sf) - 2 * s.cohesion * s.cos_friction;
  const double T = s.tension_cutoff();
  return std::isfinite(T) ? std::max(cone, p[0] - T) : cone;
}

double yield_value_of_stress(const double* stress, const Strength& s) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(to_matrix(stress), Eigen::EigenvaluesOnly);
  const Vec3 v = eigen.eigenvalues();
  return yield_value({v(0), v(1), v(2)}, s);
}

ReturnResult return_stress(const double* trial, const Strength& s, const Elasticity& e, double* stress,
                           double* tangent) {
  ReturnResult result;
  // Most points are elastic: the closed-form eigenvalues (no vectors) settle those clearly inside
  // the surface; a point near it gets the iterative decomposition, accurate to round-off, so a
  // stress returned onto the surface reads as on it again.
  const Mat3 S = to_matrix(trial);
  Eigen::SelfAdjointEigenSolver<Mat3> quick;
  quick.computeDirect(S, Eigen::EigenvaluesOnly);
  const Vec3 rough = quick.eigenvalues();
  const double rough_scale = std::max({rough.cwiseAbs().maxCoeff(), s.cohesion, 1.0});
  if (yield_value({rough(0), rough(1), rough(2)}, s) < -1e-6 * rough_scale) {
    std::copy(trial, trial + 6, stress);
    if (tangent) elastic_tangent(e, tangent);
    return result;
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(S);
  // Descending: σ1 (the least compressive) first.
  const Vec3 principal(eigen.eigenvalues()(2), eigen.eigenvalues()(1), eigen.eigenvalues()(0));
  Mat3 Q;
  Q << eigen.eigenvectors().col(2), eigen.eigenvectors().col(1), eigen.eigenvectors().col(0);
  const double scale = std::max({principal.cwiseAbs().maxCoeff(), s.cohesion, 1.0});
  if (yield_value({principal(0), principal(1), principal(2)}, s) <= 1e-10 * scale) {
    std::copy(trial, trial + 6, stress);
    if (tangent) elastic_tangent(e, tangent);
    return result;
  }
  Vec3 sigma, plastic;
  Mat3 C;
  double volumetric = 0;
  result.kind = return_principal(principal, s, e, scale, sigma, C, plastic, volumetric);
  if (result.kind == ReturnKind::failed) {
    std::copy(trial, trial + 6, stress);
    if (tangent) elastic_tangent(e, tangent);
    return result;
  }
  // Only the change goes through the eigenvectors, so a point barely past the surface keeps
  // its stress to round-off.
  const Vec3 drop = principal - sigma;
  Mat3 change = Mat3::Zero();
  for (int a = 0; a < 3; ++a) change += drop(a) * Q.col(a) * Q.col(a).transpose();
  to_voigt(S - change, stress);
  if (result.kind == ReturnKind::apex)  // exactly hydrostatic, in every frame
    for (int k = 0; k < 6; ++k) stress[k] = k < 3 ? sigma(0) : 0.0;
  const Vec3 deviatoric = (plastic.array() - plastic.mean()).matrix();
  result.plastic_deviatoric = std::sqrt(2.0 / 3.0 * deviatoric.squaredNorm());
  result.plastic_volumetric = volumetric;
  if (!tangent) return result;
  // dσ/dε of an isotropic function of the trial strain: normal components through C, the
  // shear ones in the eigenframe through (σ_a − σ_b)/(ε_a − ε_b) (its limit C_aa − C_ab at
  // equal trial eigenvalues). Column j is the response to a unit tensor strain component j.
  double theta[3][3] = {};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      if (a == b) continue;
      const double gap = principal(a) - principal(b);
      theta[a][b] = std::abs(gap) > 1e-12 * scale ? 2 * e.G * (sigma(a) - sigma(b)) / gap
                                                  : 0.5 * (C(a, a) - C(a, b) + C(b, b) - C(b, a));
    }
  constexpr int kPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  for (int j = 0; j < 6; ++j) {
    Mat3 unit = Mat3::Zero();
    unit(kPair[j][0], kPair[j][1]) = unit(kPair[j][1], kPair[j][0]) = 1;
    const Mat3 local = Q.transpose() * unit * Q;
    Mat3 response;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        response(a, b) = a == b ? C(a, 0) * local(0, 0) + C(a, 1) * local(1, 1) + C(a, 2) * local(2, 2)
                                : theta[a][b] * local(a, b);
    double column[6];
    to_voigt(Q * response * Q.transpose(), column);
    for (int i = 0; i < 6; ++i) tangent[6 * i + j] = column[i];
  }
  return result;
}

}  // namespace frostmpm::mohr_coulomb
