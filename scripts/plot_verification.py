#!/usr/bin/python3
"""Figures of the skeleton's verification scenes against their closed forms.

    /usr/bin/python3 scripts/plot_verification.py terzaghi OUT [OUT ...] [--png FILE]
    /usr/bin/python3 scripts/plot_verification.py mandel OUT [OUT ...] [--png FILE]
    /usr/bin/python3 scripts/plot_verification.py prandtl OUT [OUT ...] [--png FILE]
    /usr/bin/python3 scripts/plot_verification.py reissner OUT [OUT ...] [--png FILE]
    /usr/bin/python3 scripts/plot_verification.py granular OUT [OUT ...] [--png FILE]
    /usr/bin/python3 scripts/plot_verification.py thawing_slope OUT [OUT ...] [--png FILE]

terzaghi: configs/verification/terzaghi_consolidation.yaml runs (any cell sizes): the degree of
consolidation U = settlement / (q H / E_oed) and the base pore pressure against Terzaghi's series
(c_v = 0.1 m²/s, T_v = t / 10 s). mandel: configs/verification/mandel.yaml runs: p(0, t)/p0 at the
centre against Mandel's series for ν = 0.3 (T = t / 50 s), with the Mandel–Cryer overshoot.
prandtl: configs/verification/prandtl_footing.yaml runs: the footing pressure over (2 + π) c
against the settlement in cells, labelled with the cell size and `volumetric_strain`. reissner:
configs/verification/reissner_footing.yaml runs: the footing pressure over c N_c + q0 N_q
(φ = 20°) against the settlement in mm, with the window the test averages. granular:
configs/verification/granular_collapse.yaml runs (any aspect ratio): one panel each, the final
deposit's particles coloured by their plastic deviatoric strain over the column's outline, and
the band of runouts the experiments give (Lube et al. 2005, ±20 %). thawing_slope:
configs/verification/thawing_slope.yaml runs (any slope angle, set by gravity): the slide against
time, labelled with McRoberts and Morgenstern's factor of safety for the run's angle, and the
thawed layer's excess pore pressure over γ′ z cos β at the last frame against Morgenstern and
Nixon's 1 / (1 + 1/(2R²)).
Each OUT is a run folder; the legend shows its cell size from run.json.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import frostplot  # noqa: E402
from frostplot import metrics, np, plt  # noqa: E402


def terzaghi_degree(tv, terms=400):
    m = np.pi * (2 * np.arange(terms) + 1) / 2
    return 1 - np.sum(2 / m[:, None] ** 2 * np.exp(-np.outer(m ** 2, np.atleast_1d(tv))), axis=0)


def terzaghi_base_pressure(tv, terms=400):
    m = np.pi * (2 * np.arange(terms) + 1) / 2
    return np.sum((2 / m * np.sin(m))[:, None] * np.exp(-np.outer(m ** 2, np.atleast_1d(tv))), axis=0)


def mandel_centre(T, nu=0.3, nu_u=0.5, terms=400):
    from scipy.optimize import brentq
    k = (1 - nu) / (nu_u - nu)
    a = np.array([brentq(lambda x: np.sin(x) - k * x * np.cos(x), max(n * np.pi, 1e-9), n * np.pi + np.pi / 2)
                  for n in range(terms)])
    coefficient = np.sin(a) / (a - np.sin(a) * np.cos(a)) * (1 - np.cos(a))
    return 2 * np.sum(coefficient[:, None] * np.exp(-np.outer(a ** 2, np.atleast_1d(T))), axis=0)


def cell_label(folder):
    scene = frostplot.run_summary(folder).get("resolved_scene", {})
    h = scene.get("grid", {}).get("cell_size", [None])[0]
    return f"h = {h:g} m" if h else folder


def terzaghi(folders, png):
    q, oedometric = 1e4, 1e6 * 0.7 / (1.3 * 0.4)
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    tv = np.linspace(1e-4, 1.0, 400)
    a.plot(tv, terzaghi_degree(tv), "k-", lw=1, label="Terzaghi")
    b.plot(tv, terzaghi_base_pressure(tv), "k-", lw=1, label="Terzaghi")
    for folder in folders:
        m = metrics(folder)
        t = m["time_s"] / 10.0
        a.plot(t, m["settlement"] / (q * 1.0 / oedometric), ".", ms=4, label=cell_label(folder))
        b.plot(t, m["p_base"] / q, ".", ms=4, label=cell_label(folder))
    a.set(xlabel="T_v = c_v t / H²", ylabel="U = s / (q H / E_oed)", title="settlement")
    b.set(xlabel="T_v", ylabel="p_base / q", title="pore pressure at the undrained base")
    a.legend()
    b.legend()
    frostplot.save(fig, png)


def mandel(folders, png):
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    T = np.linspace(1e-3, 0.6, 400)
    ax.plot(T, mandel_centre(T), "k-", lw=1, label="Mandel (ν = 0.3)")
    for folder in folders:
        m = metrics(folder)
        ax.plot(m["time_s"] / 50.0, m["p_centre"] / 1e4, ".", ms=4, label=cell_label(folder))
    ax.axhline(1.0, color="k", lw=0.5, ls=":")
    ax.set(xlabel="T = c t / a²", ylabel="p(0, t) / p0", title="Mandel–Cryer effect at the centre")
    ax.legend()
    frostplot.save(fig, png)


def finish_footing(fig, ax, png, closed_form, window, xlabel, title):
    """The closed form's line, the window the test averages, labels; saved to png."""
    ax.axhline(1.0, color="k", lw=0.8, label=closed_form)
    ax.axvspan(*window, color="0.9", label="plateau read")
    ax.set(xlabel=xlabel, ylabel=f"q / {closed_form}", ylim=(0, 1.5), title=title)
    ax.legend(fontsize=8)
    frostplot.save(fig, png)


