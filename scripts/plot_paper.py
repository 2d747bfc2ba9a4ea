#!/usr/bin/python3
"""The paper's thermo-hydraulic figures from FrostMPM runs (Yu et al. 2024, Sec. 5.1, Figs. 3–10).

    /usr/bin/python3 scripts/plot_paper.py inclusion OUT_1 OUT_2 OUT_3 [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py talik OUT_1 OUT_2 OUT_3 [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py contours OUT [--png FILE] [--frame N]

inclusion: global T_min(t) and liquid water volume V_l(t) of the frozen-inclusion cases (Fig. 10,
left), with the 13 INTERFROST codes' thaw-time ranges shaded (VERIFICATION §3).
talik: temperature at the centre point A and the equivalent hydraulic conductivity k_eq(t)
(Fig. 10, right). contours: temperature contours of one frame of fields.h5 with the 0 °C isotherm
(Figs. 3 and 7); the last frame unless --frame. Each OUT is a run folder (metrics.csv, fields.h5).
Needs matplotlib, numpy and h5py (Debian's /usr/bin/python3). Every figure of one run:
scripts/plot.py.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import frostplot  # noqa: E402
from frostplot import metrics, np, plt  # noqa: E402

INTERFROST_H = [(32.4, 41.7), (18.1, 20.7), (10.8, 12.8)]  # thaw time, cases 1–3 (0, 3, 9 %)
LABELS = ["case 1 (0 %)", "case 2 (3 %)", "case 3 (9 %)"]


def two_panels(folders, left, right):
    """T-like curve on the left, its companion on the right, one colour per run; returns the axes
    and the colour of each run."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    colours = []
    for i, folder in enumerate(folders):
        m = metrics(folder)
        t = m["time_s"] / 3600
        line, = a.plot(t, m[left], label=LABELS[i] if i < 3 else folder)
        if right in m:
            b.plot(t, m[right], color=line.get_color())
        colours.append(line.get_color())
    a.axhline(0, color="k", lw=0.5)
    a.legend()
    return fig, a, b, colours


def inclusion(folders, png):
    fig, a, b, colours = two_panels(folders, "T_min", "liquid_volume_m3")
    for i, colour in enumerate(colours[:3]):
        a.axvspan(*INTERFROST_H[i], color=colour, alpha=0.15)
    a.set(xlabel="t [h]", ylabel="global T_min [°C]", title="T_min (shaded: INTERFROST thaw-time ranges)")
    b.axhline(1.0710, color="k", lw=0.5, ls=":")
    b.axhline(1.1100, color="k", lw=0.5, ls=":")
    b.set(xlabel="t [h]", ylabel="liquid water volume [m³ per m]", title="V_l (dotted: 1.0710, 1.1100)")
    frostplot.save(fig, png)


def talik(folders, png):
    fig, a, b, _ = two_panels(folders, "T_center", "k_eq_m_per_s")
    a.set(xlabel="t [h]", ylabel="T at A (0.5, 0.5) [°C]", title="temperature at the centre")
    b.set(xlabel="t [h]", ylabel="k_eq [m/s]", title="equivalent hydraulic conductivity at the outlet")
    frostplot.save(fig, png)


def contours(folder, png, frame):
    fr = frostplot.read_fields.read_frames(folder)[frame]
    fig, ax = plt.subplots(figsize=(9, 9 * frostplot.aspect(fr) + 1))
    frostplot.field_panel(ax, fig, fr, "temperature", levels=np.linspace(-5, 5, 21), zero_line=True, label="T [°C]")
    ax.set(title=f"{folder}: t = {fr['time']:.0f} s (black: 0 °C)")
    frostplot.save(fig, png)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("figure", choices=["inclusion", "talik", "contours"])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--png", help="output file (default: FIGURE.png in the current folder)")
    parser.add_argument("--frame", type=int, default=-1, help="frame for contours (default: the last)")
    args = parser.parse_args()
    png = args.png or f"{args.figure}.png"
    if args.figure == "inclusion":
        inclusion(args.folders, png)
    elif args.figure == "talik":
        talik(args.folders, png)
    else:
        contours(args.folders[0], png, args.frame)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
