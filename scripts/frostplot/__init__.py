"""Shared helpers for FrostMPM's figure scripts (plot.py, plot_paper.py): matplotlib set-up,
run-folder readers and the panels more than one figure draws.

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
    import matplotlib.pyplot as plt  # noqa: F401  (re-exported)
    import matplotlib.tri as mtri
    import numpy as np
except ImportError as error:  # pragma: no cover - depends on the machine
    sys.exit(f"{os.path.basename(sys.argv[0])}: {error}; run it with Debian's /usr/bin/python3 (python3-matplotlib)")

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import read_fields  # noqa: E402,F401  (re-exported)

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


# ---- axes ----------------------------------------------------------------------------------

TIME_UNITS = [(1.0, "s"), (60.0, "min"), (3600.0, "h"), (86400.0, "d"), (365.25 * 86400.0, "yr")]


def time_unit(seconds):
    """(divisor, name) of the largest unit in which the span `seconds` is at least 2."""
    divisor, name = TIME_UNITS[0]
    for d, n in TIME_UNITS:
        if seconds >= 2 * d:
            divisor, name = d, n
    return divisor, name


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


def field_panel(ax, fig, frame, name, levels=None, cmap="coolwarm", zero_line=False, label=None):
    """One scalar particle field of a fields.h5 frame on axes `ax`: filled contours over the
    particles' Delaunay triangulation (triangles much longer than the particle spacing are
    masked so holes and re-entrant corners stay empty), or a profile line when the particles lie
    on one line. `zero_line` draws the value-0 contour in black (the 0 °C isotherm)."""
    xy = frame["coordinates"]
    x = xy[:, 0]
    y = xy[:, 1] if xy.shape[1] > 1 else np.zeros_like(x)
    v = frame["fields"][name]
    label = label or name
    if np.ptp(y) <= 1e-12 * max(1.0, np.ptp(x)) or len(x) < 3:
        order = np.argsort(x)
        ax.plot(x[order], v[order], ".-", ms=2)
        ax.set(xlabel="x [m]", ylabel=label)
        return
    tri = mtri.Triangulation(x, y)
    edges = np.hypot(x[tri.edges[:, 0]] - x[tri.edges[:, 1]], y[tri.edges[:, 0]] - y[tri.edges[:, 1]])
    longest = np.max(np.hypot(np.diff(x[tri.triangles], axis=1, append=x[tri.triangles][:, :1]),
                              np.diff(y[tri.triangles], axis=1, append=y[tri.triangles][:, :1])), axis=1)
    tri.set_mask(longest > 3 * np.median(edges))
    low, high = float(np.nanmin(v)), float(np.nanmax(v))
    if levels is None and high - low <= 1e-9 * max(1.0, abs(high)):  # a uniform field
        levels = np.linspace(low - 0.5, high + 0.5, 3) if high - low < 1 else 21
    c = ax.tricontourf(tri, v, levels=levels if levels is not None else 21, cmap=cmap, extend="both")
    if zero_line and np.nanmin(v) < 0 < np.nanmax(v):
        ax.tricontour(tri, v, levels=[0.0], colors="k", linewidths=1)
    fig.colorbar(c, ax=ax, label=label)
    ax.set(aspect="equal", xlabel="x [m]", ylabel="y [m]")