def prandtl(folders, png):
    q_u = (2 + np.pi) * 1e4
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for folder in folders:
        m = metrics(folder)
        scene = frostplot.run_summary(folder).get("resolved_scene", {})
        h = scene["grid"]["cell_size"][0]
        remedy = scene.get("physics", {}).get("mechanical", {}).get("volumetric_strain", "particle")
        ax.plot(m["footing_displacement"] / h, m["footing_pressure"] / q_u, "-", lw=1, label=f"{cell_label(folder)}, {remedy}")
    finish_footing(fig, ax, png, "(2 + π) c", (0.25, 0.625), "settlement d / h (cells of travel)",
                   "Prandtl's rough strip footing on Tresca soil")


def reissner(folders, png):
    phi = np.radians(20.0)
    n_q = np.exp(np.pi * np.tan(phi)) * np.tan(np.pi / 4 + phi / 2) ** 2
    q_u = 1e4 * (n_q - 1) / np.tan(phi) + 1e4 * n_q
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for folder in folders:
        m = metrics(folder)
        d, q = m["footing_displacement"], m["footing_pressure"] / q_u
        window = (d >= 0.008) & (d <= 0.028)
        line, = ax.plot(1e3 * d, q, "-", lw=1, label=cell_label(folder))
        ax.hlines(q[window].mean(), 8, 28, colors=line.get_color(), linestyles="--", lw=1)
    finish_footing(fig, ax, png, "(c N_c + q0 N_q)", (8, 28), "settlement d [mm] (dashed: the mean read)",
                   "Prandtl–Reissner footing: c = 10 kPa, φ = ψ = 20°, q0 = 10 kPa")


def lube_band(aspect):
    """Runout (L∞ − L0)/L0 of Lube et al. (2005), ±20 %; between their two fits, both."""
    fits = [1.2 * aspect] if aspect < 1.8 else [1.9 * aspect ** (2 / 3)] if aspect > 2.8 else \
        [1.2 * aspect, 1.9 * aspect ** (2 / 3)]
    return 0.8 * min(fits), 1.2 * max(fits)


def deposit_toe(x, bin_width=0.005):
    """Where the deposit's surface meets the base, as tests/verification/test_granular_collapse.cpp
    reads it: the top of the particles in 5 mm columns between 10 % and 50 % of the deposit's
    height beyond its highest column, fitted by a line and extended to zero height. (toe, line)"""
    bins = (x[:, 0] / bin_width).astype(int)
    top = np.zeros(bins.max() + 1)
    np.maximum.at(top, bins, x[:, 1])
    centres = (np.arange(top.size) + 0.5) * bin_width
    beyond = np.arange(top.size) > np.argmax(top)
    used = beyond & (top > 0.1 * top.max()) & (top < 0.5 * top.max())
    slope, intercept = np.polyfit(centres[used], top[used], 1)
    return -intercept / slope, (slope, intercept)


