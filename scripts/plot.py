#!/usr/bin/python3
"""Every figure of one FrostMPM run folder, as PNG files.

    /usr/bin/python3 scripts/plot.py OUT [--to DIR] [--frame N | --time T]
                                         [--along x=X] [--field NAME] [--times T1,T2,...]

OUT is a folder `frostmpm run` wrote. Draws what it finds:
  metrics.csv        metrics.png: one panel per probe column against time (s, min, h, d or yr), dt_s last
  freezing-curve tables  <name>.png for each CSV the freezing_curves task wrote (T_degC, S_l, ...):
                     S_l(T), dS_l/dT, k_r(T) (log) and k(T) (log)
  fields.xdmf/.h5    fields.png: the particle fields of the last frame (--frame N or --time T for
                     another): filled contours in 2-D with the 0 °C isotherm on temperatures, vector
                     fields as their magnitude with arrows, the water flux as arrows over the
                     temperature; profiles when the particles form a column or layer at most two
                     particles across
                     FIELD_profiles.png and FIELD_time_depth.png along a vertical line (a column's
                     axis, or --along x=X through a 2-D domain), in depth below the top of the
                     material at the first frame: trumpet curves (the range of the field over every
                     frame, and its profiles at --times, by default six times spread over the run)
                     and a time-depth contour with the 0 °C line. --field picks the field (default
                     temperature; a vector's component as water_flux.y).
Times are seconds or carry a unit: 3600, 90min, 2.5h, 30d, 1yr.

Labels take their units from the run: the `units` attribute of each fields.h5 dataset and
run.json's `metrics_units`. Output written before FrostMPM recorded units gets bare names.
The PNGs go into OUT unless --to DIR. Prints one line per file written; exit 1 when OUT holds
nothing to plot, 2 for a bad option (one line). Needs Debian's /usr/bin/python3
(python3-matplotlib, python3-numpy, python3-h5py).
"""
import argparse
import glob
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import frostplot  # noqa: E402
from frostplot import lines, np, plt, units  # noqa: E402

FREEZING_CURVE_COLUMNS = ("T_degC", "S_l", "dS_l_dT_per_degC", "k_r")
LEADING_COLUMNS = ("time_s", "step")
PROFILE_COUNT = 6  # profiles a trumpet figure draws when no --times are given


class Refused(Exception):
    """A bad option value: one line for the user."""


