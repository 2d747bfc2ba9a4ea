#!/usr/bin/python3
"""Every figure of one FrostMPM run folder, as PNG files.

    /usr/bin/python3 scripts/plot.py OUT [--to DIR] [--frame N]

OUT is a folder `frostmpm run` wrote. Draws what it finds:
  metrics.csv           metrics.png: one panel per probe column against time (s, min, h, d or yr)
  freezing-curve tables <name>.png for each CSV the freezing_curves task wrote (T_degC, S_l, ...):
                        S_l(T), dS_l/dT, k_r(T) (log) and k(T) (log)
  fields.xdmf/.h5       fields.png: every scalar particle field of the last frame (--frame N for
                        another), filled contours in 2D (0 °C isotherm on temperatures), profiles in 1D
The PNGs go into OUT unless --to DIR. Prints one line per file written; exit 1 when OUT holds
nothing to plot. Needs Debian's /usr/bin/python3 (python3-matplotlib, python3-numpy, python3-h5py).
"""
import argparse
import glob
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import frostplot  # noqa: E402
from frostplot import np, plt  # noqa: E402

FREEZING_CURVE_COLUMNS = ("T_degC", "S_l", "dS_l_dT_per_degC", "k_r")
UNITS = {"T": "°C", "dt": "s", "m3": "m³", "m": "m", "Pa": "Pa", "s": "s", "J": "J", "W": "W"}


def grid(n, width=4.2, height=3.0, columns=3):
    cols = min(columns, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


def axis_label(column):
    """'T_center' -> 'T_center [°C]', 'liquid_volume_m3' -> 'liquid_volume [m³]'."""
    head, _, unit = column.rpartition("_")
    if head and unit in UNITS and unit != "T":
        return f"{head} [{UNITS[unit]}]"
    if column.startswith("T_") or column == "T":
        return f"{column} [°C]"
    return column


def plot_metrics(folder, to, title):
    m = frostplot.metrics(folder)
    if "time_s" not in m or len(m["time_s"]) == 0:
        return []
    divisor, unit = frostplot.time_unit(float(m["time_s"].max()))
    t = m["time_s"] / divisor
    columns = [c for c in m if c not in ("time_s", "step")]
    fig, axes = grid(len(columns))
    for ax, column in zip(axes, columns):
        ax.plot(t, m[column], lw=1.2)
        ax.set(xlabel=f"t [{unit}]", ylabel=axis_label(column), title=column)
        ax.grid(alpha=0.3)
    fig.suptitle(title)
    return [frostplot.save(fig, os.path.join(to, "metrics.png"))]


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


def plot_fields(folder, to, title, frame_index):
    if not os.path.exists(os.path.join(folder, "fields.xdmf")):
        return []
    frames = frostplot.read_fields.read_frames(folder)
    if not frames:
        return []
    frame = frames[frame_index]
    names = [n for n, v in frame["fields"].items() if v.ndim == 1]
    if not names:
        return []
    ratio = frostplot.aspect(frame)
    fig, axes = grid(len(names), width=6.0, height=min(6.0, 1.3 + 4.5 * ratio) if ratio else 3.5, columns=2)
    for ax, name in zip(axes, names):
        temperature = name.startswith("temperature")
        frostplot.field_panel(ax, fig, frame, name, cmap="coolwarm" if temperature else "viridis",
                              zero_line=temperature, label=name + (" [°C]" if temperature else ""))
        ax.set_title(name)
    divisor, unit = frostplot.time_unit(frame["time"])
    fig.suptitle(f"{title}: t = {frame['time'] / divisor:.4g} {unit}")
    return [frostplot.save(fig, os.path.join(to, "fields.png"))]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", metavar="OUT", help="run output folder")
    parser.add_argument("--to", metavar="DIR", help="folder for the PNG files (default: OUT)")
    parser.add_argument("--frame", type=int, default=-1, help="fields.h5 frame to draw (default: the last)")
    args = parser.parse_args(argv)
    if not os.path.isdir(args.out):
        parser.error(f"{args.out} is not a folder")
    to = args.to or args.out
    os.makedirs(to, exist_ok=True)
    summary = frostplot.run_summary(args.out)
    title = os.path.basename(summary.get("scene", "") or os.path.abspath(args.out))
    models = model_names(summary)
    written = plot_metrics(args.out, to, title)
    written += plot_freezing_curves(args.out, to, f"{title}: {models}" if models else title)
    written += plot_fields(args.out, to, title, args.frame)
    for path in written:
        print(f"wrote {path}")
    if not written:
        print(f"plot.py: nothing to plot in {args.out} (no metrics.csv, freezing-curve table or fields.xdmf)",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
