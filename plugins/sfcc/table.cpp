// Tabulated SFCC: a measured freezing curve, points (T_i, S_l,i) given inline or read from a
// CSV file, interpolated by monotone piecewise-cubic Hermite polynomials (Fritsch & Carlson 1980,
// with the end slopes of Moler's pchip, as SciPy's PchipInterpolator). Between two points the
// curve stays within their values — no overshoot above 1 or below the residual, no spurious ice
// growth on warming — and dS_l/dT is the cubic's own derivative, so the Newton and energy
// terms see the curve they integrate. Below the first point S_l keeps its first value, and at
// and above the first point with S_l = 1 the soil is thawed.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/plugin/plugin_api.hpp"

namespace frostmpm {

namespace {

/// "T, S_l" rows of a CSV file; a first line that is not numbers is a header, '#' a comment.
void read_table_file(const ParamSet& p, std::vector<double>& T, std::vector<double>& S) {
  const std::string& name = p.string("file");
  std::filesystem::path path(name);
  // A relative path is relative to the scene file that names it (not to the working folder).
  const std::string& scene = p.where("file").file;
  if (path.is_relative() && !scene.empty() && scene != "--set" && std::filesystem::exists(scene))
    path = std::filesystem::path(scene).parent_path() / path;
  std::ifstream in(path);
  if (!in) throw p.error("file", "cannot read the freezing-curve table '" + path.string() + "'");
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::replace(line.begin(), line.end(), ';', ' ');
    std::istringstream row(line);
    double t = 0, s = 0;
    std::string rest;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (!(row >> t >> s)) {
      if (T.empty() && number == 1) continue;  // header
      throw p.error("file", path.string() + ":" + std::to_string(number) +
                                ": expected two numbers 'temperature, liquid_saturation', got '" + line + "'");
    }
    if (row >> rest)
      throw p.error("file", path.string() + ":" + std::to_string(number) + ": more than two columns in '" + line + "'");
    T.push_back(t);
    S.push_back(s);
  }
}

/// One-sided end slope of the three-point formula, kept monotone (Moler, Numerical Computing
/// with MATLAB, pchip): zero if it points against the data, at most 3× the secant where the
/// secants change sign.
double end_slope(double h0, double h1, double delta0, double delta1) {
  const double d = ((2 * h0 + h1) * delta0 - h0 * delta1) / (h0 + h1);
  if (d * delta0 <= 0) return 0.0;
  if (delta0 * delta1 < 0 && std::abs(d) > 3 * std::abs(delta0)) return 3 * delta0;
  return d;
}

}  // namespace

class TableSfcc final : public SfccModel {
 public:
  static constexpr const char* kName = "table";
  static constexpr const char* kDoc =
      "measured freezing curve: points (T, S_l) inline or from a CSV file, monotone cubic (PCHIP) between them";

  static ParamSchema schema() {
    ParamSchema s;
    s.reals("temperatures", "degC", "table temperatures, increasing (with saturations; or give file)")
        .defaults_to(std::vector<double>{});
    s.reals("saturations", "-",
            "liquid saturation at each temperature, non-decreasing, in [0, 1], the last 1 (thawed)")
        .defaults_to(std::vector<double>{});
    s.string("file", "CSV file of 'temperature, liquid_saturation' rows (header optional), relative to the scene")
        .defaults_to("");
    return s;
  }

