"""Shared helpers for FrostMPM's figure scripts (plot.py, plot_paper.py): matplotlib set-up,
run-folder readers and the panels more than one figure draws. `frostplot.units` turns the
recorded units into labels and reads times such as "30d"; `frostplot.lines` finds columns
and follows a field along a vertical line.

Import after `sys.path.insert(0, <scripts folder>)`. Needs Debian's /usr/bin/python3
(python3-matplotlib, python3-numpy; python3-h5py for particle fields).
"""
import csv
import json
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.colors as mcolors
    import matplotlib.pyplot as plt  # noqa: F401  (re-exported)
    import matplotlib.ticker as mticker
    import matplotlib.tri as mtri
    import numpy as np
except ImportError as error:  # pragma: no cover - depends on the machine
    sys.exit(f"{os.path.basename(sys.argv[0])}: {error}; run it with Debian's /usr/bin/python3 (python3-matplotlib)")

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import read_fields  # noqa: E402,F401  (re-exported)

from frostplot import lines, units  # noqa: E402,F401  (re-exported)

DPI = 120

# ---- readers -------------------------------------------------------------------------------


def read_table(path):
    """A CSV file with a header row, as {column: numpy array} in column order (floats)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], [r for r in rows[1:] if r]
    return {name: np.array([float(r[i]) for r in body]) for i, name in enumerate(header)}


def metrics(folder):
    """<folder>/metrics.csv as {column: numpy array}, or {} when there is none."""
    path = os.path.join(folder, "metrics.csv")
    return read_table(path) if os.path.exists(path) else {}


def run_summary(folder):
    """<folder>/run.json, or {} when there is none."""
    try:
        with open(os.path.join(folder, "run.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def metrics_units(folder):
    """{metrics.csv column: unit} from run.json; {} for a run written before units were
    recorded (or still running: run.json is written at its end)."""
    return run_summary(folder).get("metrics_units", {})


# ---- axes ----------------------------------------------------------------------------------


def aspect(frame):
    """Height/width of the particles' bounding box in a fields.h5 frame (0 for a 1D line)."""
    xy = frame["coordinates"]
    width = np.ptp(xy[:, 0])
    return float(np.ptp(xy[:, 1]) / width) if xy.shape[1] > 1 and width > 0 else 0.0


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


# ---- panels ----------------------------------------------------------------------------------


def field_panel(ax, fig, frame, name, levels=None, cmap="coolwarm", zero_line=False, label=None, stretch=False):
    """One scalar particle field of a fields.h5 frame on axes `ax` (see scalar_panel)."""
    return scalar_panel(ax, fig, frame, frame["fields"][name], label or name, levels, cmap, zero_line, stretch)


def scalar_panel(ax, fig, frame, values, label, levels=None, cmap="coolwarm", zero_line=False, stretch=False):
    """Per-particle `values` of a frame on axes `ax`: a profile when the particles form a column
    or layer at most two particles across (nothing to triangulate), else filled contours over
    the particles' Delaunay triangulation (triangles much longer than the particle spacing are
    masked so holes and re-entrant corners stay empty). `zero_line` draws the value-0 contour
    in black (the 0 °C isotherm) and centres the colour map on 0; `stretch` draws x out of
    scale (a tall, narrow domain)."""
    xy = lines.planar(frame)
    axis = lines.line_axis(frame) if len(xy) >= 3 else int(np.ptp(xy[:, 0]) == 0)
    tri = None if axis is not None else triangulation(xy)
    if tri is None:
        profile_panel(ax, xy, [(values, None)], 1 if axis is None else axis, label, zero_line)
        return
    low, high = float(np.nanmin(values)), float(np.nanmax(values))
    levels, norm = colour_scale(low, high, zero_line, levels)
    c = ax.tricontourf(tri, values, levels=levels, cmap=cmap, norm=norm, extend="both")
    if zero_line and low < 0 < high:
        ax.tricontour(tri, values, levels=[0.0], colors="k", linewidths=1)
    fig.colorbar(c, ax=ax, label=label)
    ax.set(aspect="auto" if stretch else "equal", xlabel="x [m] (not to scale)" if stretch else "x [m]",
           ylabel="y [m]")


