"""Units as FrostMPM records them (UDUNITS-2 strings: "degC", "m^3/m", "kg/(m^3 s)", "1" for
dimensionless) and as a figure shows them, and times as a user types them ("30d", "2.5h").

Labels come from the recorded units only: output written before FrostMPM recorded units
gets no unit in its labels, never one guessed from a name.
"""
import re

SUPERSCRIPTS = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
SYMBOLS = {"degC": "°C", "degree": "°", "1": "-"}

# Time units a user may type and the figures use, shortest first.
TIME_UNITS = [(1.0, "s"), (60.0, "min"), (3600.0, "h"), (86400.0, "d"), (365.25 * 86400.0, "yr")]
TIME_TEXT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-z]*)\s*$")


def pretty(unit):
    """'degC' -> '°C', 'm^3/m' -> 'm³/m', '1' -> '-' (dimensionless); None -> None."""
    if unit is None or unit == "":
        return None
    if unit in SYMBOLS:
        return SYMBOLS[unit]
    text = re.sub(r"\bdegC\b", "°C", unit)
    return re.sub(r"\^(-?\d+)", lambda m: m.group(1).translate(SUPERSCRIPTS), text)


def label(name, unit):
    """'T_min [°C]', or the bare name when the unit is not recorded."""
    shown = pretty(unit)
    return f"{name} [{shown}]" if shown else name


def is_temperature(unit):
    return unit == "degC"


def time_unit(seconds):
    """(divisor, name) of the largest unit in which the span `seconds` is at least 2."""
    divisor, name = TIME_UNITS[0]
    for d, n in TIME_UNITS:
        if seconds >= 2 * d:
            divisor, name = d, n
    return divisor, name


def parse_time(text):
    """Seconds of '30d', '2.5 h', '90min', '1yr' or a bare number of seconds; ValueError naming
    the text and the units accepted otherwise."""
    match = TIME_TEXT.match(text)
    units = dict((name, divisor) for divisor, name in TIME_UNITS)
    if not match or match.group(2) not in units and match.group(2) != "":
        raise ValueError(f"'{text}' is not a time: give a number of seconds, or one with a unit "
                         f"({', '.join(units)}), e.g. 30d")
    return float(match.group(1)) * units.get(match.group(2), 1.0)


def format_time(seconds, divisor, name):
    return f"{seconds / divisor:.4g} {name}"