def granular(folders, png):
    runs = []
    for folder in folders:
        frames = frostplot.read_fields.read_frames(folder)
        x0 = frames[0]["coordinates"]
        width, height = x0[:, 0].max() + x0[:, 0].min(), x0[:, 1].max() + x0[:, 1].min()
        runs.append((folder, frames[-1], width, height))
    reach = max(1 + 1.1 * lube_band(h / w)[1] for _, _, w, h in runs)
    fig, axes = plt.subplots(len(runs), 1, figsize=(8, 1.6 * sum(h / w for _, _, w, h in runs) + 1.6 * len(runs)),
                             gridspec_kw={"height_ratios": [h / w for _, _, w, h in runs]}, squeeze=False)
    for ax, (folder, last, width, height) in zip(axes[:, 0], runs):
        x, aspect = last["coordinates"], height / width
        strain = last["fields"]["plastic_deviatoric_strain"]
        dots = ax.scatter(x[:, 0] / width, x[:, 1] / width, c=np.clip(strain, 0, 2), s=1.5, cmap="viridis", vmin=0, vmax=2)
        ax.plot([0, 1, 1], [aspect, aspect, 0], "k--", lw=0.8, label="the column at t = 0")
        toe, (slope, intercept) = deposit_toe(x[:, :2])
        ax.plot([toe / width - 0.5 * aspect, toe / width], [-0.5 * aspect * slope, 0], "r-", lw=1,
                label=f"surface extended: runout {(toe - width) / width:.2f}")
        low, high = lube_band(aspect)
        ax.axvspan(1 + low, 1 + high, color="0.85", zorder=0, label="Lube et al. (2005) ±20 %")
        ax.set(aspect="equal", xlim=(0, reach), ylim=(0, aspect * 1.05))
        ax.set_title(f"a = {aspect:g}, t = {last['time']:g} s, {cell_label(folder)}", fontsize=9)
        ax.set_ylabel("y / L0")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1, 0].set_xlabel("x / L0")
    fig.colorbar(dots, ax=axes[:, 0].tolist(), orientation="horizontal", fraction=0.05, pad=0.12,
                 label="plastic deviatoric strain (clipped at 2)")
    fig.savefig(png, dpi=120)
    plt.close(fig)


def thawing_slope(folders, png, R=0.5):
    """Slide against time; the thawed layer's excess pore pressure ratio against depth. The unit
    weights, the slope and φ′ come from each run's resolved scene; R is the scene's 0.5."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for folder in folders:
        scene = frostplot.run_summary(folder).get("resolved_scene", {})
        soil = scene["materials"]["soil"]
        n, water = soil["porosity"], soil["water_density"]
        density = (1 - n) * soil["solid_density"] + n * water  # saturated
        buoyant = density - water
        top = scene["regions"][0]["shape"]["box"]["max"][1]
        gx, gy = scene["gravity"][:2]
        beta = np.arctan2(gx, -gy)
        phi = np.radians(soil["mechanical_model"]["friction_angle"])
        fs = buoyant / density * np.sin(phi) / ((1 + 2 * R * R) * np.tan(beta))
        label = f"FS = {fs:.2f} (β = {np.degrees(beta):.2f}°), {cell_label(folder)}"
        m = metrics(folder)
        line, = a.plot(m["time_s"] / 3600, 1e3 * m["slide"], "-", lw=1, label=label)
        last = frostplot.read_fields.read_frames(folder)[-1]
        depth = top - last["coordinates"][:, 1]
        thawed = (last["fields"]["liquid_saturation"] > 0.5) & (depth > 0.005)
        g_normal = np.hypot(gx, gy) * np.cos(beta)
        excess = last["fields"]["pore_pressure"] - water * g_normal * depth
        b.plot(excess[thawed] / (buoyant * g_normal * depth[thawed]), 100 * depth[thawed], ".", ms=3,
               color=line.get_color(), label=label)
    b.axvline(1 / (1 + 1 / (2 * R * R)), color="k", lw=0.8, label="Morgenstern & Nixon: 1 / (1 + 1/(2R²))")
    a.set(xlabel="t [h]", ylabel="slide down the slope [mm]", title="the thawed layer's slide")
    b.set(xlabel="excess pore pressure / (γ′ z cos β)", ylabel="depth z [cm]", xlim=(0, 0.6),
          title="thawed layer at the last frame")
    b.invert_yaxis()
    a.legend(fontsize=7)
    b.legend(fontsize=7)
    frostplot.save(fig, png)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("figure", choices=["terzaghi", "mandel", "prandtl", "reissner", "granular",
                                                  "thawing_slope"])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--png", help="output file (default: FIGURE.png)")
    args = parser.parse_args()
    png = args.png or f"{args.figure}.png"
    {"terzaghi": terzaghi, "mandel": mandel, "prandtl": prandtl, "reissner": reissner,
     "granular": granular, "thawing_slope": thawing_slope}[args.figure](args.folders, png)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
