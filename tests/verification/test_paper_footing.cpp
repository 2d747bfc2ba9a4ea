// The strip footing on thawing ground of Yu et al. (2024, Sec. 5.3.2; configs/paper/strip_footing.yaml,
// with its cell-averaged volumetric strain and its surface conditions on the top layer of
// material points) on the coarse 0.2 m mesh, to d/B = 0.3: which ground resists most. The paper
// finds unthawed > thawing > pre-thawed (its Fig. 27). Here the resistance is read as the mean
// footing pressure over the second cell of travel, d/B = 0.2–0.3 (the footing snaps to each node
// row it crosses; docs/user-guide.md).
//
// What the runs show, asserted so that a change to any of it is seen:
//   - ground thawed beforehand (its temperature taken from the thermal run's last frame) is the
//     weakest: no ice cohesion where the mechanism runs, and no melting under the footing;
//   - with the melting source of the pore-water balance switched off, thawing ground is weaker
//     than frozen ground, in the paper's order;
//   - with it on (the paper's Eq. 7), the meltwater lacks ζ φ ΔS_l of the ice's volume: the
//     frozen ground warming under the footing closes it by compressing its skeleton (190–210 kPa
//     more effective stress at t = 0.1–0.2 s; at 0.1 s its volume change is 95 % of a sealed soil's,
//     the volume balance configs/verification/undrained_warming.yaml verifies), and the thawed layer beside
//     it draws it in through itself under −0.1 to −0.2 MPa (Darcy's estimate −0.4 MPa at the
//     front); the effective stress and the frictional strength (φ′ = 30°) rise above those of the
//     undrained frozen ground (to d/B = 1 in the full run). docs/verification.md compares with
//     the paper's code (both read the mixture's force and leave the ice's strength unsoftened;
//     its tension cut-off, its k_r floor and its drained free surface were tried, none gives its
//     order).
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "scene_runs.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

/// The mean footing pressure over d/B ∈ [0.2, 0.3].
double resistance(const CsvTable& t) {
  const auto d = t.column("footing_displacement"), q = t.column("footing_pressure");
  double sum = 0;
  int n = 0;
  for (const auto& row : t.rows)
    if (row[d] / 1.2 >= 0.2 && row[d] / 1.2 <= 0.3) {
      sum += row[q];
      ++n;
    }
  REQUIRE(n >= 10);
  return sum / n;
}

}  // namespace

TEST_CASE("strip footing on frozen, thawing and thawed ground: the order of their resistance",
          "[verification][paper][footing]") {
  TempDir dir;
  const std::string paper = source_dir() + "/configs/paper/";
  run_scene(dir, paper + "strip_footing_thermal.yaml", {}, "thermal");
  const std::vector<std::string> coarse = {"grid.cells=[45,33]", "grid.cell_size=0.2", "time.end=0.41",
                                           "output.every=0"};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), coarse.begin(), coarse.end());
    return extra;
  };
  const double unthawed = resistance(run_scene(dir, paper + "strip_footing.yaml", with({"boundary_conditions.3.value=-5.0"}), "unthawed"));
  const double thawing = resistance(run_scene(dir, paper + "strip_footing.yaml", with({}), "thawing"));
  const double no_melt_suction = resistance(run_scene(
      dir, paper + "strip_footing.yaml", with({"physics.hydraulic.phase_change_source=false"}), "no_melt_suction"));
  const double thawed = resistance(run_scene(
      dir, paper + "strip_footing.yaml",
      with({"regions.0.initial.temperature={from: " + dir.file("thermal") + "}"}), "thawed"));
  WARN("footing pressure at d/B = 0.2-0.3 [kPa]: unthawed " << unthawed / 1e3 << ", thawing " << thawing / 1e3
                                                             << ", thawing without melt suction "
                                                             << no_melt_suction / 1e3 << ", pre-thawed " << thawed / 1e3);
  CHECK(thawed < no_melt_suction);
  CHECK(no_melt_suction < unthawed);
  CHECK(unthawed < thawing);
  // The margins: each at least 15 % apart, frozen and thawing ground at least 10 % (they read
  // 1.94 and 2.32 MPa).
  CHECK(thawed < 0.85 * no_melt_suction);
  CHECK(no_melt_suction < 0.85 * unthawed);
  CHECK(unthawed < 0.90 * thawing);
}
