// `task: freezing_curves` — evaluates a material's SFCC and permeability models over a
// temperature range and writes a CSV table: the calibration check an engineer makes before a
// run. `/usr/bin/python3 scripts/plot.py OUT` draws the curves from the table.
#include <cmath>
#include <iomanip>
#include <vector>

#include "frostmpm/models/permeability_model.hpp"
#include "frostmpm/models/sfcc_model.hpp"
#include "frostmpm/scene/model_section.hpp"
#include "task.hpp"

namespace frostmpm::app {
namespace {

ParamSchema material_schema() {
  ParamSchema s;
  s.real("porosity", "-", "porosity φ").above(0).below(1);
  return s;
}

ParamSchema range_schema() {
  ParamSchema s;
  s.reals("temperature_range", "degC", "[T_min, T_max] of the table").size(2);
  s.integer("samples", "number of temperatures (evenly spaced)").defaults_to(241L).at_least(2).at_most(1000000);
  s.real("pore_pressure", "Pa", "liquid pressure p_l at which S_l is evaluated").defaults_to(0.0);
  s.string("output", "base name of the CSV file").defaults_to("freezing_curves");
  return s;
}

class FreezingCurvesTask final : public Task {
 public:
  explicit FreezingCurvesTask(const TaskContext& ctx) {
    const ConfigNode material = ctx.root.child("material");
    material_ = parse_params(material_schema(), material,
                             {"sfcc", "relative_permeability", "absolute_permeability"});
    sfcc_ = read_model_section(ctx.registry, SfccModel::kKind, material.child("sfcc"));
    relative_ = read_model_section(ctx.registry, RelativePermeabilityModel::kKind,
                                   material.child("relative_permeability"));
    absolute_ = read_model_section(ctx.registry, AbsolutePermeabilityModel::kKind,
                                   material.child("absolute_permeability"));
    const ConfigNode range_node = ctx.root.child("freezing_curves");
    range_ = parse_params(range_schema(), range_node);
    const auto& r = range_.reals("temperature_range");
    if (!(r[0] < r[1])) throw range_.error("temperature_range", "T_min must be below T_max");
    // Build the models now so parameter cross-checks fail before anything is written.
    sfcc_model_ = sfcc_.create<SfccModel>(ctx.registry);
    relative_model_ = relative_.create<RelativePermeabilityModel>(ctx.registry);
    absolute_model_ = absolute_.create<AbsolutePermeabilityModel>(ctx.registry);
  }

  std::vector<std::string> sections() const override { return {"material", "freezing_curves"}; }

  YAML::Node resolved() const override {
    YAML::Node root;
    YAML::Node material = material_.to_yaml();
    material["sfcc"] = sfcc_.resolved();
    material["relative_permeability"] = relative_.resolved();
    material["absolute_permeability"] = absolute_.resolved();
    root["material"] = material;
    root["freezing_curves"] = range_.to_yaml();
    return root;
  }

  void execute(const OutputDir& out, const RunRequest& request) override {
    if (request.restart) throw InputError("task 'freezing_curves' writes no checkpoints; run it again instead");
    const auto n = static_cast<std::size_t>(range_.integer("samples"));
    const auto& r = range_.reals("temperature_range");
    std::vector<double> T(n), p(n, range_.real("pore_pressure")), phi(n, material_.real("porosity"));
    for (std::size_t i = 0; i < n; ++i) T[i] = r[0] + (r[1] - r[0]) * double(i) / double(n - 1);
    std::vector<double> S(n), dSdT(n), dSdp(n), kr(n), dkr(n), ka(n), dka(n);
    sfcc_model_->evaluate(T, p, SfccResult{S, dSdT, dSdp});
    relative_model_->evaluate(S, phi, kr, dkr);
    absolute_model_->evaluate(phi, ka, dka);

    const std::string base = range_.string("output");
    out.write_text(base + ".csv", [&](std::ostream& os) {
      os << "T_degC,S_l,dS_l_dT_per_degC,dS_l_dp_per_Pa,k_r,dk_r_dS_l,k_a_m_per_s,k_m_per_s\n";
      os << std::setprecision(10);
      for (std::size_t i = 0; i < n; ++i)
        os << T[i] << ',' << S[i] << ',' << dSdT[i] << ',' << dSdp[i] << ',' << kr[i] << ',' << dkr[i]
           << ',' << ka[i] << ',' << ka[i] * kr[i] << '\n';
    });
  }

 private:
  ParamSet material_, range_;
  ModelSection sfcc_, relative_, absolute_;
  std::shared_ptr<SfccModel> sfcc_model_;
  std::shared_ptr<RelativePermeabilityModel> relative_model_;
  std::shared_ptr<AbsolutePermeabilityModel> absolute_model_;
};

}  // namespace

std::unique_ptr<Task> make_freezing_curves_task(const TaskContext& context) {
  return std::make_unique<FreezingCurvesTask>(context);
}

}  // namespace frostmpm::app