def colour_scale(low, high, centre_on_zero=False, levels=None):
    """(levels, norm) for filled contours of values from low to high: the given levels, or
    about 20 round ones (three around a uniform value, which has none of its own); with
    `centre_on_zero`, a norm that puts 0 at the colour map's centre (on coolwarm: frozen blue,
    thawed red, also when every value lies on one side)."""
    if levels is None and high - low <= 1e-9 * max(1.0, abs(high)):
        levels = np.linspace(low - 0.5, high + 0.5, 3)
    elif levels is None:
        levels = mticker.MaxNLocator(20).tick_values(low, high)
    if not centre_on_zero:
        return levels, None
    if levels[0] < 0 < levels[-1]:
        return levels, mcolors.TwoSlopeNorm(0.0, levels[0], levels[-1])
    reach = max(abs(levels[0]), abs(levels[-1]))
    return levels, mcolors.Normalize(-reach, reach)


def triangulation(xy):
    """The particles' Delaunay triangulation with over-long triangles masked; None when Qhull
    cannot triangulate them (points too close to a line)."""
    x, y = xy[:, 0], xy[:, 1]
    try:
        tri = mtri.Triangulation(x, y)
    except (RuntimeError, ValueError):
        return None
    edges = np.hypot(x[tri.edges[:, 0]] - x[tri.edges[:, 1]], y[tri.edges[:, 0]] - y[tri.edges[:, 1]])
    corners_x, corners_y = x[tri.triangles], y[tri.triangles]
    longest = np.max(np.hypot(np.diff(corners_x, axis=1, append=corners_x[:, :1]),
                              np.diff(corners_y, axis=1, append=corners_y[:, :1])), axis=1)
    tri.set_mask(longest > 3 * np.median(edges))
    return tri


def profile_panel(ax, xy, series, axis, label, zero_line=False):
    """Values along a column (axis 1: y upwards, values across) or a layer (axis 0: x across):
    `series` is a list of (per-particle values, legend label or None); particles at one
    coordinate are averaged."""
    tol = lines.tolerance(xy)
    for values, name in series:
        where, mean = lines.averaged_along(xy[:, axis], values, tol)
        if axis == 1:
            ax.plot(mean, where, ".-", ms=2, label=name)
        else:
            ax.plot(where, mean, ".-", ms=2, label=name)
    if zero_line:
        (ax.axvline if axis == 1 else ax.axhline)(0.0, color="k", lw=0.6)
    if any(name for _, name in series):
        ax.legend(fontsize=8)
    if axis == 1:
        ax.set(xlabel=label, ylabel="y [m]")
    else:
        ax.set(xlabel="x [m]", ylabel=label)
    ax.grid(alpha=0.3)


def round_number(value):
    """1, 2 or 5 times a power of ten, at most `value` (> 0)."""
    power = 10.0 ** np.floor(np.log10(value))
    return max(m for m in (1, 2, 5) if m * power <= value * (1 + 1e-12)) * power


def arrows(ax, frame, vectors, unit, per_side=20):
    """Arrows of a vector field (its x and y components), averaged over square bins about
    `per_side` to the longer side of the particles' extent, with a key arrow of a round
    magnitude in `unit` above the axes' right end (put the title left). White with a black
    edge, so they show on any colour map. Draws nothing where the field is zero everywhere."""
    xy = lines.planar(frame)
    size = float(np.max(np.ptp(xy, axis=0))) / per_side
    if size <= 0:
        return
    cells = np.floor((xy - xy.min(axis=0)) / size).astype(np.int64)
    _, bin_of = np.unique(cells[:, 0] * (cells[:, 1].max() + 1) + cells[:, 1], return_inverse=True)
    count = np.bincount(bin_of)
    mean = [np.bincount(bin_of, column) / count for column in (xy[:, 0], xy[:, 1], vectors[:, 0], vectors[:, 1])]
    largest = float(np.max(np.hypot(mean[2], mean[3])))
    if not largest > 0:
        return
    q = ax.quiver(*mean, color="w", edgecolor="k", linewidth=0.5, pivot="mid", angles="xy", width=0.005)
    key = round_number(largest)
    shown = units.pretty(unit)
    ax.quiverkey(q, 0.9, 1.04, key, f"{key:g} {shown}" if shown else f"{key:g}", labelpos="W",
                 coordinates="axes", fontproperties={"size": 8})
