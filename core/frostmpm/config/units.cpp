#include "frostmpm/config/units.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <memory>
#include <mutex>
#include <sstream>
#include <utility>

#include <udunits2.h>

namespace frostmpm::units {

namespace {

struct FreeUnit {
  void operator()(ut_unit* unit) const { ut_free(unit); }
};
struct FreeConverter {
  void operator()(cv_converter* converter) const { cv_free(converter); }
};
using Unit = std::unique_ptr<ut_unit, FreeUnit>;
using Converter = std::unique_ptr<cv_converter, FreeConverter>;

/// UDUNITS-2 keeps its status and error handler in globals: one caller at a time.
std::mutex& udunits_mutex() {
  static std::mutex mutex;
  return mutex;
}

/// The unit database from its default place (UDUNITS2_XML_PATH, else the packaged XML), read
/// once and kept for the life of the process; nullptr when it cannot be read.
ut_system* unit_system() {
  static ut_system* const system = [] {
    ut_set_error_message_handler(ut_ignore);  // UDUNITS-2 would print to stderr; we report ourselves
    ut_system* s = ut_read_xml(nullptr);
    // "deg" is the usual abbreviation of the arc degree, which UDUNITS-2 knows only as degree,
    // arc_degree and °: "30 deg" would be an unknown unit.
    if (s)
      if (Unit degree{ut_get_unit_by_name(s, "arc_degree")}) ut_map_symbol_to_unit("deg", UT_ASCII, degree.get());
    return s;
  }();
  if (!system)
    throw UnitError("the UDUNITS-2 unit database could not be read (is the package libudunits2-data installed, or "
                    "UDUNITS2_XML_PATH wrong?)");
  return system;
}

std::string trim(std::string text) {
  const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!text.empty() && space(text.back())) text.pop_back();
  std::size_t first = 0;
  while (first < text.size() && space(text[first])) ++first;
  return text.substr(first);
}

/// "-" is UDUNITS-2's "1".
std::string udunits_spelling(const std::string& declared) { return declared == "-" ? "1" : declared; }

Unit parse(const std::string& text) {
  return Unit{ut_parse(unit_system(), trim(text).c_str(), UT_UTF8)};
}

/// Whether `unit` measures temperature on a scale whose zero is not absolute zero (degC, degF):
/// its conversion to kelvin has an offset.
bool offset_temperature(const ut_unit* unit) {
  const Unit kelvin{ut_get_unit_by_name(unit_system(), "kelvin")};
  if (!kelvin || !ut_are_convertible(unit, kelvin.get())) return false;
  const Converter to_kelvin{ut_get_converter(const_cast<ut_unit*>(unit), kelvin.get())};
  return to_kelvin && cv_convert_double(to_kelvin.get(), 0.0) != 0.0;
}

bool temperature_related(const ut_unit* unit) {
  const Unit kelvin{ut_get_unit_by_name(unit_system(), "kelvin")};
  return kelvin && ut_are_convertible(unit, kelvin.get());
}

std::string name_of(const std::string& declared, const ut_unit* unit) {
  if (declared == "-" || declared == "1") return "a pure number";
  if (temperature_related(unit)) return offset_temperature(unit) ? "a temperature" : "a temperature difference";
  // The first entry of the declared unit's dimension names it.
  static const std::array<std::pair<const char*, const char*>, 20> kNames = {{
      {"s", "a time"},
      {"m", "a length"},
      {"m^2", "an area"},
      {"m^3", "a volume"},
      {"m/s", "a speed"},
      {"m/s^2", "an acceleration"},
      {"Pa", "a pressure"},
      {"1/Pa", "a compressibility"},
      {"Pa s", "a viscosity"},
      {"kg", "a mass"},
      {"kg/m^3", "a density"},
      {"N", "a force"},
      {"N/m", "a force per length"},
      {"J/kg", "an energy per mass"},
      {"W/m^2", "a heat flux"},
      {"W/(m K)", "a thermal conductivity"},
      {"J/(kg K)", "a specific heat capacity"},
      {"W/(m^2 K)", "a heat transfer coefficient"},
      {"1/K", "a thermal expansion coefficient"},
      {"rad", "an angle"},
  }};
  for (const auto& [symbol, name] : kNames)
    if (const Unit known = parse(symbol); known && ut_are_convertible(unit, known.get())) return name;
  return "";
}

}  // namespace

