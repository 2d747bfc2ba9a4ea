#!/usr/bin/python3
"""Work-precision plot of the Neumann thaw sweep written by bench/neumann_sweep.py.

    /usr/bin/python3 scripts/plot_neumann_sweep.py CSV PNG

Two log-log panels against wall time: profile RMSE of the particle temperature at 1 d, and
|front error| at 1 d. One marker series per scheme (explicit: circles, implicit: squares);
runs on the same cell size are joined by a thin line in order of Δt, the marker size grows as Δx
shrinks, and every point is labelled "Δx [mm]/Δt [s]" (explicit: the mean automatic step).
Skipped runs (status other than "ok") are left out. Needs matplotlib (Agg backend, no display).
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

STYLE = {"explicit": {"marker": "o", "color": "tab:blue"},
         "implicit": {"marker": "s", "color": "tab:orange"}}
CELL_SIZE_MARKER = {0.01: 5, 0.005: 7, 0.0025: 9}   # marker size by Δx (others: 6)


def read(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r.get("status", "ok") != "ok":
                continue
            for key in ("cell_size_m", "cfl", "dt_requested_s", "dt_mean_s", "wall_s", "front_error_m", "rmse_C"):
                r[key] = float(r[key]) if r.get(key) not in (None, "") else math.nan
            rows.append(r)
    if not rows:
        sys.exit(f"plot_neumann_sweep.py: no finished runs in {path}")
    return rows


def label(r):
    """Δx [mm] / Δt [s]; explicit: the mean automatic step."""
    dt = r["dt_mean_s"] if r["scheme"] == "explicit" else r["dt_requested_s"]
    return f"{r['cell_size_m'] * 1000:g}/{dt:.3g}"


def panel(ax, rows, value, ylabel, title):
    for scheme, style in STYLE.items():
        mine = [r for r in rows if r["scheme"] == scheme]
        if not mine:
            continue
        for h in sorted({r["cell_size_m"] for r in mine}, reverse=True):
            line = sorted((r for r in mine if r["cell_size_m"] == h), key=lambda r: r["dt_mean_s"])
            ax.plot([r["wall_s"] for r in line], [value(r) for r in line], "-", color=style["color"],
                    lw=0.8, alpha=0.5)
        for i, r in enumerate(mine):
            ax.plot(r["wall_s"], value(r), linestyle="none", marker=style["marker"], color=style["color"],
                    markersize=CELL_SIZE_MARKER.get(r["cell_size_m"], 6), markeredgecolor="black",
                    markeredgewidth=0.5, label=f"{scheme} (Δx [mm]/Δt [s])" if i == 0 else None)
            ax.annotate(label(r), (r["wall_s"], value(r)), textcoords="offset points",
                        xytext=(5, 2 if scheme == "explicit" else -8), fontsize=7, color=style["color"])
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(loc="lower left", fontsize=8)
    lo, hi = ax.get_xlim()
    ax.set_xlim(lo, hi * 1.6)   # room for the labels on the right


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_neumann_sweep.py CSV PNG")
    rows = read(sys.argv[1])
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2), constrained_layout=True)
    panel(axes[0], rows, lambda r: r["rmse_C"], "profile RMSE at 1 d [°C]",
          "Temperature profile vs two-phase Neumann solution")
    panel(axes[1], rows, lambda r: max(abs(r["front_error_m"]), 1e-6), "|front error| at 1 d [m]",
          "Thaw front (S_l = ½) vs X(1 d) = 2λ√(α_thawed t)")
    fig.suptitle("Neumann thaw (Kurylyk et al. 2014): error against wall time (larger marker = finer Δx)",
                 fontsize=11)
    fig.savefig(sys.argv[2], dpi=130)
    print(f"wrote {sys.argv[2]}")


if __name__ == "__main__":
    main()