def grid(n, width=4.2, height=3.0, columns=3):
    cols = min(columns, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


# ---- metrics ---------------------------------------------------------------------------------


def plot_metrics(folder, to, title):
    m = frostplot.metrics(folder)
    if "time_s" not in m or len(m["time_s"]) == 0:
        return []
    column_units = frostplot.metrics_units(folder)
    divisor, unit = units.time_unit(float(m["time_s"].max()))
    t = m["time_s"] / divisor
    # The probes first: the step size is a diagnostic, not a result.
    columns = [c for c in m if c not in LEADING_COLUMNS and c != "dt_s"] + [c for c in m if c == "dt_s"]
    fig, axes = grid(len(columns))
    for ax, column in zip(axes, columns):
        ax.plot(t, m[column], lw=1.2)
        ax.set(xlabel=f"t [{unit}]", ylabel=units.label(column, column_units.get(column)), title=column)
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    return [frostplot.save(fig, os.path.join(to, "metrics.png"))]


# ---- freezing curves -------------------------------------------------------------------------


def model_names(summary):
    """'van_genuchten_cc + van_genuchten_mualem' from run.json's resolved material, or ''."""
    material = summary.get("resolved_scene", {}).get("material", {})
    names = [material.get(key, {}).get("model") for key in ("sfcc", "relative_permeability", "absolute_permeability")]
    return " + ".join(n for n in names if n)


def plot_freezing_curves(folder, to, title):
    written = []
    for path in sorted(glob.glob(os.path.join(folder, "*.csv"))):
        with open(path) as f:
            header = f.readline().strip().split(",")
        if not all(c in header for c in FREEZING_CURVE_COLUMNS):
            continue
        c = frostplot.read_table(path)
        T = c["T_degC"]
        fig, (s_ax, slope_ax, kr_ax, k_ax) = grid(4, columns=2)
        s_ax.plot(T, c["S_l"])
        s_ax.set(xlabel="T [°C]", ylabel="S_l [-]", title="liquid saturation (SFCC)")
        slope_ax.plot(T, c["dS_l_dT_per_degC"])
        slope_ax.set(xlabel="T [°C]", ylabel="dS_l/dT [1/°C]", title="slope of the SFCC")
        kr_ax.semilogy(T, c["k_r"])
        kr_ax.set(xlabel="T [°C]", ylabel="k_r [-]", title="relative permeability")
        if "k_m_per_s" in c:
            k_ax.semilogy(T, c["k_m_per_s"])
            k_ax.set(xlabel="T [°C]", ylabel="k [m/s]", title="hydraulic conductivity k_a k_r")
        else:
            k_ax.set_visible(False)
        for ax in (s_ax, slope_ax, kr_ax, k_ax):
            ax.grid(alpha=0.3)
        fig.suptitle(title)
        name = os.path.splitext(os.path.basename(path))[0]
        written.append(frostplot.save(fig, os.path.join(to, name + ".png")))
    return written


# ---- choosing frames -------------------------------------------------------------------------


def frame_near(frames, seconds, option):
    """The frame whose time is nearest `seconds`; Refused when it lies outside the run by more
    than half the spacing of its frames."""
    times = np.array([fr["time"] for fr in frames])
    slack = 0.5 * float(np.median(np.diff(times))) if len(times) > 1 else 1e-9 * max(1.0, abs(times[-1]))
    if seconds < times[0] - slack or seconds > times[-1] + slack:
        divisor, name = units.time_unit(times[-1])
        raise Refused(f"{option}: t = {units.format_time(seconds, divisor, name)} lies outside the frames of "
                      f"fields.h5 (t = {units.format_time(times[0], divisor, name)} to "
                      f"{units.format_time(times[-1], divisor, name)})")
    return frames[int(np.argmin(np.abs(times - seconds)))]


def chosen_frame(frames, index, time_text):
    if time_text is not None:
        return frame_near(frames, parse_time(time_text, "--time"), "--time")
    if not -len(frames) <= index < len(frames):
        raise Refused(f"--frame {index}: fields.h5 has {len(frames)} frames (0 to {len(frames) - 1}, or -1 for the last)")
    return frames[index]


def parse_time(text, option):
    try:
        return units.parse_time(text)
    except ValueError as error:
        raise Refused(f"{option}: {error}") from None


def field_unit(frames, name):
    """The field's unit as the newest frame that records one says (a restart may append
    frames with units to frames without), or None."""
    for frame in reversed(frames):
        if frame.get("units", {}).get(name):
            return frame["units"][name]
    return None


def is_temperature(name, unit):
    """Temperature fields get a diverging colour map and the 0 °C line. Without a recorded unit
    (older output) the field's name decides: only the colours depend on it, never a label."""
    return units.is_temperature(unit) or (unit is None and name.startswith("temperature"))


# ---- fields of one frame ---------------------------------------------------------------------


def field_axes(n, frame):
    """(figure, axes, stretch) for n panels of one frame, shaped after the particles' extent: a
    column gets tall panels side by side, a layer wide ones stacked, a tall domain panels side by
    side (x drawn out of scale beyond 4:1, `stretch`), a wide one two columns of panels."""
    axis = lines.line_axis(frame)
    if axis == 1:
        return (*grid(n, width=3.2, height=6.5, columns=5), False)
    if axis == 0:
        return (*grid(n, width=7.5, height=2.8, columns=1), False)
    ratio = frostplot.aspect(frame)
    if ratio >= 1.5:
        stretch = ratio > 4
        height = 7.0
        width = 3.0 if stretch else max(3.0, (height - 1.2) / ratio + 1.9)
        return (*grid(n, width=width, height=height, columns=4), stretch)
    return (*grid(n, width=6.0, height=min(6.0, max(2.4, 1.3 + 4.5 * ratio)), columns=2), False)


def plot_fields(frames, frame, to, title):
    fields = frame["fields"]
    scalars = [n for n, v in fields.items() if v.ndim == 1]
    vectors = [n for n, v in fields.items() if frame["types"].get(n) == "Vector"]
    if not scalars and not vectors:
        return []
    dim = frame.get("coordinates_components", 2)
    fig, axes, stretch = field_axes(len(scalars) + len(vectors), frame)
    flux_shown = False
    for ax, name in zip(axes, scalars):
        unit = field_unit(frames, name)
        temperature = is_temperature(name, unit)
        frostplot.field_panel(ax, fig, frame, name, cmap="coolwarm" if temperature else "viridis",
                              zero_line=temperature, label=units.label(name, unit), stretch=stretch)
        # The water flux over the (first) temperature: where the flow carries heat.
        if temperature and not flux_shown and "water_flux" in vectors and lines.line_axis(frame) is None:
            frostplot.arrows(ax, frame, fields["water_flux"], field_unit(frames, "water_flux"))
            ax.set_title(f"{name}, arrows: water_flux", loc="left")
            flux_shown = True
        else:
            ax.set_title(name)
    for ax, name in zip(axes[len(scalars):], vectors):
        unit = field_unit(frames, name)
        values = fields[name]
        axis = lines.line_axis(frame)
        if axis is not None:  # a column or layer: the components along it
            series = [(values[:, d], "xyz"[d]) for d in range(min(dim, values.shape[1]))]
            frostplot.profile_panel(ax, lines.planar(frame), series, axis, units.label(name, unit))
        else:
            magnitude = np.hypot(values[:, 0], values[:, 1])
            frostplot.scalar_panel(ax, fig, frame, magnitude, units.label(f"|{name}|", unit), cmap="viridis",
                                   stretch=stretch)
            frostplot.arrows(ax, frame, values, unit)
        ax.set_title(name, loc="center" if axis is not None else "left")
    divisor, unit = units.time_unit(frame["time"])
    fig.suptitle(f"{title}: t = {units.format_time(frame['time'], divisor, unit)}")
    return [frostplot.save(fig, os.path.join(to, "fields.png"))]


# ---- along a vertical line -------------------------------------------------------------------


def line_values(frames, spec):
    """(name shown, unit, per-frame values function) for a scalar field or one component of a
    vector field ('water_flux.y')."""
    fields = frames[-1]["fields"]
    name, _, part = spec.partition(".")
    if name not in fields:
        raise Refused(f"--field {spec}: fields.h5 has no field '{name}'; it has {', '.join(fields)}")
    if fields[name].ndim == 1:
        if part:
            raise Refused(f"--field {spec}: '{name}' is a scalar field; give it without a component")
        return spec, field_unit(frames, name), lambda frame: frame["fields"][name]
    if part not in ("x", "y"):
        raise Refused(f"--field {spec}: '{name}' is a vector field; give a component, {name}.x or {name}.y")
    index = "xy".index(part)
    return spec, field_unit(frames, name), lambda frame: frame["fields"][name][:, index]


def profile_frames(frames, times_text):
    """The frames whose profiles a trumpet figure draws: those nearest --times, or up to
    PROFILE_COUNT spread evenly over the run."""
    if times_text:
        return [frame_near(frames, parse_time(t, "--times"), "--times") for t in times_text.split(",")]
    picks = np.unique(np.round(np.linspace(0, len(frames) - 1, min(len(frames), PROFILE_COUNT))).astype(int))
    return [frames[k] for k in picks]


class LineData:
    """A field along a vertical line at every frame, and what its figures say about it."""

    def __init__(self, frames, line, spec, title):
        self.name, self.unit, self.values_of = line_values(frames, spec)
        self.temperature = is_temperature(spec, self.unit)
        self.times, self.depths, self.table = line.time_depth(frames, self.values_of)
        self.divisor, self.time_name = units.time_unit(self.times[-1])
        self.label = units.label(self.name, self.unit)
        self.title = f"{title}: {self.name} along x = {line.x:.4g} m"
        self.file_stem = self.name.replace(".", "_")

    def when(self, seconds):
        return units.format_time(seconds, self.divisor, self.time_name)


def plot_trumpet(frames, line, data, times_text, to):
    """Profiles at the chosen times over the range the field takes from the first of them to
    the last (the whole run by default): the trumpet curves of a seasonal thaw."""
    fig, ax = plt.subplots(figsize=(5.6, 6.8))
    chosen = profile_frames(frames, times_text)
    first, last = min(fr["time"] for fr in chosen), max(fr["time"] for fr in chosen)
    span = (data.times >= first) & (data.times <= last)
    if np.count_nonzero(span) > 1:
        with np.errstate(all="ignore"):
            low, high = np.nanmin(data.table[span], axis=0), np.nanmax(data.table[span], axis=0)
        ax.fill_betweenx(data.depths, low, high, color="0.88", label=f"range, t = {data.when(first)} to {data.when(last)}")
        ax.plot(low, data.depths, color="0.45", lw=0.8)
        ax.plot(high, data.depths, color="0.45", lw=0.8)
    for frame in chosen:
        depth, values = line.profile(frame, data.values_of(frame))
        ax.plot(values, depth, lw=1.4, label=f"t = {data.when(frame['time'])}")
    if data.temperature:
        ax.axvline(0.0, color="k", lw=0.7)
    ax.invert_yaxis()
    ax.set(xlabel=data.label, ylabel="depth [m]", title=data.title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return frostplot.save(fig, os.path.join(to, f"{data.file_stem}_profiles.png"))


def plot_time_depth(data, to):
    """The field along the line at every frame, filled, with the 0 °C line on temperatures."""
    fig, ax = plt.subplots(figsize=(9.0, 5.0))
    values = np.ma.masked_invalid(data.table.T)
    levels, norm = frostplot.colour_scale(float(values.min()), float(values.max()), data.temperature)
    t = data.times / data.divisor
    filled = ax.contourf(t, data.depths, values, levels=levels, norm=norm,
                         cmap="coolwarm" if data.temperature else "viridis", extend="both")
    if data.temperature and values.min() < 0 < values.max():
        ax.contour(t, data.depths, values, levels=[0.0], colors="k", linewidths=1.2)
    fig.colorbar(filled, ax=ax, label=data.label)
    ax.invert_yaxis()
    ax.set(xlabel=f"t [{data.time_name}]", ylabel="depth [m]",
           title=data.title + (" (black: 0 °C)" if data.temperature else ""))
    return frostplot.save(fig, os.path.join(to, f"{data.file_stem}_time_depth.png"))


def plot_line(frames, line, spec, times_text, to, title):
    data = LineData(frames, line, spec, title)
    written = [plot_trumpet(frames, line, data, times_text, to)]
    if len(frames) > 1:  # one frame has no time axis
        written.append(plot_time_depth(data, to))
    return written


def vertical_line(frames, along):
    """The line of the line figures: --along x=X, a column's axis, or None (a 2-D run asked for none)."""
    if along is None:
        return lines.VerticalLine(frames[0]) if lines.line_axis(frames[0]) == 1 else None
    axis, _, value = along.partition("=")
    if axis.strip() != "x":
        raise Refused(f"--along {along}: give a vertical line as x=X (metres), e.g. --along x=0.5")
    try:
        x = float(value)
    except ValueError:
        raise Refused(f"--along {along}: '{value}' is not a number of metres") from None
    try:
        return lines.VerticalLine(frames[0], x)
    except ValueError as error:
        raise Refused(f"--along {along}: {error}") from None


# ---- main ------------------------------------------------------------------------------------


def plot_run_fields(folder, to, title, args):
    if not os.path.exists(os.path.join(folder, "fields.xdmf")):
        return []
    frames = frostplot.read_fields.read_frames(folder)
    if not frames:
        return []
    written = plot_fields(frames, chosen_frame(frames, args.frame, args.time), to, title)
    line = vertical_line(frames, args.along)
    if line is None:
        if args.field or args.times:
            raise Refused("--field and --times draw along a vertical line: give one with --along x=X")
        return written
    return written + plot_line(frames, line, args.field or "temperature", args.times, to, title)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", metavar="OUT", help="run output folder")
    parser.add_argument("--to", metavar="DIR", help="folder for the PNG files (default: OUT)")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--frame", type=int, default=-1, help="fields.h5 frame of fields.png (default: the last)")
    which.add_argument("--time", metavar="T", help="the frame nearest this time instead (30d, 12h, 3600)")
    parser.add_argument("--along", metavar="x=X", help="profiles and time-depth contour along this vertical line")
    parser.add_argument("--field", metavar="NAME", help="field of the line figures (default: temperature)")
    parser.add_argument("--times", metavar="T1,T2", help="times of the profiles (default: six spread over the run)")
    args = parser.parse_args(argv)
    if not os.path.isdir(args.out):
        parser.error(f"{args.out} is not a folder")
    to = args.to or args.out
    os.makedirs(to, exist_ok=True)
    summary = frostplot.run_summary(args.out)
    title = os.path.basename(summary.get("scene", "") or os.path.abspath(args.out))
    models = model_names(summary)
    try:
        written = plot_metrics(args.out, to, title)
        written += plot_freezing_curves(args.out, to, f"{title}: {models}" if models else title)
        written += plot_run_fields(args.out, to, title, args)
    except Refused as error:
        print(f"plot.py: {error}", file=sys.stderr)
        return 2
    for path in written:
        print(f"wrote {path}")
    if not written:
        print(f"plot.py: nothing to plot in {args.out} (no metrics.csv, freezing-curve table or fields.xdmf)",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
