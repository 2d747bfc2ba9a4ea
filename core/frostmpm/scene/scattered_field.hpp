#pragma once
// A field known at scattered points (another run's material points) evaluated anywhere: the
// value of a point that coincides with the query, otherwise a moving-least-squares linear fit
// over the points within 2 point spacings (4 where those are too few or in a line, beyond a
// corner of the cloud), otherwise the nearest point within 3 spacings.
//
// Why this fit: two runs on the same grid and particle layout (the usual "spin-up, then load"
// workflow) get the stored values bit for bit, a field that is linear in space is reproduced
// exactly on any layout, and the weights are compactly supported, so each query costs a few
// dozen points. The point spacing is the median nearest-neighbour distance of a sample of the
// points; the fit falls back to the nearest point where its neighbours are too few or in a line.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace frostmpm {

template <int Dim>
class ScatteredField {
 public:
  /// points: n × Dim, values: n × components (row-major), taken over. n ≥ 1.
  ScatteredField(std::vector<double> points, std::vector<double> values, int components);

  int components() const { return components_; }
  /// The spacing the fit's radius is measured in.
  double spacing() const { return spacing_; }
  /// Writes the components at x into out and returns true; false (out untouched) when no point
  /// lies within 3 spacings of x (x is outside the points' cloud).
  bool evaluate(const std::array<double, Dim>& x, std::span<double> out) const;
  /// Distance from x to the nearest point (a full scan: for error messages).
  double nearest_distance(const std::array<double, Dim>& x) const;

 private:
  int components_;
  std::size_t count_;
  std::vector<double> points_, values_;
  double spacing_ = 1, radius_ = 2;
  std::array<double, Dim> origin_{};
  std::array<long, Dim> buckets_{};
  std::vector<std::size_t> bucket_start_, bucket_points_;  ///< CSR: the points of each bucket

  void build_buckets(const std::array<double, Dim>& hi);
  double distance2(std::size_t p, const std::array<double, Dim>& x) const;
  long bucket_of(int d, double x) const;
  template <class Visit>
  void for_points_near(const std::array<double, Dim>& x, long rings, Visit&& visit) const;
};

extern template class ScatteredField<2>;
extern template class ScatteredField<3>;

}  // namespace frostmpm
