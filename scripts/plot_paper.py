#!/usr/bin/python3
"""The paper's figures from FrostMPM runs (Yu et al. 2024, Secs. 5.1–5.2, Figs. 3–13).

    /usr/bin/python3 scripts/plot_paper.py inclusion OUT_1 OUT_2 OUT_3 [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py talik OUT_1 OUT_2 OUT_3 [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py contours OUT [--png FILE] [--frame N]
    /usr/bin/python3 scripts/plot_paper.py thaw OUT_A OUT_B OUT_C OUT_D [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py mn OUT_R0.5 OUT_R1.5 [more pairs at other cell sizes] [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py rock OUT [OUT_beta0 OUT_beta4.5e-5] [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py stabilization OUT_tau0 OUT_tau0.1 OUT_tau0.5 OUT_tau1 [--png FILE] [--frame N]
    /usr/bin/python3 scripts/plot_paper.py footing_thermal OUT_0.2 OUT_0.1 [OUT_0.05] [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py footing OUT_unthawed OUT_thawing OUT_prethawed [...] [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py slump OUT [--png FILE] [--frame N]
    /usr/bin/python3 scripts/plot_paper.py planar_slump OUT [OUT ...] [--png FILE] [--frame N]
    /usr/bin/python3 scripts/plot_paper.py planar_onset OUT_h1 OUT_h2 [OUT_h3 ...] [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py footing_rates OUT_2 OUT_1 OUT_0.5 OUT_0.25 [--png FILE]
    /usr/bin/python3 scripts/plot_paper.py footing_melt OUT_unthawed OUT_thawing [--frame N]

inclusion: global T_min(t) and liquid water volume V_l(t) of the frozen-inclusion cases (Fig. 10,
left), with the 13 INTERFROST codes' thaw-time ranges shaded (Grenier et al. 2018).
talik: temperature at the centre point A and the equivalent hydraulic conductivity k_eq(t)
(Fig. 10, right). contours: temperature contours of one frame of fields.h5 with the 0 °C isotherm
(Figs. 3 and 7); the last frame unless --frame. thaw: the thaw consolidation of Sec. 5.2.1
(configs/paper/thaw_consolidation.yaml, Tests A–D): settlement and thaw depth against time with
the Neumann estimate and q H/E_oed (Fig. 12B), pore pressure against depth (Fig. 13A) and, for
Test A at 1 h, p/q, S_c and k0/k (Fig. 13B); it writes FILE and FILE with _profiles before the
extension. mn: settlement and excess pore pressure of configs/verification/thaw_consolidation_mn.yaml
against Morgenstern & Nixon's closed form. rock: the rock freezing of Sec. 5.2.2
(configs/paper/rock_freezing.yaml): temperature and radial strain at A and B against time, one
line per run (Fig. 17; the β_s variants by --set), contours of T, S_c, the radial displacement
and p_l at 5, 10 and 15 h (Figs. 15–16, into FILE with _contours), and p_l, S_l and k along the
x axis (Fig. 18, _profiles). stabilization: the pore pressure of runs with τ = 0, 0.1, 0.5, 1
(App. C) at one frame (the last unless --frame). footing_thermal: the thermal mesh study of the
strip footing on thawing ground (Sec. 5.3.2, configs/paper/strip_footing_thermal.yaml): the last
frame's temperature with the −1, 0 and 1 °C lines per mesh (Fig. 24A–C), the temperature at A and B
and the thaw depths against time, one line per mesh (Fig. 24E–F). footing: the THM runs of the
strip footing (configs/paper/strip_footing.yaml): footing pressure against d/B with the
Prandtl–Reissner pressure of the thawed soil (Fig. 27), and each run's plastic deviatoric strain
at its last frame with the −1 and 0 °C lines (Figs. 25–26). slump: the thaw slump of Sec. 5.3.1
(configs/paper/thaw_slump.yaml) at one frame (the last unless --frame): temperature, plastic
deviatoric strain and displacement, each with the thaw front (S_l = ½) and the slope's initial
surface (Figs. 20–22), and the thaw depths and displacements against time. planar_slump: the
planar slope after Harris et al. (2001) (configs/paper/thaw_slump_planar.yaml), one row per run:
plastic deviatoric strain and u_x at one frame, and the thaw depth and movement against time with
the depth at which the infinite-slope factor of safety is 1. planar_onset: the same scene on several
meshes (fields.h5 frames every 0.05 d or so): when the surface point from x = 0.7 m has moved 1 mm,
the depth of ice-free soil (T ≥ 0, where S_l = 1) in the material points' column at x = 0.7 m, against the
cell size, with the first-order extrapolation of the two finest and the infinite slope's limit
depth; the numbers are printed as a table. footing_rates: the
strip footing pushed at different speeds (Sec. 5.3.2, Fig. 28): for each run the plastic deviatoric
strain at d/B = 0.5, 1 and 1.5 with the 0 and −1 °C lines, and the footing pressures against d/B.
footing_melt: no figure; for one frame (the last unless --frame) of an unthawed and a thawing
footing run, the frozen ground under the footing against the sealed closed form (the volume its
meltwater lacks, closed by its skeleton) and the thawed layer's suction against Darcy's estimate.
Each OUT is a run folder (metrics.csv, fields.h5).
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


# ---- thaw consolidation (Sec. 5.2.1) ----------------------------------------------------------

THAW_Q, THAW_H = 5.0e4, 0.1                              # surcharge [Pa], column [m]
THAW_EOED = 4.0e5 * 0.7 / (1.3 * 0.4)                    # E(1 − ν)/((1 + ν)(1 − 2ν)) [Pa]
THAW_TESTS = ["A (reference)", "B (no surcharge)", "C (no phase-change volume term)", "D (constant k)"]


def neumann_front(k_thawed, c_thawed, k_frozen, c_frozen, latent, t_surface, t_initial, t_freeze=0.0):
    """Two-phase Neumann thaw: X(t) = 2λ√(α_u t); returns the function X(t)."""
    from scipy.optimize import brentq
    from scipy.special import erf, erfc
    au, af = k_thawed / c_thawed, k_frozen / c_frozen

    def f(lam):
        return (k_thawed * (t_surface - t_freeze) * np.exp(-lam * lam) / (np.sqrt(au) * erf(lam))
                - k_frozen * (t_freeze - t_initial) * np.exp(-lam * lam * au / af) / (np.sqrt(af) * erfc(lam * np.sqrt(au / af)))
                - lam * latent * np.sqrt(np.pi * au))
    lam = brentq(f, 1e-6, 5.0)
    return lambda t: 2 * lam * np.sqrt(au * np.asarray(t))


def thaw_neumann_estimate():
    """The paper's thermal data (φ 0.4, arithmetic mixing, S_l = 0.0887 at −1 °C from its SFCC),
    a sharp front at 0 °C carrying the latent heat of the ice at −1 °C."""
    phi, s_l = 0.4, 0.0887
    k_t = 0.6 * 1.6 + phi * 0.6
    c_t = 0.6 * 2750 * 720 + phi * 1000 * 4200
    k_f = 0.6 * 1.6 + phi * (s_l * 0.6 + (1 - s_l) * 2.2)
    c_f = 0.6 * 2750 * 720 + phi * (s_l * 1000 * 4200 + (1 - s_l) * 917 * 2060)
    return neumann_front(k_t, c_t, k_f, c_f, phi * (1 - s_l) * 917 * 3.34e5, 20.0, -1.0)


def depth_profile(frame, field, top=THAW_H):
    """(depth below the fixed surface, values of `field`) of a 1-D column, sorted by depth."""
    y = frame["coordinates"][:, 1]
    order = np.argsort(top - y)
    return (top - y)[order], np.asarray(frame["fields"][field])[order]


def frame_at(frames, time):
    return min(frames, key=lambda fr: abs(fr["time"] - time))


def thaw(folders, png):
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for i, folder in enumerate(folders):
        m = metrics(folder)
        a.plot(m["time_s"] / 3600, 1e3 * m["settlement"], label=THAW_TESTS[i] if i < 4 else folder)
        if i == 0:
            b.plot(m["time_s"] / 3600, 1e2 * m["thaw_depth"], label="FrostMPM, Test A")
            t = np.linspace(0, m["time_s"][-1], 200)
            b.plot(t / 3600, 1e2 * thaw_neumann_estimate()(t), "k--", lw=1, label="Neumann estimate (semi-infinite)")
    small = 1e3 * THAW_Q * THAW_H / THAW_EOED
    large = 1e3 * THAW_H * (1 - np.exp(-THAW_Q / THAW_EOED))
    a.axhline(small, color="k", ls=":", lw=1)
    a.axhline(large, color="k", ls="--", lw=1)
    a.text(0.2, small, f" q H/E_oed = {small:.2f} mm (small strain)", va="bottom", fontsize=8)
    a.text(0.2, large, f" H(1 − e^(−q/E_oed)) = {large:.2f} mm (logarithmic strain)", va="top", fontsize=8)
    a.set(xlabel="t [h]", ylabel="settlement [mm]", title="settlement (paper Fig. 12B)")
    a.legend(fontsize=8, loc="center right")
    b.set(xlabel="t [h]", ylabel="thaw depth [cm]", title="0 °C isotherm below the surface")
    b.legend(fontsize=8)
    frostplot.save(fig, png)
    # Fig. 13: pore pressure against depth in Tests A–C, and Test A at 1 h.
    root, ext = os.path.splitext(png)
    fig, axes = plt.subplots(1, 4, figsize=(15, 4.2), sharey=True)
    for i, folder in enumerate(folders[:3]):
        frames = frostplot.read_fields.read_frames(folder)
        for hours in (1, 3, 6, 10):
            fr = frame_at(frames, 3600 * hours)
            d, p = depth_profile(fr, "pore_pressure")
            axes[i].plot(p / THAW_Q, 1e2 * d, label=f"{fr['time'] / 3600:.0f} h")
        axes[i].set(xlabel="p_l / q", title=f"Test {THAW_TESTS[i]}")
        axes[i].legend(fontsize=8)
    axes[0].set(ylabel="depth [cm]")
    axes[0].invert_yaxis()
    fr = frame_at(frostplot.read_fields.read_frames(folders[0]), 3600)
    d, p = depth_profile(fr, "pore_pressure")
    _, s_l = depth_profile(fr, "liquid_saturation")
    _, phi = depth_profile(fr, "porosity")
    # k0/k from the scene's models: van Genuchten–Mualem (m = 0.5) and Kozeny–Carman (φ0 = 0.4).
    m_vg = 0.5
    k_r = np.sqrt(s_l) * (1 - (1 - s_l ** (1 / m_vg)) ** m_vg) ** 2
    kc = phi ** 3 / (1 - phi) ** 2 * (1 - 0.4) ** 2 / 0.4 ** 3
    ax = axes[3]
    ax.plot(p / THAW_Q, 1e2 * d, label="p_l / q")
    ax.plot(1 - s_l, 1e2 * d, label="S_c")
    ax2 = ax.twiny()
    ax2.semilogx(1 / np.maximum(k_r * kc, 1e-30), 1e2 * d, "g", label="k0 / k")
    ax2.set_xlabel("k0 / k", color="g")
    front = 1e2 * float(np.interp(0.0, depth_profile(fr, "temperature")[1][::-1], d[::-1]))
    ax.axhline(front, color="r", ls="--", lw=1)
    ax.set(xlabel="p_l / q, S_c", title="Test A at 1 h (red: thaw front)")
    ax.legend(fontsize=8, loc="lower left")
    frostplot.save(fig, root + "_profiles" + ext)


# ---- Morgenstern–Nixon thaw consolidation ------------------------------------------------------

MN_P0, MN_M, MN_H = 1.0e4, 1.0e6, 0.3


def mn_closed_form(R, x, t, c_v):
    """Excess pore pressure u(x, t) of Morgenstern & Nixon (surcharge P0, no self-weight)."""
    from scipy.special import erf
    return MN_P0 * erf(x / (2 * np.sqrt(c_v * t))) / (erf(R) + np.exp(-R * R) / (np.sqrt(np.pi) * R))


def mn_degree(R):
    from scipy.special import erf
    return 1 / (np.sqrt(np.pi) * R * erf(R) + np.exp(-R * R))


def mn(folders, png):
    alpha = 3.2581e-4  # the scene's two-phase Neumann front constant [m/√s]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    drawn = set()
    for folder in folders:
        summary = frostplot.run_summary(folder)
        scene = summary.get("resolved_scene", {})
        K = scene["materials"]["soil"]["absolute_permeability"]["k0"]
        h = scene["grid"]["cell_size"][0]
        c_v = K * MN_M / 9810.0
        R = alpha / (2 * np.sqrt(c_v))
        m = metrics(folder)
        t = m["time_s"]
        line, = a.plot(t / 3600, 1e3 * m["settlement"], marker=".", ms=3, lw=0.8, label=f"R = {R:.1f}, h = {1e3 * h:g} mm")
        if R not in drawn:
            drawn.add(R)
            a.plot(t / 3600, 1e3 * MN_P0 * alpha * np.sqrt(t) * mn_degree(R) / MN_M, "k--", lw=1)
            tt = t[-1]
            x = np.linspace(0, alpha * np.sqrt(tt), 100)
            b.plot(mn_closed_form(R, x, tt, c_v) / MN_P0, 1e2 * x, "k--", lw=1)
        fr = frostplot.read_fields.read_frames(folder)[-1]
        d, p = depth_profile(fr, "pore_pressure", top=MN_H)
        b.plot(p / MN_P0, 1e2 * d, ".", ms=3, color=line.get_color())
    a.set(xlabel="t [h]", ylabel="settlement [mm]", title="settlement (dashed: Morgenstern & Nixon)")
    a.legend(fontsize=8)
    b.set(xlabel="p_l / P0", ylabel="depth [cm]", title=f"pore pressure at the end (dashed: closed form)")
    b.invert_yaxis()
    frostplot.save(fig, png)


# ---- rock freezing (Sec. 5.2.2) ---------------------------------------------------------------

ROCK_HOLE = 0.023  # hole radius [m]; A and B lie 1 and 4 cm from its wall on the x axis


def rock_label(folder):
    scene = frostplot.run_summary(folder).get("resolved_scene", {})
    beta = scene.get("materials", {}).get("rock", {}).get("solid_thermal_expansion")
    tau = scene.get("physics", {}).get("hydraulic", {}).get("stabilization")
    return f"β_s = {beta:g}/K, τ = {tau:g}" if beta is not None else folder


def rock(folders, png):
    # Row 2: the strain the stress answers to, ε_rr less the grains' free thermal strain — what
    # the paper's code writes as its strain (its particles add −β ΔT to it), so its Fig. 17C–D.
    fig, axes = plt.subplots(3, 2, figsize=(11, 10))
    for folder in folders:
        m = metrics(folder)
        t = m["time_s"] / 3600
        label = rock_label(folder)
        for k, point in enumerate("AB"):
            strain = m[f"radial_strain_{point}"]
            axes[0, k].plot(t, m[f"T_{point}"], label=label)
            axes[1, k].plot(t, 1e6 * strain, label=label)
            axes[2, k].plot(t, 1e6 * (strain - m[f"thermal_strain_{point}"]), label=label)
    for k, (point, d) in enumerate((("A", 1), ("B", 4))):
        for row in range(3):
            axes[row, k].axhline(0, color="k", lw=0.5)
        axes[0, k].set(xlabel="t [h]", ylabel="T [°C]", title=f"temperature at {point} ({d} cm from the wall)")
        axes[1, k].set(xlabel="t [h]", ylabel="ε_rr [10⁻⁶]", title=f"radial strain at {point} (total)")
        axes[2, k].set(xlabel="t [h]", ylabel="ε_rr − thermal strain [10⁻⁶]",
                       title=f"radial strain at {point} less the grains' thermal strain")
    axes[1, 0].legend(fontsize=8)
    frostplot.save(fig, png)
    root, ext = os.path.splitext(png)
    frames = frostplot.read_fields.read_frames(folders[0])
    hours = [h for h in (5, 10, 15) if any(abs(fr["time"] - 3600 * h) < 1 for fr in frames)]
    fig, axes = plt.subplots(len(hours), 4, figsize=(18, 3.2 * len(hours)), squeeze=False)
    for row, h in enumerate(hours):
        fr = frame_at(frames, 3600 * h)
        xy = fr["coordinates"]
        r = np.hypot(xy[:, 0], xy[:, 1])
        u = fr["fields"]["displacement"]
        fr["fields"]["ice_saturation"] = 1 - fr["fields"]["liquid_saturation"]
        fr["fields"]["radial_displacement"] = 1e6 * (u[:, 0] * xy[:, 0] + u[:, 1] * xy[:, 1]) / r
        fr["fields"]["pore_pressure_kPa"] = fr["fields"]["pore_pressure"] / 1e3
        for col, (name, label, cmap, zero) in enumerate((
                ("temperature", "T [°C]", "coolwarm", True), ("ice_saturation", "S_c", "Blues", False),
                ("radial_displacement", "u_r [µm]", "RdBu_r", True), ("pore_pressure_kPa", "p_l [kPa]", "viridis", False))):
            frostplot.field_panel(axes[row, col], fig, fr, name, cmap=cmap, zero_line=zero, label=label)
            axes[row, col].set_title(f"{label} at {h} h")
    frostplot.save(fig, root + "_contours" + ext)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    for h in hours:
        fr = frame_at(frames, 3600 * h)
        xy = fr["coordinates"]
        band = np.abs(xy[:, 1]) < 0.0026  # the particles along the x axis
        d = xy[band, 0] - ROCK_HOLE
        order = np.argsort(d)
        s_l = fr["fields"]["liquid_saturation"][band][order]
        phi = fr["fields"]["porosity"][band][order]
        m_vg = 0.5
        k = 1e-7 * np.sqrt(s_l) * (1 - (1 - s_l ** (1 / m_vg)) ** m_vg) ** 2 * (
            phi ** 3 / (1 - phi) ** 2 * (1 - 0.224) ** 2 / 0.224 ** 3)
        line, = axes[0].plot(1e2 * d[order], fr["fields"]["pore_pressure"][band][order] / 1e3, label=f"{h} h")
        axes[1].plot(1e2 * d[order], s_l, color=line.get_color())
        axes[2].semilogy(1e2 * d[order], np.maximum(k, 1e-30), color=line.get_color())
        temperature = fr["fields"]["temperature"][band][order]
        if temperature.min() < 0 < temperature.max():
            front = 1e2 * float(np.interp(0.0, temperature, d[order]))
            for ax in axes:
                ax.axvline(front, color=line.get_color(), ls="--", lw=0.8)
    axes[0].set(xlabel="distance from the wall d [cm]", ylabel="p_l [kPa]", title="pore pressure (dashed: 0 °C)")
    axes[1].set(xlabel="d [cm]", ylabel="S_l", title="liquid saturation")
    axes[2].set(xlabel="d [cm]", ylabel="k [m/s]", title="hydraulic conductivity (the scene's models)")
    axes[0].legend()
    frostplot.save(fig, root + "_profiles" + ext)


def stabilization(folders, png, frame):
    fig, axes = plt.subplots(1, len(folders), figsize=(4.6 * len(folders), 3.6), squeeze=False)
    frames = [frostplot.read_fields.read_frames(folder)[frame] for folder in folders]
    # One colour scale for every panel, so the oscillations of a small τ show against the others.
    top = max(float(np.nanmax(fr["fields"]["pore_pressure"])) for fr in frames) / 1e3
    levels = np.linspace(min(0.0, min(float(np.nanmin(fr["fields"]["pore_pressure"])) for fr in frames) / 1e3), top, 21)
    for ax, folder, fr in zip(axes[0], folders, frames):
        fr["fields"]["pore_pressure_kPa"] = fr["fields"]["pore_pressure"] / 1e3
        frostplot.field_panel(ax, fig, fr, "pore_pressure_kPa", levels=levels, cmap="viridis", label="p_l [kPa]")
        tau = frostplot.run_summary(folder).get("resolved_scene", {}).get("physics", {}).get("hydraulic", {}).get(
            "stabilization")
        ax.set_title(f"τ = {tau:g}, t = {fr['time'] / 3600:.0f} h" if tau is not None else folder)
        ax.set(xlim=(0, 0.1), ylim=(0, 0.1))
    frostplot.save(fig, png)


# ---- strip footing on thawing ground, thermal preliminary (Sec. 5.3.2) -------------------------

def footing_thermal(folders, png):
    frames = [frostplot.read_fields.read_frames(f)[-1] for f in folders]
    fig, axes = plt.subplots(2, max(len(folders), 2), figsize=(5 * max(len(folders), 2), 8.5))
    for ax, fr, folder in zip(axes[0], frames, folders):
        frostplot.field_panel(ax, fig, fr, "temperature", levels=np.linspace(-5, 15, 21), label="T [°C]")
        x, y = fr["coordinates"][:, 0], fr["coordinates"][:, 1]
        ax.tricontour(x, y, fr["fields"]["temperature"], levels=[-1, 0, 1], colors=["b", "k", "r"], linewidths=1)
        ax.set(title=f"{os.path.basename(folder.rstrip('/'))}: t = {fr['time'] / 86400 / 30.4375:.0f} months")
    a, b = axes[1][0], axes[1][1]
    for folder in folders:
        m = metrics(folder)
        months = m["time_s"] / 86400 / 30.4375
        name = os.path.basename(folder.rstrip("/"))
        line, = a.plot(months, m["T_A"], label=f"{name}: A (0, 3 m)")
        a.plot(months, m["T_B"], color=line.get_color(), ls="--", label=f"{name}: B (0, 1.6 m)")
        line, = b.plot(months, m["thaw_depth_centre"], label=f"{name}: centre line")
        b.plot(months, m["thaw_depth_x6"], color=line.get_color(), ls="--", label=f"{name}: x = 6 m")
    a.axhline(0, color="k", lw=0.5)
    a.set(xlabel="t [months]", ylabel="T [°C]", title="temperature at A and B (Fig. 24E)")
    b.set(xlabel="t [months]", ylabel="thaw depth [m]", title="thaw depth (S_l = 1/2; Fig. 24F)")
    b.invert_yaxis()
    a.legend(fontsize=7)
    b.legend(fontsize=7)
    for ax in axes[1][2:]:
        ax.axis("off")
    frostplot.save(fig, png)


def reissner(c, phi_deg, q0):
    """Prandtl–Reissner bearing pressure c N_c + q0 N_q of a weightless soil (associated flow)."""
    t = np.tan(np.radians(phi_deg))
    n_q = np.exp(np.pi * t) * np.tan(np.radians(45 + phi_deg / 2)) ** 2
    return c * (n_q - 1) / t + q0 * n_q


def footing(folders, png):
    """Resistance against settlement (Fig. 27) and the deviatoric plastic strain of each run's
    last frame with its 0 °C line (Figs. 25–26)."""
    width = 1.2
    n = len(folders)
    fig, axes = plt.subplots(1, n + 1, figsize=(5 * (n + 1), 4.2))
    a = axes[0]
    for folder in folders:
        m = metrics(folder)
        a.plot(m["footing_displacement"] / width, m["footing_pressure"] / 1e3, label=os.path.basename(folder.rstrip("/")))
    for c, style in ((20e3, "--"), (10e3, ":")):
        a.axhline(reissner(c, 30, 20e3) / 1e3, color="k", ls=style, lw=0.8,
                  label=f"Prandtl–Reissner, thawed, c = {c / 1e3:.0f} kPa")
    a.set(xlabel="d / B", ylabel="footing pressure [kPa]", title="resistance (Fig. 27)")
    a.legend(fontsize=7)
    for ax, folder in zip(axes[1:], folders):
        fr = frostplot.read_fields.read_frames(folder)[-1]
        frostplot.field_panel(ax, fig, fr, "plastic_deviatoric_strain", levels=np.linspace(0, 1, 11),
                              label="plastic deviatoric strain")
        x, y = fr["coordinates"][:, 0], fr["coordinates"][:, 1]
        T = fr["fields"]["temperature"]
        if T.min() < 0 < T.max():
            ax.tricontour(x, y, T, levels=[-1, 0], colors=["b", "k"], linewidths=1)
        ax.set(xlim=(0, 5), ylim=(2, 6.4), title=f"{os.path.basename(folder.rstrip('/'))}: t = {fr['time']:.2f} s")
    frostplot.save(fig, png)


def footing_melt(folders, frame):
    """What the thawing ground's melting does under and beside the footing (Sec. 5.3.2): for
    one frame of an unthawed and a thawing run of configs/paper/strip_footing.yaml (fields.h5
    with porosity, liquid_saturation, temperature, pore_pressure, stress and displacement), the
    frozen material points under the footing against their undrained closed form, and the
    thawed layer's suction against Darcy's estimate. Printed, no figure."""
    if len(folders) != 2:
        sys.exit("footing_melt: give two run folders, the unthawed run and the thawing run")
    zeta, phi0 = 1 - 917.0 / 1000.0, 0.4
    k = 1.0e-10 * 2.16e7  # k0 times the scene's transport scaling [m/s]
    unthawed, thawing = (frostplot.read_fields.read_frames(f) for f in folders)
    a, b = unthawed[frame], thawing[frame]
    fa, fb = a["fields"], b["fields"]
    start = b["coordinates"][:, :2] - np.asarray(fb["displacement"])[:, :2]
    same = len(a["coordinates"]) == len(b["coordinates"]) and abs(a["time"] - b["time"]) < 1e-9
    if not same or not np.allclose(start, a["coordinates"][:, :2] - np.asarray(fa["displacement"])[:, :2], atol=1e-9):
        sys.exit("footing_melt: the two frames differ in time or in their material points")
    if b["time"] <= 0:
        sys.exit("footing_melt: pick a frame after the start (--frame 1 or later)")
    S_a, S_b = np.asarray(fa["liquid_saturation"]), np.asarray(fb["liquid_saturation"])
    volume_ratio = lambda f: (1 - phi0) / (1 - np.asarray(f["porosity"]))  # grains keep their volume
    mean_stress = lambda f: np.asarray(f["stress"])[:, :3].mean(axis=1)
    print(f"t = {b['time']:.3f} s")
    under = (start[:, 0] < 0.6) & (start[:, 1] > 4.8) & (S_b < 0.2)
    dS = S_b[under] - S_a[under]
    measured = np.log(volume_ratio(fb)[under] / volume_ratio(fa)[under])
    phi = 1 - (1 - phi0) / volume_ratio(fb)[under]
    sealed = -zeta * phi * dS / (1 - zeta * (1 - S_b[under]))
    print(f"frozen ground under the footing (x0 < 0.6 m, y0 > 4.8 m, S_l < 0.2), {under.sum()} points, medians:")
    print(f"  temperature {np.median(np.asarray(fb['temperature'])[under]):.2f} degC (unthawed run -5), "
          f"S_l {np.median(S_a[under]):.4f} -> {np.median(S_b[under]):.4f}")
    print(f"  ln(J_thawing / J_unthawed) {np.median(measured):.5f}; sealed, incompressible water: "
          f"-zeta phi dS_l / (1 - zeta S_c) {np.median(sealed):.5f} ({np.median(measured) / np.median(sealed):.0%})")
    print(f"  mean effective stress {np.median(mean_stress(fb)[under] - mean_stress(fa)[under]) / 1e3:+.0f} kPa, "
          f"pore pressure {np.median(np.asarray(fb['pore_pressure'])[under] - np.asarray(fa['pore_pressure'])[under]) / 1e3:+.0f} kPa "
          "(thawing minus unthawed)")
    m = metrics(folders[1])
    t, X = m["time_s"], m["thaw_depth_x3"]
    # X dX/dt = d(X²/2)/dt over ±0.05 s (the front steps from cell to cell), or what of that
    # window the run has; dS_l from the initial −5 °C: an upper bound where the ground ahead of
    # the front has already warmed.
    before, after = (int(np.argmin(abs(t - (b["time"] + d)))) for d in (-0.05, 0.05))
    i = int(np.argmin(abs(t - b["time"])))
    x_rate = (X[after] ** 2 - X[before] ** 2) / (2 * (t[after] - t[before]))
    front = -1000 * 9.81 / k * zeta * phi0 * (1 - 0.0678) * x_rate
    thawed = (start[:, 0] > 0.6) & (start[:, 0] < 3) & (start[:, 1] > 4.5) & (S_b > 0.95)
    print(f"thawed layer beside the footing (0.6 < x0 < 3 m, y0 > 4.5 m, S_l > 0.95), {thawed.sum()} points: "
          f"pore pressure median {np.median(np.asarray(fb['pore_pressure'])[thawed]) / 1e3:.0f} kPa, "
          f"mean effective stress median {np.median(mean_stress(fb)[thawed]) / 1e3:.0f} kPa")
    print(f"  Darcy, the meltwater drawn down to the front at x = 3 m: X = {X[i]:.2f} m, X dX/dt = {x_rate:.2f} m2/s, "
          f"p_front = -(rho_l g / k) zeta phi dS_l X dX/dt = {front / 1e3:.0f} kPa (half that mid-layer)")
    print(f"  (dX/dt over {t[before]:.3f} to {t[after]:.3f} s)")


# ---- thaw slump (Sec. 5.3.1) ------------------------------------------------------------------

SLUMP_SURFACE = [(0, 0.455), (0.35, 0.455), (1.1361128709, 0.105), (1.4, 0.105)]  # thaw_slump.yaml


def slump_neumann_estimate():
    """1-D Neumann thaw of the slump's soil (φ 0.4, arithmetic mixing, S_l = 0.042 at −10 °C from
    its SFCC), +10 °C on −10 °C, a sharp front at 0 °C; X(t) with t in days (the run's seconds)."""
    phi, s_l = 0.4, 0.042
    k_t, c_t = 0.6 * 1.0 + phi * 0.6, 0.6 * 2650 * 837 + phi * 1000 * 4200
    k_f = 0.6 * 1.0 + phi * (s_l * 0.6 + (1 - s_l) * 2.2)
    c_f = 0.6 * 2650 * 837 + phi * (s_l * 1000 * 4200 + (1 - s_l) * 917 * 2060)
    front = neumann_front(k_t, c_t, k_f, c_f, phi * (1 - s_l) * 917 * 3.34e5, 10.0, -10.0)
    return lambda days: front(86400.0 * np.asarray(days))


def slump_frame_panel(ax, fig, fr, title, values, levels, cmap, label, surface):
    """One field of a slump frame with the thaw front (S_l = ½, dashed) and the initial surface."""
    frostplot.scalar_panel(ax, fig, fr, np.asarray(values), label, levels=levels, cmap=cmap)
    saturation = np.asarray(fr["fields"]["liquid_saturation"])
    if saturation.min() < 0.5 < saturation.max():  # a front to draw (none once thawed through)
        ax.tricontour(frostplot.triangulation(fr["coordinates"][:, :2]), saturation, levels=[0.5],
                      colors="w" if cmap == "viridis" else "k", linewidths=1.2, linestyles="--")
    surface = np.array(surface)
    ax.plot(surface[:, 0], surface[:, 1], color="0.4", lw=0.8, ls=":")
    ax.set(title=f"{title}, t = {fr['time']:.1f} s ({fr['time']:.1f} days of thaw)")


def slump(folder, png, frame):
    """Temperature, plastic deviatoric strain and displacement of one frame (Figs. 20–22) with the
    thaw front and the initial surface, and the probes against time."""
    fr = frostplot.read_fields.read_frames(folder)[frame]
    x, y = fr["coordinates"][:, 0], fr["coordinates"][:, 1]
    f = fr["fields"]
    u = np.asarray(f["displacement"])
    panels = [("temperature", f["temperature"], np.linspace(-10, 10, 21), "coolwarm", "T [°C]"),
              ("plastic deviatoric strain", f["plastic_deviatoric_strain"], np.linspace(0, 0.25, 11), "viridis",
               "plastic deviatoric strain"),
              ("displacement", np.hypot(u[:, 0], u[:, 1]), None, "viridis", "|u| [m]")]
    fig, axes = plt.subplots(2, 2, figsize=(13, 7.5))
    for ax, (title, values, levels, cmap, label) in zip(axes.flat, panels):
        slump_frame_panel(ax, fig, fr, title, values, levels, cmap, label, SLUMP_SURFACE)
        ax.set(xlim=(0, 1.4), ylim=(0, 0.5))
    if "displacement" in f:
        step = max(1, len(x) // 400)
        axes.flat[2].quiver(x[::step], y[::step], u[::step, 0], u[::step, 1], angles="xy", scale_units="xy", scale=1,
                            width=0.002, color="w")
    m = metrics(folder)
    a = axes.flat[3]
    a.plot(m["time_s"], m["thaw_depth_crest"], label="thaw depth, crest (vertical)")
    a.plot(m["time_s"], m["thaw_depth_face"], label="thaw depth, face middle (normal)")
    a.plot(m["time_s"], slump_neumann_estimate()(m["time_s"]), "k:", label="Neumann, 1-D")
    a.set(xlabel="t [s] = days of thaw", ylabel="depth [m]", title="thaw and movement (dashed: S_l = ½)")
    b = a.twinx()
    b.plot(m["time_s"], m["face_mid_x"], "C2--", label="face middle, u_x")
    b.plot(m["time_s"], m["toe_x"], "C3--", label="toe, u_x")
    b.plot(m["time_s"], -m["crest_edge_y"], "C4--", label="crest edge, settlement")
    b.set(ylabel="displacement [m]")
    lines = a.get_legend_handles_labels()
    more = b.get_legend_handles_labels()
    a.legend(lines[0] + more[0], lines[1] + more[1], fontsize=7, loc="upper left")
    frostplot.save(fig, png)


def planar_slope_geometry(folder):
    """The layer's initial outline (top and free end, in the slope's frame) and the thaw depth at
    which the drained infinite-slope factor of safety of the thawed layer is 1 (ψ = 0, Davis's
    strength c′ cos φ′ and sin φ′: FS(X) = (γ′/γ) sin φ′ / tan β + c′ cos φ′ / (γ X sin β cos β)),
    from the run's resolved scene."""
    scene = frostplot.run_summary(folder)["resolved_scene"]
    (soil,) = scene["materials"].values()  # the scene has one material
    n, water = soil["porosity"], soil["water_density"]
    density = (1 - n) * soil["solid_density"] + n * water
    gx, gy = scene["gravity"][:2]
    beta, g = np.arctan2(gx, -gy), np.hypot(gx, gy)
    model = soil["mechanical_model"]
    phi = np.radians(model["friction_angle"])
    frictional = (density - water) / density * np.sin(phi) / np.tan(beta)
    cohesive = model["cohesion"] * np.cos(phi) / (density * g * np.sin(beta) * np.cos(beta))
    right, top = scene["regions"][0]["shape"]["box"]["max"]
    return [(0, top), (right, top), (right, 0)], cohesive / (1 - frictional)


def planar_slump(folders, png, frame):
    """The planar thaw slump (configs/paper/thaw_slump_planar.yaml), one row per run: plastic
    deviatoric strain and displacement at one frame, in the slope's frame, with the thaw front and
    the initial surface; below, thaw depth and movement against time with the thaw depth at which
    the infinite-slope factor of safety falls to 1."""
    surface, onset_depth = planar_slope_geometry(folders[0])
    fig, axes = plt.subplots(len(folders) + 1, 2, figsize=(15, 2.6 * len(folders) + 3.4), squeeze=False)
    for row, folder in zip(axes[:-1], folders):
        name = os.path.basename(folder.rstrip("/"))
        fr = frostplot.read_fields.read_frames(folder)[frame]
        u = np.asarray(fr["fields"]["displacement"])
        slump_frame_panel(row[0], fig, fr, f"{name}: plastic deviatoric strain", fr["fields"]["plastic_deviatoric_strain"],
                          np.linspace(0, 2, 11), "viridis", "plastic deviatoric strain", surface)
        slump_frame_panel(row[1], fig, fr, f"{name}: u_x (downslope)", u[:, 0], None, "viridis", "u_x [m]", surface)
        for ax in row:
            ax.set(xlim=(0, 3.5), ylim=(0, 0.28))
    a, b = axes[-1]
    for i, folder in enumerate(folders):
        name = os.path.basename(folder.rstrip("/"))
        m = metrics(folder)
        a.plot(m["time_s"], m["thaw_depth_middle"], f"C{i}", label=f"{name}: thaw depth at x = 0.7 m")
        b.plot(m["time_s"], m["surface_middle_x"], f"C{i}", label=f"{name}: surface point from x = 0.7 m")
        b.plot(m["time_s"], m["toe_x"], f"C{i}--", label=f"{name}: top corner of the free end")
    a.axhline(onset_depth, color="k", ls=":", label=f"FS = 1 (infinite slope, drained): {onset_depth:.3f} m")
    a.set(xlabel="t [s] = days of thaw", ylabel="depth [m]", title="thaw depth (S_l = ½)")
    b.set(xlabel="t [s] = days of thaw", ylabel="u_x [m]", title="downslope movement")
    a.legend(fontsize=7)
    b.legend(fontsize=7)
    frostplot.save(fig, png)


def planar_onset(folders, png):
    """Onset of sliding on the planar slope against the cell size: the ice-free depth (the soil the
    layer can slip in: the ice's cohesion acts from the first ice) in the material points' column at
    x = 0.7 m when the surface point above has moved 1 mm downslope."""
    _, limit = planar_slope_geometry(folders[0])
    sizes, depths = [], []
    print("cell [m]  onset [d]  ice-free depth [m]  S_l = 1/2 depth (probe) [m]")
    for folder in folders:
        grid = frostplot.run_summary(folder)["resolved_scene"]["grid"]
        h = grid["cell_size"][0]
        spacing = h / grid["particles_per_cell"]
        m = metrics(folder)
        t, u = np.asarray(m["time_s"]), np.asarray(m["surface_middle_x"])
        i = int(np.nonzero(u >= 1e-3)[0][0])
        onset = t[i - 1] + (t[i] - t[i - 1]) * (1e-3 - u[i - 1]) / (u[i] - u[i - 1])
        times, ice_free = [], []
        for fr in frostplot.read_fields.read_frames(folder):
            start = fr["coordinates"][:, :2] - np.asarray(fr["fields"]["displacement"])[:, :2]
            column = np.abs(start[:, 0] - 0.7) < 0.51 * spacing
            top = start[:, 1].max() + 0.5 * spacing
            order = np.argsort(top - start[column, 1])
            depth = (top - start[column, 1])[order]
            # Ice-free down to T = 0 (the freezing curve holds S_l = 1 above it): the first crossing,
            # linear between the two material points either side of it.
            T = np.asarray(fr["fields"]["temperature"])[column][order]
            k = int(np.nonzero(T < 0)[0][0])
            ice_free.append(0.0 if k == 0 else depth[k - 1] + (depth[k] - depth[k - 1]) * T[k - 1] / (T[k - 1] - T[k]))
            times.append(fr["time"])
        sizes.append(h)
        depths.append(float(np.interp(onset, times, ice_free)))
        probe = float(np.interp(onset, t, m["thaw_depth_middle"]))
        print(f"{h:8.4f}  {onset:9.3f}  {depths[-1]:18.4f}  {probe:27.4f}")
    order = np.argsort(sizes)
    sizes, depths = np.asarray(sizes)[order], np.asarray(depths)[order]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(sizes, depths, "o-", label="ice-free depth when the middle has moved 1 mm")
    if len(sizes) >= 2:
        slope = (depths[1] - depths[0]) / (sizes[1] - sizes[0])
        extrapolated = depths[0] - slope * sizes[0]
        print(f"first-order extrapolation of the two finest: {extrapolated:.4f} m (limit depth {limit:.4f} m)")
        ax.plot([0, sizes[0]], [extrapolated, depths[0]], "k--", lw=1,
                label=f"first order, h → 0: {extrapolated:.3f} m")
    ax.axhline(limit, color="k", ls=":", label=f"FS = 1 (infinite slope, drained): {limit:.3f} m")
    ax.set(xlabel="cell size h [m]", ylabel="depth [m]", xlim=(0, None), ylim=(0, None),
           title="planar slope: onset of sliding against the mesh")
    ax.legend(fontsize=7)
    frostplot.save(fig, png)


def footing_rates(folders, png):
    """Plastic deviatoric strain at d/B = 0.5, 1, 1.5 per run with the 0 and −1 °C lines (Fig. 28),
    and footing pressure against d/B (one line per run)."""
    width, depths = 1.2, (0.5, 1.0, 1.5)
    fig, axes = plt.subplots(len(folders), len(depths) + 1, figsize=(4.2 * (len(depths) + 1), 3.0 * len(folders)),
                             squeeze=False)
    for row, folder in zip(axes, folders):
        name = os.path.basename(folder.rstrip("/"))
        m = metrics(folder)
        frames = frostplot.read_fields.read_frames(folder)
        times = np.array([fr["time"] for fr in frames])
        reached = float(np.max(m["footing_displacement"])) / width
        for ax, target in zip(row[:-1], depths):
            if target > reached + 0.05:  # the run stopped before (a blow-up): say so, draw nothing
                ax.text(0.5, 0.5, f"{name}: stopped at d/B = {reached:.2f}", ha="center", va="center",
                        transform=ax.transAxes)
                ax.set_axis_off()
                continue
            # the frame whose time is nearest to the row where the footing reached target × B
            t = np.interp(target * width, m["footing_displacement"], m["time_s"])
            fr = frames[int(np.argmin(np.abs(times - t)))]
            d = np.interp(fr["time"], m["time_s"], m["footing_displacement"]) / width
            frostplot.field_panel(ax, fig, fr, "plastic_deviatoric_strain", levels=np.linspace(0, 1, 11),
                                  label="plastic deviatoric strain")
            x, y = fr["coordinates"][:, 0], fr["coordinates"][:, 1]
            T = fr["fields"]["temperature"]
            if T.min() < -1 < T.max():
                ax.tricontour(x, y, T, levels=[-1, 0], colors=["r", "r"], linewidths=1, linestyles=["--", "-"])
            ax.set(xlim=(0, 5), ylim=(1.5, 6.6), title=f"{name}: d/B = {d:.2f}")
        row[-1].plot(m["footing_displacement"] / width, m["footing_pressure"] / 1e3)
        row[-1].set(xlabel="d / B", ylabel="footing pressure [kPa]", title=name)
    frostplot.save(fig, png)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("figure", choices=["inclusion", "talik", "contours", "thaw", "mn", "rock", "stabilization",
                                                      "footing_thermal", "footing", "slump", "planar_slump",
                                                      "planar_onset", "footing_rates", "footing_melt"])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--png", help="output file (default: FIGURE.png in the current folder)")
    parser.add_argument("--frame", type=int, default=-1, help="frame for contours (default: the last)")
    args = parser.parse_args()
    png = args.png or f"{args.figure}.png"
    if args.figure == "inclusion":
        inclusion(args.folders, png)
    elif args.figure == "talik":
        talik(args.folders, png)
    elif args.figure == "thaw":
        thaw(args.folders, png)
    elif args.figure == "mn":
        mn(args.folders, png)
    elif args.figure == "rock":
        rock(args.folders, png)
    elif args.figure == "stabilization":
        stabilization(args.folders, png, args.frame)
    elif args.figure == "footing_thermal":
        footing_thermal(args.folders, png)
    elif args.figure == "footing":
        footing(args.folders, png)
    elif args.figure == "slump":
        slump(args.folders[0], png, args.frame)
    elif args.figure == "planar_slump":
        planar_slump(args.folders, png, args.frame)
    elif args.figure == "planar_onset":
        planar_onset(args.folders, png)
    elif args.figure == "footing_rates":
        footing_rates(args.folders, png)
    elif args.figure == "footing_melt":
        footing_melt(args.folders, args.frame)
        return
    else:
        contours(args.folders[0], png, args.frame)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
