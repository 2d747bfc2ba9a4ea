#pragma once
// Units as FrostMPM's outputs carry them: every particle field (the `units` attribute of its
// fields.h5 datasets) and every metrics.csv column (run.json's `metrics_units`) has one,
// written as UDUNITS-2 text: "degC", "Pa", "m/s", "kg/(m^3 s)", "1" for dimensionless. In 2-D,
// extensive quantities are per metre of thickness: a volume is "m^3/m", a force "N/m".
#include <algorithm>
#include <string_view>

namespace frostmpm {

/// Non-empty printable ASCII: what a unit may be (it is written unchanged into HDF5 and JSON).
inline bool valid_unit(std::string_view unit) {
  return !unit.empty() && std::all_of(unit.begin(), unit.end(), [](char c) { return c >= 0x20 && c < 0x7f && c != '"'; });
}

}  // namespace frostmpm