std::optional<Quantity> split(const std::string& written) {
  const std::string text = trim(written);
  const char* first = text.data();
  const char* const end = first + text.size();
  if (first != end && *first == '+') ++first;  // from_chars reads no plus sign
  double value = 0;
  const auto [rest, error] = std::from_chars(first, end, value);
  if (error != std::errc() || rest == first) return std::nullopt;
  std::string unit = trim(std::string(rest, end));
  if (unit.empty()) return std::nullopt;
  return Quantity{value, std::move(unit), text};
}

double convert(const Quantity& quantity, const std::string& declared) {
  if (declared.empty())
    throw UnitError("'" + quantity.text + "': this value takes a bare number in SI units (no unit is declared for it)");
  const std::lock_guard lock(udunits_mutex());
  const Unit given = parse(quantity.unit);
  if (!given)
    throw UnitError("'" + quantity.text + "': unknown unit '" + quantity.unit +
                    "' (UDUNITS-2 symbols or names: m, cm, km, s, min, h, d, kPa, MPa, degC, K, W/(m K), %)");
  const Unit wanted = parse(udunits_spelling(declared));
  if (!wanted) throw std::logic_error("the declared unit '" + declared + "' is not a UDUNITS-2 unit");
  if (!ut_are_convertible(given.get(), wanted.get())) {
    const std::string name = name_of(declared, wanted.get());
    throw UnitError("'" + quantity.text + "' is not " + (name.empty() ? "in " + declared : name) + ": its unit " +
                    quantity.unit + " is not convertible to " + udunits_spelling(declared));
  }
  const Converter converter{ut_get_converter(given.get(), wanted.get())};
  if (!converter) throw UnitError("'" + quantity.text + "' cannot be converted to " + declared);
  const double origin = cv_convert_double(converter.get(), 0.0);
  if (!std::isfinite(origin)) return cv_convert_double(converter.get(), quantity.value);  // a logarithmic unit
  if (origin != 0.0 && !offset_temperature(wanted.get()))
    throw UnitError("'" + quantity.text + "' is a temperature on a scale with an offset (" + quantity.unit +
                    "), but this value is " + name_of(declared, wanted.get()) + " in " + declared +
                    ": give it in K (a difference of 1 degC is 1 K, of 1 degF 5/9 K)");
  if (origin != 0.0) return cv_convert_double(converter.get(), quantity.value);
  // A pure scale change by n or 1/n with n whole (km, cm, %, g/cm^3): UDUNITS-2 composes prefixes
  // in floating point (g/cm^3 to kg/m^3 is 999.9999999999999), so the whole n is used, and 1/n
  // is divided by: the correctly rounded value, the same double as the number typed in the
  // declared unit (5 cm is 0.05 m to the last bit).
  const double slope = cv_convert_double(converter.get(), 1.0);
  const bool linear = cv_convert_double(converter.get(), 2.0) == 2.0 * slope;
  const auto whole = [](double x) {
    const double n = std::round(x);
    return n >= 1.0 && std::abs(x - n) <= 1e-12 * n ? n : 0.0;
  };
  if (linear && whole(slope) > 0) return quantity.value * whole(slope);
  if (linear && whole(1.0 / slope) > 0) return quantity.value / whole(1.0 / slope);
  return cv_convert_double(converter.get(), quantity.value);
}

bool is_declarable(const std::string& unit) {
  if (unit.empty() || unit == "-") return true;
  const std::lock_guard lock(udunits_mutex());
  return parse(unit) != nullptr;
}

bool is_output_unit(const std::string& unit) {
  const bool printable = std::all_of(unit.begin(), unit.end(), [](char c) { return c >= 0x20 && c < 0x7f && c != '"'; });
  return printable && !unit.empty() && unit != "-" && is_declarable(unit);
}

std::string quantity_name(const std::string& declared) {
  if (declared.empty()) return "";
  const std::lock_guard lock(udunits_mutex());
  const Unit unit = parse(udunits_spelling(declared));
  return unit ? name_of(declared, unit.get()) : "";
}

std::string readable_duration(double seconds, int digits) {
  // The year is UDUNITS-2's, so that a time.end of "2 yr" reads back as 2 yr.
  static const double kYear = convert(Quantity{1.0, "yr", "1 yr"}, "s");
  static const std::array<std::pair<double, const char*>, 5> kUnits = {
      {{kYear, "yr"}, {86400.0, "d"}, {3600.0, "h"}, {60.0, "min"}, {1.0, "s"}}};
  for (const auto& [size, symbol] : kUnits)
    if (std::abs(seconds) >= size || size == 1.0) {
      std::ostringstream text;
      text.precision(digits);
      text << seconds / size << ' ' << symbol;
      return text.str();
    }
  return {};
}

}  // namespace frostmpm::units
