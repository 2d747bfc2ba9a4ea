#include "frostmpm/scene/scattered_field.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace frostmpm {

template <int Dim>
ScatteredField<Dim>::ScatteredField(std::vector<double> points, std::vector<double> values, int components)
    : components_(components), count_(points.size() / Dim), points_(std::move(points)), values_(std::move(values)) {
  if (count_ == 0 || points_.size() != count_ * Dim || components < 1 ||
      values_.size() != count_ * std::size_t(components))
    throw std::invalid_argument("ScatteredField: points (n × dim) and values (n × components) disagree or are empty");
  std::array<double, Dim> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t p = 0; p < count_; ++p)
    for (int d = 0; d < Dim; ++d) {
      lo[d] = std::min(lo[d], points_[p * Dim + d]);
      hi[d] = std::max(hi[d], points_[p * Dim + d]);
    }
  // A first spacing from the box: the side of the cube each point stands for, over the axes the
  // cloud spans (a single row of points spans one). The box overstates it where the material
  // leaves parts of the box empty (a slope) and understates it for a thin column (the box of
  // the centres is a spacing short), so the spacing kept is the median distance from a sample
  // of points to their nearest neighbours.
  double volume = 1;
  int spanned = 0;
  for (int d = 0; d < Dim; ++d)
    if (hi[d] > lo[d]) {
      volume *= hi[d] - lo[d];
      ++spanned;
    }
  spacing_ = spanned ? std::pow(volume / double(count_), 1.0 / spanned) : 1.0;
  if (!(spacing_ > 0) || !std::isfinite(spacing_)) spacing_ = 1.0;
  origin_ = lo;
  build_buckets(hi);
  std::vector<double> nearest;
  const std::size_t stride = std::max<std::size_t>(1, count_ / 257);
  for (std::size_t p = 0; p < count_; p += stride) {
    std::array<double, Dim> x;
    for (int d = 0; d < Dim; ++d) x[d] = points_[p * Dim + d];
    double best = std::numeric_limits<double>::infinity();
    for_points_near(x, 2, [&](std::size_t q) {
      const double r2 = distance2(q, x);
      if (q != p && r2 > 0) best = std::min(best, r2);
    });
    if (std::isfinite(best)) nearest.push_back(std::sqrt(best));
  }
  if (!nearest.empty()) {
    std::nth_element(nearest.begin(), nearest.begin() + std::ptrdiff_t(nearest.size() / 2), nearest.end());
    spacing_ = nearest[nearest.size() / 2];
    build_buckets(hi);
  }
}

template <int Dim>
void ScatteredField<Dim>::build_buckets(const std::array<double, Dim>& hi) {
  radius_ = 2.0 * spacing_;  // wide enough for a fit one-sided at the cloud's edge
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    buckets_[d] = std::max(1L, static_cast<long>(std::floor((hi[d] - origin_[d]) / radius_)) + 1);
    total *= std::size_t(buckets_[d]);
  }
  auto flat = [&](std::size_t p) {
    std::size_t b = 0;
    for (int d = Dim - 1; d >= 0; --d) b = b * std::size_t(buckets_[d]) + std::size_t(bucket_of(d, points_[p * Dim + d]));
    return b;
  };
  bucket_start_.assign(total + 1, 0);
  for (std::size_t p = 0; p < count_; ++p) ++bucket_start_[flat(p) + 1];
  for (std::size_t b = 0; b < total; ++b) bucket_start_[b + 1] += bucket_start_[b];
  bucket_points_.resize(count_);
  std::vector<std::size_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
  for (std::size_t p = 0; p < count_; ++p) bucket_points_[fill[flat(p)]++] = p;
}

template <int Dim>
double ScatteredField<Dim>::distance2(std::size_t p, const std::array<double, Dim>& x) const {
  double r2 = 0;
  for (int d = 0; d < Dim; ++d) r2 += (points_[p * Dim + d] - x[d]) * (points_[p * Dim + d] - x[d]);
  return r2;
}

template <int Dim>
long ScatteredField<Dim>::bucket_of(int d, double x) const {
  const long b = static_cast<long>(std::floor((x - origin_[d]) / radius_));
  return std::clamp(b, 0L, buckets_[d] - 1);
}

