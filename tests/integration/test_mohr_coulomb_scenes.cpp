// Mohr–Coulomb in a scene: the self-weight column of configs/verification with the model
// swapped. A strength it never reaches gives the elastic column; a cohesionless soil at
// φ = 20° cannot hold the elastic K0 = ν/(1 − ν) = 0.4286 below Rankine's active ratio
// K_a = (1 − sin φ)/(1 + sin φ) = 0.4903, so every particle's σ_xx/σ_yy ends at or above K_a
// (elastic: 0.4286, below it), with its plastic strain, yielded flag and strength in fields.h5.
// mohr_coulomb_ice reads λ from the material's freezing curve; a plastic material left at the
// default volumetric strain is warned of locking.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "frostmpm/io/hdf5_support.hpp"
#include "test_support.hpp"

using namespace frostmpm::test;

namespace {

const std::string kColumn = source_dir() + "/configs/verification/self_weight_column.yaml";

/// A field of the last frame of OUT/fields.h5, n × components.
std::vector<double> last_frame(const std::string& out, const std::string& field) {
  namespace h5 = frostmpm::hdf5;
  const auto file = h5::open_file(out + "/fields.h5", false);
  auto names = h5::child_names(file.get());
  const auto group = h5::open_group(file.get(), names.back());
  const auto shape = h5::dataset_shape(group.get(), field);
  std::vector<double> values(shape.front() * (shape.size() > 1 ? shape[1] : 1));
  h5::read_reals(group.get(), field, values);
  return values;
}

}  // namespace

TEST_CASE("Mohr-Coulomb column: never yielding is the elastic column, cohesionless soil holds Rankine's K_a",
          "[mohr_coulomb]") {
  TempDir dir;
  const std::string fields = " --set 'output.fields=[stress, plastic_deviatoric_strain, yielded, cohesion, friction_angle]'";
  const auto elastic = run_frostmpm("run " + kColumn + " -o " + dir.file("elastic") + " --set 'output.fields=[stress]'");
  INFO(elastic.output);
  REQUIRE(elastic.exit_code == 0);
  // A strength far beyond the 20 kPa the column reaches: the same settlement as linear_elastic.
  const auto strong = run_frostmpm("run " + kColumn + " -o " + dir.file("strong") + fields +
                                   " --set 'materials.soil.mechanical_model={model: mohr_coulomb, youngs_modulus: "
                                   "1.0e6, poisson_ratio: 0.3, cohesion: 1.0e7, friction_angle: 30}'");
  INFO(strong.output);
  REQUIRE(strong.exit_code == 0);
  const auto a = read_csv(dir.file("elastic") + "/metrics.csv"), b = read_csv(dir.file("strong") + "/metrics.csv");
  const std::size_t s = a.column("settlement");
  REQUIRE(a.rows.size() == b.rows.size());
  for (std::size_t k = 0; k < a.rows.size(); ++k) CHECK(b.rows[k][s] == Approx(a.rows[k][s]).epsilon(1e-9).margin(1e-15));
  for (double y : last_frame(dir.file("strong"), "yielded")) CHECK(y == 0);

  const auto sand = run_frostmpm("run " + kColumn + " -o " + dir.file("sand") + fields +
                                 " --set 'materials.soil.mechanical_model={model: mohr_coulomb, youngs_modulus: 1.0e6, "
                                 "poisson_ratio: 0.3, cohesion: 0, friction_angle: 20}'");
  INFO(sand.output);
  REQUIRE(sand.exit_code == 0);
  const double K_a = (1 - std::sin(20 * M_PI / 180)) / (1 + std::sin(20 * M_PI / 180));
  REQUIRE(K_a == Approx(0.4902906).epsilon(1e-6));
  const auto elastic_stress = last_frame(dir.file("elastic"), "stress");
  const auto sand_stress = last_frame(dir.file("sand"), "stress");
  const auto plastic = last_frame(dir.file("sand"), "plastic_deviatoric_strain");
  const auto friction = last_frame(dir.file("sand"), "friction_angle");
  REQUIRE(sand_stress.size() == 6 * plastic.size());
  double yielded_somewhere = 0;
  for (std::size_t p = 0; p < plastic.size(); ++p) {
    const double sv = sand_stress[6 * p + 1], ev = elastic_stress[6 * p + 1];
    if (sv > -1000) continue;  // the top few particles: ratios of near-zero stresses
    INFO("particle " << p);
    CHECK(elastic_stress[6 * p] / ev == Approx(0.3 / 0.7).epsilon(0.02));  // K0 = ν/(1 − ν), below K_a
    CHECK(sand_stress[6 * p] / sv >= K_a - 1e-9);
    CHECK(friction[p] == 20);
    yielded_somewhere = std::max(yielded_somewhere, plastic[p]);
  }
  CHECK(yielded_somewhere > 1e-4);  // it got there by plastic flow
}

TEST_CASE("mohr_coulomb_ice reads lambda from the material's freezing curve", "[mohr_coulomb]") {
  const std::string model =
      " --set 'materials.rock.mechanical_model={model: mohr_coulomb_ice, youngs_modulus: 1.0e9, poisson_ratio: 0.25, "
      "cohesion: 1.0e6, friction_angle: 35, max_ice_cohesion: 2.0e6, ice_bonding_rate: 0.05";
  const auto r = run_frostmpm("check " + source_dir() + "/configs/paper/rock_freezing.yaml" + model + "}'");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  // The resolved mechanical_model section carries the sfcc's λ = 0.5.
  const auto at = r.output.find("model: mohr_coulomb_ice");
  REQUIRE(at != std::string::npos);
  CHECK(r.output.find("lambda: 0.5", at) != std::string::npos);
  // The same value given twice is fine; another value is refused naming both places.
  CHECK(run_frostmpm("check " + source_dir() + "/configs/paper/rock_freezing.yaml" + model + ", lambda: 0.5}'")
            .exit_code == 0);
  const auto clash = run_frostmpm("check " + source_dir() + "/configs/paper/rock_freezing.yaml" + model + ", lambda: 0.4}'");
  CHECK(clash.exit_code == 2);
  CHECK(clash.output.find("materials.rock.sfcc.lambda") != std::string::npos);
}

TEST_CASE("a plastic material left at each particle's own volumetric strain is warned of locking, a chosen "
          "volumetric_strain, or an elastic material, is not",
          "[mohr_coulomb]") {
  const std::string plastic = " --set 'materials.soil.mechanical_model={model: mohr_coulomb, youngs_modulus: 1.0e6, "
                              "poisson_ratio: 0.3, cohesion: 0, friction_angle: 20}'";
  const auto warned = run_frostmpm("check " + kColumn + plastic);
  INFO(warned.output);
  REQUIRE(warned.exit_code == 0);
  CHECK(warned.output.find("warning: ") != std::string::npos);
  CHECK(warned.output.find("at 'physics.mechanical': material 'soil' is plastic ('mohr_coulomb')") != std::string::npos);
  CHECK(warned.output.find("set volumetric_strain: cell_average") != std::string::npos);
  for (const std::string quiet : {plastic + " --set physics.mechanical.volumetric_strain=particle",
                                  plastic + " --set physics.mechanical.volumetric_strain=cell_average", std::string()}) {
    const auto r = run_frostmpm("check " + kColumn + quiet);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("locks") == std::string::npos);
  }
}
