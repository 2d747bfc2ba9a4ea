#pragma once
// Quantities with units in scenes ("90 d", "5 cm", "2.1 W/(m K)", "-2 degC"), converted to the
// unit a schema declares. UDUNITS-2 parses and converts; this header includes none of it (only
// units.cpp does), so plugins and apps never depend on its headers.
//
// Declared units: "-" is a pure number (a bare number, or one with a dimensionless unit such as
// "35 %"), "" a value with no declared unit (bare numbers only), anything else a UDUNITS-2 unit.
// Absolute temperatures are declared "degC"; every other declared unit that involves temperature
// ("K", "1/K", "W/(m K)") is a difference or a ratio, for which a value on an offset scale (degC,
// degF) is refused: a difference of 5 degC is 5 K, while UDUNITS-2 would turn "5 degC" into 278.15 K.
#include <optional>
#include <stdexcept>
#include <string>

namespace frostmpm::units {

/// A unit-bearing scalar as written: "90 d" is {90, "d", "90 d"}.
struct Quantity {
  double value = 0;
  std::string unit;
  std::string text;  ///< as written, for messages
};

/// Splits "<number> <unit>" (the space may be left out: "5cm"); nullopt when the text is not a
/// number followed by something (a bare number, a word, an empty string).
std::optional<Quantity> split(const std::string& text);

/// A unit UDUNITS-2 does not know, a value of another dimension, or a temperature on an offset
/// scale where a difference is declared. The message is one sentence without a location (the
/// caller adds the scene's file, line and path).
class UnitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `quantity` in the `declared` unit. A scale change by a whole number n or by 1/n (km, cm, %)
/// multiplies or divides by n exactly, so "5 cm" is the same double as 0.05 typed in metres.
double convert(const Quantity& quantity, const std::string& declared);

/// Whether a schema may declare `unit`: "-", "" or a unit UDUNITS-2 parses. (The unit database
/// is read once, on first use; safe to call from several threads.)
bool is_declarable(const std::string& unit);

/// Whether `unit` may label an output (a particle field's `units` attribute in fields.h5, a
/// metrics.csv column in run.json, a model's internal variable): UDUNITS-2 text it parses
/// ("degC", "m/s", "1" when dimensionless), printable ASCII without '"' since it is written
/// unchanged into HDF5 and JSON. Not "-" nor "" (those are for schemas only).
bool is_output_unit(const std::string& unit);

/// What a declared unit measures, for messages: "a time", "a pressure", "a temperature
/// difference"; "" when it has no common name.
std::string quantity_name(const std::string& declared);

/// A duration in the largest of s, min, h, d, yr (365.25 d) that keeps it at least 1, with
/// `digits` significant digits: "45 s", "2.5 h", "90 d".
std::string readable_duration(double seconds, int digits = 3);

}  // namespace frostmpm::units