template <int Dim>
template <class Visit>
void ScatteredField<Dim>::for_points_near(const std::array<double, Dim>& x, long rings, Visit&& visit) const {
  std::array<long, Dim> from, to, b;
  for (int d = 0; d < Dim; ++d) {
    const long centre = static_cast<long>(std::floor((x[d] - origin_[d]) / radius_));
    from[d] = std::max(0L, centre - rings);
    to[d] = std::min(buckets_[d] - 1, centre + rings);
    if (from[d] > to[d]) return;  // x is far outside the cloud along d
    b[d] = from[d];
  }
  while (true) {
    std::size_t flat = 0;
    for (int d = Dim - 1; d >= 0; --d) flat = flat * std::size_t(buckets_[d]) + std::size_t(b[d]);
    for (std::size_t k = bucket_start_[flat]; k < bucket_start_[flat + 1]; ++k) visit(bucket_points_[k]);
    int d = 0;
    while (d < Dim && ++b[d] > to[d]) {
      b[d] = from[d];
      ++d;
    }
    if (d == Dim) return;
  }
}

template <int Dim>
bool ScatteredField<Dim>::evaluate(const std::array<double, Dim>& x, std::span<double> out) const {
  const int c = components_;
  constexpr int n = Dim + 1;
  const double coincide2 = 1e-18 * spacing_ * spacing_;
  std::size_t nearest = count_;
  double nearest2 = std::numeric_limits<double>::infinity();
  // The fit over the points within `rings` bucket widths; true when it was possible (or a point
  // coincides). A query beyond a corner of the cloud has too few points within one radius.
  auto fit = [&](long rings) {
    const double r = radius_ * double(rings);
    Eigen::Matrix<double, n, n> A = Eigen::Matrix<double, n, n>::Zero();
    Eigen::Matrix<double, n, Eigen::Dynamic> b = Eigen::Matrix<double, n, Eigen::Dynamic>::Zero(n, c);
    std::size_t exact = count_, used = 0;
    for_points_near(x, rings, [&](std::size_t p) {
      // Offsets in units of the radius keep the normal matrix well scaled.
      Eigen::Matrix<double, n, 1> row;
      row(0) = 1;
      for (int d = 0; d < Dim; ++d) row(d + 1) = (points_[p * Dim + d] - x[d]) / r;
      const double r2 = distance2(p, x);
      if (r2 < nearest2) {
        nearest2 = r2;
        nearest = p;
      }
      if (r2 <= coincide2 && exact == count_) exact = p;
      const double q = r2 / (r * r);
      if (q >= 1) return;
      const double w = (1 - q) * (1 - q);
      A.noalias() += w * row * row.transpose();
      for (int k = 0; k < c; ++k) b.col(k) += w * values_[p * std::size_t(c) + std::size_t(k)] * row;
      ++used;
    });
    if (exact < count_) {
      std::copy_n(values_.begin() + std::ptrdiff_t(exact * std::size_t(c)), c, out.begin());
      return true;
    }
    if (used < std::size_t(n)) return false;
    // Kept only where the normal matrix is far from singular (the points not in a line).
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, n, n>> eig(A, Eigen::EigenvaluesOnly);
    if (!(eig.eigenvalues()(0) > 1e-6 * eig.eigenvalues()(n - 1))) return false;
    const Eigen::Matrix<double, n, Eigen::Dynamic> coef = A.ldlt().solve(b);
    for (int k = 0; k < c; ++k) out[std::size_t(k)] = coef(0, k);
    return true;
  };
  if (fit(1) || fit(2)) return true;
  if (nearest == count_ || nearest2 > 9 * spacing_ * spacing_) return false;
  std::copy_n(values_.begin() + std::ptrdiff_t(nearest * std::size_t(c)), c, out.begin());
  return true;
}

template <int Dim>
double ScatteredField<Dim>::nearest_distance(const std::array<double, Dim>& x) const {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < count_; ++p) best = std::min(best, distance2(p, x));
  return std::sqrt(best);
}

template class ScatteredField<2>;
template class ScatteredField<3>;

}  // namespace frostmpm
