#include "frostmpm/scene/region.hpp"

#include <cmath>

namespace frostmpm {

namespace {
std::array<double, 2> read_point(const ConfigNode& node) {
  const auto v = node.as_reals("m");
  if (v.size() != 2) throw node.error("expected a point [x, y]");
  return {v[0], v[1]};
}
double read_positive(const ConfigNode& node) {
  const double v = node.as_real("m");
  if (!(v > 0)) throw node.error("must be positive");
  return v;
}
YAML::Node point_yaml(const std::array<double, 2>& p) {
  YAML::Node n(YAML::NodeType::Sequence);
  n.push_back(p[0]);
  n.push_back(p[1]);
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}
}  // namespace

RegionShape read_region_shape(const ConfigNode& node) {
  static const std::vector<std::string> kinds = {"box", "disk", "half_disk", "polygon"};
  const auto keys = node.keys();
  if (!node.is_map() || keys.size() != 1)
    throw node.error("expected exactly one shape: " + join(kinds));
  node.reject_unknown(kinds);
  RegionShape shape;
  shape.kind = keys.front();
  const ConfigNode body = node.child(shape.kind);
  shape.resolved = YAML::Node(YAML::NodeType::Map);
  if (shape.kind == "box") {
    const auto lo = read_point(body.child("min"));
    const auto hi = read_point(body.child("max"));
    body.finish({"min", "max"});
    if (!(lo[0] < hi[0] && lo[1] < hi[1])) throw body.error("box min must be below max on every axis");
    shape.contains = [lo, hi](const std::array<double, 2>& x) {
      return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1];
    };
    shape.resolved["box"]["min"] = point_yaml(lo);
    shape.resolved["box"]["max"] = point_yaml(hi);
  } else if (shape.kind == "disk" || shape.kind == "half_disk") {
    const auto c = read_point(body.child("center"));
    const double r = read_positive(body.child("radius"));
    std::array<double, 2> keep{0, 0};  // half-plane direction for half discs
    if (shape.kind == "half_disk") {
      const ConfigNode side = body.child("side");
      const std::string s = side.as_string();
      if (s == "top") keep = {0, 1};
      else if (s == "bottom") keep = {0, -1};
      else if (s == "left") keep = {-1, 0};
      else if (s == "right") keep = {1, 0};
      else throw side.error("'" + s + "' is not a side; valid: top, bottom, left, right");
      body.finish({"center", "radius", "side"});
      shape.resolved["half_disk"]["side"] = s;
    } else {
      body.finish({"center", "radius"});
    }
    shape.contains = [c, r, keep](const std::array<double, 2>& x) {
      const double dx = x[0] - c[0], dy = x[1] - c[1];
      return dx * dx + dy * dy <= r * r && dx * keep[0] + dy * keep[1] >= 0;
    };
    shape.resolved[shape.kind]["center"] = point_yaml(c);
    shape.resolved[shape.kind]["radius"] = r;
  } else {
    std::vector<std::array<double, 2>> vertices;
    for (const auto& v : body.elements()) vertices.push_back(read_point(v));
    if (vertices.size() < 3) throw body.error("a polygon needs at least 3 vertices");
    shape.contains = [vertices](const std::array<double, 2>& x) {
      bool inside = false;  // even-odd ray casting
      for (std::size_t i = 0, j = vertices.size() - 1; i < vertices.size(); j = i++) {
        const auto& a = vertices[i];
        const auto& b = vertices[j];
        if ((a[1] > x[1]) != (b[1] > x[1]) &&
            x[0] < (b[0] - a[0]) * (x[1] - a[1]) / (b[1] - a[1]) + a[0])
          inside = !inside;
      }
      return inside;
    };
    YAML::Node poly(YAML::NodeType::Sequence);
    for (const auto& v : vertices) poly.push_back(point_yaml(v));
    shape.resolved["polygon"] = poly;
  }
  return shape;
}

std::vector<std::array<double, 2>> sample_region(const UniformGrid<2>& grid, const RegionShape& shape,
                                                 int n) {
  std::vector<std::array<double, 2>> points;
  for (int j = 0; j < grid.cells[1]; ++j)
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < grid.cells[0]; ++i)
        for (int a = 0; a < n; ++a) {
          const std::array<double, 2> x{grid.origin[0] + (i + (a + 0.5) / n) * grid.spacing[0],
                                        grid.origin[1] + (j + (b + 0.5) / n) * grid.spacing[1]};
          if (shape.contains(x)) points.push_back(x);
        }
  return points;
}

}  // namespace frostmpm
