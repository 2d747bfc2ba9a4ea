#pragma once
// The heat content of a grid node as a function of its temperature:
//     H_i(T) = a_i T + Σ_m b_im G_m(T)                                        [J/m³]
// with a_i = Σ_p V_p S_ip (1 − φ_p) C_s / V_i and b_im = Σ_{p of material m} V_p S_ip φ_p / V_i:
// the volume-weighted mixture of the enthalpy curves of the particles the node sees. A node
// of one material (almost all of them) inverts in closed form through that material's table;
// a node where materials meet uses a bracketed Newton iteration. Every lookup keeps a hint per
// node and material, written only by the thread that owns the node.
#include <algorithm>
#include <cmath>
#include <vector>

#include "enthalpy_table.hpp"

namespace frostmpm::thermal {

class NodalHeat {
 public:
  static constexpr int kMixed = -1, kEmpty = -2;

  void configure(std::vector<const EnthalpyTable*> tables, std::size_t nodes) {
    tables_ = std::move(tables);
    sensible.assign(nodes, 0.0);
    pore.assign(tables_.size(), std::vector<double>(nodes, 0.0));
    material.assign(nodes, kEmpty);
    hint.assign(tables_.size(), std::vector<int>(nodes, 0));
    for (std::size_t m = 0; m < tables_.size(); ++m)
      std::fill(hint[m].begin(), hint[m].end(), tables_[m]->freezing_interval());
  }

  /// After a_i and b_im are filled: which material(s) each node holds.
  void classify(std::size_t i) {
    int found = kEmpty;
    for (std::size_t m = 0; m < pore.size(); ++m)
      if (pore[m][i] > 0) found = found == kEmpty ? static_cast<int>(m) : kMixed;
    if (found == kEmpty && sensible[i] > 0) found = 0;  // porosity 0: sensible heat only
    material[i] = found;
  }

  double pore_heat(std::size_t m, std::size_t i, double T) {
    int& h = hint[m][i];
    h = tables_[m]->locate(T, h);
    return tables_[m]->pore_heat(T, h);
  }

  double heat(std::size_t i, double T) {
    double H = sensible[i] * T;
    for (std::size_t m = 0; m < pore.size(); ++m)
      if (pore[m][i] > 0) H += pore[m][i] * pore_heat(m, i, T);
    return H;
  }

  /// H_i'(T): the apparent (sensible + latent) capacity.
  double capacity(std::size_t i, double T) {
    double c = sensible[i];
    for (std::size_t m = 0; m < pore.size(); ++m)
      if (pore[m][i] > 0) {
        int& h = hint[m][i];
        h = tables_[m]->locate(T, h);
        c += pore[m][i] * tables_[m]->pore_capacity(T, h);
      }
    return c;
  }

  /// Lower bound of H_i' (no latent heat, the smaller pore-filling capacity).
  double min_capacity(std::size_t i) const {
    double c = sensible[i];
    for (std::size_t m = 0; m < pore.size(); ++m) c += pore[m][i] * tables_[m]->min_pore_capacity();
    return c;
  }

  /// The T with H_i(T) = H; `guess` starts the mixed-node iteration.
  double invert(std::size_t i, double H, double guess) {
    const int m = material[i];
    if (m >= 0) return tables_[m]->invert(sensible[i], pore[m][i], H, hint[m][i]);
    // Mixed node: Newton inside a bracket that H' ≥ c_min guarantees.
    const double c_min = min_capacity(i);
    double T = guess, f = heat(i, T) - H;
    double lo = f < 0 ? T : T - f / c_min, hi = f < 0 ? T - f / c_min : T;
    for (int it = 0; it < 200 && f != 0 && hi - lo > 1e-14 * (1 + std::abs(T)); ++it) {
      (f < 0 ? lo : hi) = T;
      const double next = T - f / capacity(i, T);
      T = next > lo && next < hi ? next : 0.5 * (lo + hi);
      f = heat(i, T) - H;
    }
    return T;
  }

  std::vector<double> sensible;            ///< a_i
  std::vector<std::vector<double>> pore;   ///< b_im, one array per material
  std::vector<int> material;               ///< the node's only material, kMixed or kEmpty
  std::vector<std::vector<int>> hint;      ///< table interval hints, per material and node

 private:
  std::vector<const EnthalpyTable*> tables_;
};

}  // namespace frostmpm::thermal
