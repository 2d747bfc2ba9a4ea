#include "test_model.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include "frostmpm/models/model_contract.hpp"
#include "frostmpm/scene/plugin_setup.hpp"

namespace frostmpm::app {
namespace {

/// A value inside the declared range, for a required parameter the user did not give: lets
/// `test-model KIND/NAME` run without arguments. Printed as "(picked)" so it can be overridden.
YAML::Node picked_value(const ParamSpec& spec, const std::string& model) {
  double number = 0.0;
  if (spec.lower && spec.upper) number = 0.5 * (*spec.lower + *spec.upper);
  else if (spec.lower) number = *spec.lower + 1.0;
  else if (spec.upper) number = *spec.upper - 1.0;
  switch (spec.type) {
    case ParamType::Real: return YAML::Node(number);
    case ParamType::Integer: return YAML::Node(static_cast<long>(std::ceil(number)));
    case ParamType::Boolean: return YAML::Node(false);
    case ParamType::Choice: return YAML::Node(spec.choices.front());
    case ParamType::RealList: {
      YAML::Node list(YAML::NodeType::Sequence);
      for (std::size_t i = 0; i < std::max<std::size_t>(spec.list_size, 1); ++i) list.push_back(number);
      return list;
    }
    case ParamType::String: break;
  }
  throw InputError("test-model " + model + ": give the required parameter '" + spec.name + "' with --set " +
                   spec.name + "=VALUE");
}

struct Parameters {
  ParamSet values;
  std::vector<std::string> picked;
};

Parameters read_parameters(const RegistryEntry& entry, const std::vector<std::string>& settings,
                           const std::string& model) {
  YAML::Node given(YAML::NodeType::Map);
  for (const auto& setting : settings) {
    const auto eq = setting.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("test-model --set '" + setting + "': expected parameter=value");
    given[setting.substr(0, eq)] = YAML::Load(setting.substr(eq + 1));
  }
  Parameters out;
  for (const auto& spec : entry.schema.params())
    if (spec.required() && !given[spec.name].IsDefined()) {
      given[spec.name] = picked_value(spec, model);
      out.picked.push_back(spec.name);
    }
  out.values = parse_params(entry.schema, ConfigNode(given, "--set"));
  // An optional parameter the model cannot do without when nothing else supplies it (the λ that
  // mohr_coulomb_ice reads from a scene's freezing curve): when the model refuses the set, the
  // first optional parameter with a two-sided range whose picked value makes it accept is picked.
  try {
    (void)entry.create(out.values);
  } catch (const InputError&) {
    for (const auto& spec : entry.schema.params()) {
      if (spec.optional_meaning.empty() || !spec.lower || !spec.upper || given[spec.name].IsDefined()) continue;
      YAML::Node fuller = YAML::Clone(given);
      fuller[spec.name] = picked_value(spec, model);
      try {
        ParamSet values = parse_params(entry.schema, ConfigNode(fuller, "--set"));
        (void)entry.create(values);
        out.values = std::move(values);
        out.picked.push_back(spec.name);
        break;
      } catch (const InputError&) {
        continue;  // not this one
      }
    }
  }
  return out;
}

std::string parameter_line(const Parameters& p) {
  std::string line;
  for (const auto& kv : p.values.to_yaml()) {
    const std::string name = kv.first.as<std::string>();
    std::ostringstream value;
    double number = 0;
    if (kv.second.IsScalar() && YAML::convert<double>::decode(kv.second, number)) {
      value << number;  // 1e-06, not YAML's 9.9999999999999995e-07
    } else {
      YAML::Emitter emitter;
      emitter << YAML::Flow << kv.second;
      value << emitter.c_str();
    }
    line += (line.empty() ? "" : ", ") + name + "=" + value.str();
    if (std::find(p.picked.begin(), p.picked.end(), name) != p.picked.end()) line += " (picked)";
  }
  return line.empty() ? "(none)" : line;
}

/// The given parameter set, then each real parameter not given with --set at 1 % and 99 % of a
/// two-sided declared range (the others as given): a mechanical model's contract must hold
/// across its ranges, and its moduli span decades. A set the model's own cross-parameter
/// checks refuse is skipped and named.
std::vector<std::string> check_mechanical(const std::string& name, const Registry& registry, const ParamSet& params,
                                          const TestModelOptions& o, std::ostream& out) {
  const SourceLocation where{"test-model " + o.target, "", 0, 0};
  std::vector<std::string> given;
  for (const auto& setting : o.settings) given.push_back(setting.substr(0, setting.find('=')));
  std::vector<std::shared_ptr<MechanicalModel>> models{registry.create<MechanicalModel>(name, params, where)};
  std::vector<MechanicalModelCase> cases{{models.front().get(), ""}};
  std::vector<std::string> varied, skipped;
  for (const auto& spec : registry.get(MechanicalModel::kKind, name, where).schema.params()) {
    if (spec.type != ParamType::Real || !spec.lower || !spec.upper ||
        std::find(given.begin(), given.end(), spec.name) != given.end())
      continue;
    varied.push_back(spec.name);
    for (const double fraction : {0.01, 0.99}) {
      const double value = *spec.lower + fraction * (*spec.upper - *spec.lower);
      ParamSet set = params;
      set.set(spec.name, value, where);
      const std::string label = spec.name + "=" + number_text(value, 6);
      try {
        models.push_back(registry.create<MechanicalModel>(name, set, where));
        cases.push_back({models.back().get(), label});
      } catch (const InputError&) {
        skipped.push_back(label);
      }
    }
  }
  out << "  parameter sets: " << cases.size() << " (the above";
  if (!varied.empty()) out << ", and each of " << join(varied) << " at 1 % and 99 % of its range";
  out << ")" << (skipped.empty() ? "" : "; refused by the model, skipped: " + join(skipped)) << "\n";
  out << "  sampled: " << o.samples << " states per set: strain increments up to 1e-3 from start states the model "
      << "reaches in one step from a compression up to 1 MPa, T in [-20, 20] degC, S_c in [0, 1], p_l in [0, 1e6] Pa, "
      << "random rotations; "
      << "max_p_wave_modulus() = " << number_text(models.front()->max_p_wave_modulus(), 6) << " Pa\n";
  return check_mechanical_model_contract(cases, o.samples);
}

/// The refusal of a kind with no contract to check (physics, boundary-condition types).
InputError no_contract_check(const std::string& kind) {
  return InputError("test-model: no contract check for kind '" + kind + "'; it checks " + SfccModel::kKind + ", " +
                    RelativePermeabilityModel::kKind + ", " + AbsolutePermeabilityModel::kKind + " and " +
                    MechanicalModel::kKind + " models");
}

/// Builds the model and runs the contract check of its kind.
std::vector<std::string> check(const std::string& kind, const std::string& name, const Registry& registry,
                               const ParamSet& params, const TestModelOptions& o, std::ostream& out) {
  const SourceLocation where{"test-model " + o.target, "", 0, 0};
  if (kind == MechanicalModel::kKind) return check_mechanical(name, registry, params, o, out);
  if (kind == SfccModel::kKind) {
    const auto model = registry.create<SfccModel>(name, params, where);
    const double T_f = model->freezing_point();
    const double T_min = o.temperature_range.empty() ? T_f - 10.0 : o.temperature_range.at(0);
    const double T_max = o.temperature_range.empty() ? T_f + 2.0 : o.temperature_range.at(1);
    out << "  sampled: T in [" << T_min << ", " << T_max << "] degC, " << o.samples << " points; freezing_point() = "
        << T_f << "\n";
    return check_sfcc_contract(*model, T_min, T_max, o.samples);
  }
  if (kind == RelativePermeabilityModel::kKind) {
    out << "  sampled: S_l in [0, 1] at porosity 0.1, 0.3, 0.5, " << o.samples << " points each\n";
    return check_relative_permeability_contract(*registry.create<RelativePermeabilityModel>(name, params, where),
                                                o.samples);
  }
  if (kind == AbsolutePermeabilityModel::kKind) {
    out << "  sampled: porosity in [0.01, 0.99], " << o.samples << " points\n";
    return check_absolute_permeability_contract(*registry.create<AbsolutePermeabilityModel>(name, params, where),
                                                o.samples);
  }
  throw no_contract_check(kind);
}

}  // namespace

int cmd_test_model(const TestModelOptions& o, std::ostream& out) {
  Registry registry;
  PluginLoader loader(registry);
  PluginSetup{o.plugin_paths}.load_defaults(loader);
  for (const auto& warning : refusal_warnings(loader)) std::cerr << "warning: " << warning << "\n";

  const auto slash = o.target.find('/');
  if (slash == std::string::npos) throw InputError("test-model: expected KIND/NAME, e.g. sfcc/exponential");
  const std::string kind = o.target.substr(0, slash), name = o.target.substr(slash + 1);
  if (kind != SfccModel::kKind && kind != RelativePermeabilityModel::kKind && kind != AbsolutePermeabilityModel::kKind &&
      kind != MechanicalModel::kKind)
    throw no_contract_check(kind);
  const RegistryEntry& entry = registry.get(kind, name, {"test-model", "", 0, 0});
  const Parameters params = read_parameters(entry, o.settings, o.target);

  out << o.target << " from " << entry.plugin << " " << entry.version << " (" << entry.library << ")\n";
  out << "  parameters: " << parameter_line(params) << "\n";
  std::vector<std::string> violations;
  try {
    violations = check(kind, name, registry, params.values, o, out);
  } catch (const InputError& e) {
    if (params.picked.empty()) throw;
    throw InputError(std::string(e.what()) + "; give better values than the picked ones with --set NAME=VALUE");
  }
  for (const auto& line : violations) out << "violation: " << line << "\n";
  if (violations.empty()) {
    out << o.target << ": contract kept\n";
    return 0;
  }
  out << o.target << ": " << violations.size() << " contract rule(s) broken\n";
  return kContractViolationExitCode;
}

}  // namespace frostmpm::app
