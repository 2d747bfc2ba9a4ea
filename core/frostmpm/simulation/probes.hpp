#pragma once
// Probes: what metrics.csv records over time. Each probe is one column:
//   min / max        extreme of a particle scalar (or one component: "stress.yy")
//   value_at         a particle field interpolated to a point through the grid (volume-weighted)
//   integral         Σ V_p Π fields × scale
//   isotherm         distance along a segment to the first crossing of a level
//   thaw_depth       distance along a segment to the bottom of the thawed layer: the last place
//                    where liquid saturation ≥ level (½ by default) lies over frozen material
// Any probe with `over_time: max|min` reports its extreme over the rows written so far (the
// active-layer thickness is the thaw depth's maximum); the running extreme is checkpointed.
//   displacement     one component of the displacement of the material point that started
//                    nearest to `point` (it is followed as it moves)
//   settlement       mean downward displacement of the material's top surface (the top of the GIMP
//                    domain of the top particle of every particle column, optionally within
//                    x_range), m, positive down
//   reaction         one component of the force a boundary condition (named with `name:`)
//                    exerts on the material, N per m of thickness in 2-D
//   footing_force    the force with which the material resists a footing (a rigid body a
//                    condition drives, named with `name:`), N per m in 2-D, positive resisting
//   footing_pressure that force over the footing's contact area (width in 2-D), Pa
//   footing_displacement  how far the footing has moved along its direction of motion, m
// Every column has a unit (column_units(), run.json's metrics_units): a field's for min, max
// and value_at; for an integral the fields' units times the volume's (m^3/m in 2-D), or its
// `unit:` when a `scale` carries one; m, N/m or Pa for the geometric and force probes.
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "frostmpm/config/config_node.hpp"
#include "frostmpm/grid/uniform_grid.hpp"
#include "frostmpm/particles/particle_store.hpp"
#include "frostmpm/physics/physics.hpp"
#include "frostmpm/transfer/transfer.hpp"

namespace frostmpm {

class Probes {
 public:
  static constexpr int kDim = 2;
  /// A boundary condition with a `name:`, which a reaction probe may name.
  struct NamedBoundary {
    std::string name;
    std::string label;          ///< BoundaryCondition::label(), for messages
    bool has_reaction = false;  ///< its physics reports the force it exerts
    bool is_rigid_body = false; ///< it drives a rigid body (footing_* probes)
  };
  /// What probes read: the particles (with their positions at the start), the transfer service,
  /// the grid, the named boundary conditions and the reaction of one.
  struct Sources {
    const UniformGrid<kDim>* grid = nullptr;
    const ParticleStore* particles = nullptr;
    const Transfer<kDim>* transfer = nullptr;
    std::vector<NamedBoundary> boundaries;
    std::vector<std::string> reaction_types;  ///< types of the scene's conditions that have a reaction
    std::function<std::array<double, 3>(const std::string&)> reaction;
    std::function<Physics::RigidBodyMotion(const std::string&)> rigid_body;
  };

  Probes();
  ~Probes();
  Probes(Probes&&) noexcept;
  Probes& operator=(Probes&&) noexcept;

  /// Reads the `probes:` list (none when `node` is null); particle positions are the initial ones.
  void read(const ConfigNode* node, Sources sources);
  /// One value per probe, in order, as they are now.
  std::vector<double> evaluate() const;
  /// The values of one metrics row: evaluate(), with `over_time` probes folded into their
  /// running extremes.
  std::vector<double> record();
  /// The running extremes, for checkpoints (empty when no probe has `over_time`).
  std::vector<PersistentArray> persistent_state();
  /// Particles left the run: the probes that follow material points follow the remaining ones.
  /// Throws NumericalBlowUp (at `time`) when a probe's every point left, unless `restoring`.
  void remove_particles(const ParticleRemoval& removal, double time);
  /// "time_s,step,dt_s,<probe names>".
  std::string header() const;
  /// (column, unit) of every metrics.csv column, in header order.
  std::vector<std::pair<std::string, std::string>> column_units() const;
  /// The columns metrics.csv has before the probes' (no probe may take these names).
  static const std::vector<std::string>& leading_columns();
  YAML::Node resolved() const { return resolved_; }

  /// A particle field (or one component, "stress.yy", "water_flux.x") interpolated to a point
  /// through the grid: volume-weighted nodal average, then bilinear interpolation.
  double sample_field(const std::string& field, const std::array<double, kDim>& point) const;

 private:
  struct Probe;
  /// A scalar field or one component of a vector/tensor field: value p is values[p * stride + component].
  struct ScalarColumn {
    std::span<const double> values;
    std::size_t component = 0, stride = 1;
  };
  ScalarColumn scalar_column(const std::string& name) const;
  /// The unit of a scalar name: its field's, for a component ("stress.yy") the tensor's.
  const std::string& scalar_unit(const std::string& name) const;
  /// Every scalar name a probe may use: scalar fields and the components of the others.
  std::vector<std::string> scalar_names() const;

  /// The probe's field minus its level at evenly spaced points from `from` to `to` (4 per cell).
  std::vector<double> sample_line(const Probe& probe) const;
  /// The volume-weighted nodal average Σ V_p S_ip f_p / Σ V_p S_ip of a scalar name, one pass
  /// over the particles; 0 weight where no particle reaches. {average, weight} per node.
  std::pair<std::vector<double>, std::vector<double>> nodal_average(const std::string& field) const;
  /// Bilinear interpolation of a nodal average to a point, over the corners some particle reaches.
  double interpolate(const std::pair<std::vector<double>, std::vector<double>>& nodal,
                     const std::array<double, kDim>& point) const;

  Sources sources_;
  std::vector<std::unique_ptr<Probe>> probes_;
  std::vector<double> extremes_;  ///< running extreme of each `over_time` probe (NaN: none yet)
  YAML::Node resolved_;
};

}  // namespace frostmpm