  explicit TableSfcc(const ParamSet& p) : T_(p.reals("temperatures")), S_(p.reals("saturations")) {
    const bool inline_table = !T_.empty() || !S_.empty();
    const bool from_file = !p.string("file").empty();
    if (inline_table == from_file)
      throw p.section_error("give the table either inline (temperatures: [...], saturations: [...]) or as file: "
                            "NAME.csv, not " + std::string(from_file ? "both" : "neither"));
    const std::string where = from_file ? "file" : "saturations";
    if (from_file) read_table_file(p, T_, S_);
    if (T_.size() != S_.size())
      throw p.error(where, std::to_string(T_.size()) + " temperatures but " + std::to_string(S_.size()) +
                               " saturations: give one saturation per temperature");
    if (T_.size() < 2) throw p.error(where, "a freezing-curve table needs at least 2 points");
    for (std::size_t i = 0; i < T_.size(); ++i) {
      const std::string point = "point " + std::to_string(i + 1) + " (T = " + number_text(T_[i]) + ")";
      if (!std::isfinite(T_[i]) || T_[i] < -273.15 || T_[i] > 100)
        throw p.error(from_file ? "file" : "temperatures", point + ": temperature outside [-273.15, 100] degC");
      if (i > 0 && !(T_[i] > T_[i - 1]))
        throw p.error(from_file ? "file" : "temperatures", point + ": temperatures must increase strictly");
      if (!std::isfinite(S_[i]) || S_[i] < 0 || S_[i] > 1)
        throw p.error(where, point + ": liquid saturation " + number_text(S_[i]) + " outside [0, 1]");
      if (i > 0 && S_[i] < S_[i - 1])
        throw p.error(where, point + ": liquid saturation decreases on warming (" + number_text(S_[i - 1]) +
                                 " then " + number_text(S_[i]) + "); a freezing curve is non-decreasing in T");
    }
    if (S_.back() != 1.0)
      throw p.error(where, "the last point has S_l = " + number_text(S_.back()) +
                               "; the table must reach 1 (thawed) so the freezing point is defined");
    // Points past the first S_l = 1 add nothing: the soil is thawed there.
    const auto thawed = std::find(S_.begin(), S_.end(), 1.0) - S_.begin();
    T_.resize(static_cast<std::size_t>(thawed) + 1);
    S_.resize(T_.size());
    slopes_ = pchip_slopes(T_, S_);
  }

  void evaluate(std::span<const double> T, std::span<const double>, const SfccResult& out) const override {
    const std::size_t last = T_.size() - 1;
    for (std::size_t i = 0; i < T.size(); ++i) {
      out.dS_l_dp[i] = 0.0;
      const double t = T[i];
      if (t >= T_[last]) {
        out.S_l[i] = 1.0;
        out.dS_l_dT[i] = 0.0;
        continue;
      }
      if (t <= T_[0]) {
        out.S_l[i] = S_[0];
        out.dS_l_dT[i] = 0.0;
        continue;
      }
      const std::size_t k = static_cast<std::size_t>(std::upper_bound(T_.begin(), T_.end(), t) - T_.begin()) - 1;
      const double h = T_[k + 1] - T_[k], x = (t - T_[k]) / h;
      // Cubic Hermite basis on [0, 1] and its derivative.
      const double h10 = x * (1 - x) * (1 - x);
      const double h01 = x * x * (3 - 2 * x), h11 = x * x * (x - 1);
      const double d00 = 6 * x * (x - 1), d10 = (1 - x) * (1 - 3 * x), d01 = -d00, d11 = x * (3 * x - 2);
      // h00 = 1 − h01: a flat stretch of the table then gives its value exactly, and the clamp
      // keeps round-off from stepping outside the two points (PCHIP itself never does).
      const double S = S_[k] + (S_[k + 1] - S_[k]) * h01 + h * (h10 * slopes_[k] + h11 * slopes_[k + 1]);
      out.S_l[i] = std::clamp(S, S_[k], S_[k + 1]);
      out.dS_l_dT[i] = (d00 * S_[k] + d01 * S_[k + 1]) / h + d10 * slopes_[k] + d11 * slopes_[k + 1];
    }
  }

  double freezing_point() const override { return T_.back(); }

 private:
  /// Fritsch–Carlson slopes: zero at a local extremum or flat secant, else the weighted
  /// harmonic mean of the neighbouring secants (which keeps each cubic monotone).
  static std::vector<double> pchip_slopes(const std::vector<double>& x, const std::vector<double>& y) {
    const std::size_t n = x.size();
    std::vector<double> h(n - 1), delta(n - 1), d(n, 0.0);
    for (std::size_t k = 0; k + 1 < n; ++k) {
      h[k] = x[k + 1] - x[k];
      delta[k] = (y[k + 1] - y[k]) / h[k];
    }
    if (n == 2) return {delta[0], delta[0]};
    for (std::size_t k = 1; k + 1 < n; ++k) {
      if (delta[k - 1] * delta[k] <= 0) continue;
      const double w1 = 2 * h[k] + h[k - 1], w2 = h[k] + 2 * h[k - 1];
      d[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
    }
    d[0] = end_slope(h[0], h[1], delta[0], delta[1]);
    d[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
    return d;
  }

  std::vector<double> T_, S_, slopes_;
};

FROSTMPM_REGISTER(SfccModel, TableSfcc)

}  // namespace frostmpm
