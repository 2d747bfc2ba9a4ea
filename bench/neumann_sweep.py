#!/usr/bin/python3
"""Work-precision sweep of the two-phase Neumann thaw (Kurylyk et al. 2014).

    /usr/bin/python3 bench/neumann_sweep.py [--quick] [--out DIR] [--budget S] [--reuse]

Runs configs/verification/neumann_thaw.yaml through the `frostmpm` CLI over a sweep of cell
size Δx and time step Δt, for the explicit scheme (automatic stable step at cfl 0.9, and at
cfl 0.45 on the two coarser grids) and the implicit scheme (fixed Δt = 30, 60, 240, 960 s),
and compares each run at t = 1 d with the analytic two-phase Neumann solution:

  front error   last row of metrics.csv column `half_thawed_depth` (the S_l = ½ contour, the
                centre of the latent release) minus X(1 d) = 2λ√(α_thawed t)
  profile RMSE  particle `temperature` (FLIP/state value) in the last frame of fields.h5
                against T(x, 1 d), depth x = 1.5 − y, over all particles

Prints a fixed-width table, writes DIR/neumann_sweep.csv and keeps every run in DIR/runs/.
For the finest Δx it also prints the explicit particle-steps per second and the wall-time
ratio explicit/implicit at equal-or-better profile RMSE.

Runs go one at a time (never in parallel). Before each run its wall time is predicted from
the same setting on the next coarser grid; a run that would take the total past --budget
seconds is skipped and listed as skipped. --quick keeps only Δx = 0.01 and 0.005 m.
Needs numpy, scipy and h5py (Debian: /usr/bin/python3 with python3-scipy, python3-h5py).
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time

try:
    import h5py
    import numpy as np
    from scipy.optimize import brentq
    from scipy.special import erf, erfc
except ImportError as error:  # pragma: no cover - depends on the machine
    sys.exit(f"neumann_sweep.py: {error}; run it with Debian's /usr/bin/python3 "
             "(python3-numpy, python3-scipy, python3-h5py)")

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = "configs/verification/neumann_thaw.yaml"
LENGTH = 1.5          # column length [m]; surface at y = LENGTH
T_END = 86400.0       # 1 d, the scene's time.end

# ---- analytic two-phase Neumann solution (Kurylyk et al. 2014) -------------------------------
K_THAWED, K_FROZEN = 1.839, 2.619            # W/m/K
C_THAWED, C_FROZEN = 3.20225e6, 2.169e6      # J/m³/K
L_V = 1.67e8                                 # J/m³ (0.5 · 1000 · 334000)
T_S, T_I, T_F = 5.0, -5.0, 0.0               # surface, initial, freezing [°C]
S = -1.0                                     # thawing
A1 = K_THAWED / C_THAWED                     # zone 1 = changed (thawed) phase
A2 = K_FROZEN / C_FROZEN                     # zone 2 = initial (frozen) phase
ALPHA_RATIO = math.sqrt(A1 / A2)


def stefan_residual(lam):
    """Left side minus right side of the transcendental equation of §1.1."""
    lhs = (K_THAWED * (T_F - T_S) * math.exp(-lam * lam) / (math.sqrt(A1) * math.erf(lam))
           - K_FROZEN * (T_I - T_F) * math.exp(-lam * lam * A1 / A2)
           / (math.sqrt(A2) * math.erfc(lam * ALPHA_RATIO)))
    return lhs - S * lam * L_V * math.sqrt(math.pi * A1)


LAMBDA = brentq(stefan_residual, 1e-6, 3.0, xtol=1e-15, rtol=1e-15)


def front(t):
    """Thaw depth X(t) = 2λ√(α_thawed t) [m]."""
    return 2.0 * LAMBDA * math.sqrt(A1 * t)


def temperature(x, t):
    """T(x, t) of the two-phase Neumann solution, depth x ≥ 0 [m], t > 0 [s]."""
    x = np.asarray(x, dtype=float)
    thawed = T_S + (T_F - T_S) * erf(x / (2.0 * np.sqrt(A1 * t))) / math.erf(LAMBDA)
    frozen = T_I + (T_F - T_I) * erfc(x / (2.0 * np.sqrt(A2 * t))) / math.erfc(LAMBDA * ALPHA_RATIO)
    return np.where(x < front(t), thawed, frozen)


def check_reference():
    """The published profile at 1 d (Kurylyk et al. 2014) to its printed 4 decimals."""
    published = {0.02: 3.7925, 0.05: 1.9919, 0.08: 0.2182, 0.10: -0.1629, 0.20: -1.1295,
                 0.30: -2.0082, 0.50: -3.3986}
    for x, value in published.items():
        got = float(temperature(x, T_END))
        if abs(got - value) > 0.6e-4:
            sys.exit(f"neumann_sweep.py: analytic T({x} m, 1 d) = {got:.5f}, published {value}")
    if abs(LAMBDA - 0.18796) > 5e-5:
        sys.exit(f"neumann_sweep.py: λ = {LAMBDA:.6f}, expected 0.18796")


# ---- the sweep --------------------------------------------------------------------------------
IMPLICIT_DT = (960.0, 240.0, 60.0, 30.0)
EXPLICIT_CFL_COARSE = (0.9, 0.45)            # both cfl values on the two coarser grids
EXPLICIT_CFL_FINEST = (0.9,)
FINEST_CELLS = (0.01, 0.005, 0.0025)
QUICK_CELLS = (0.01, 0.005)

# Cost per particle-step [s], used to predict a run that has no coarser counterpart yet
# (measured on the project machine: explicit 0.0025 m ≈ 8 s, implicit 0.0025 m at Δt = 60 s
# ≈ 1.4 s). Otherwise a run is predicted from the same setting on the next coarser grid:
# explicit work grows with particles × steps, (Δx_prev/Δx)³; implicit cost is dominated by the
# nonlinear solve and is scaled by the particle ratio with a 1.5 margin.
PRIOR_COST = {"explicit": 1.2e-7, "implicit": 2.0e-6}


def predict(scheme, h, cfl, dt, previous):
    """Predicted wall seconds; `previous` maps (scheme, setting) to (Δx, wall) of the last run."""
    key = (scheme, cfl if scheme == "explicit" else dt)
    if key in previous:
        h_prev, wall_prev = previous[key]
        return wall_prev * ((h_prev / h) ** 3 if scheme == "explicit" else 1.5 * h_prev / h)
    particles = 4 * round(LENGTH / h)   # 2 × 2 particles per cell, one cell wide
    return particles * predicted_steps(scheme, h, cfl, dt) * PRIOR_COST[scheme]


def plan(cells):
    """(scheme, Δx, cfl or None, Δt or None) in the order they run: coarse to fine."""
    runs = []
    for h in cells:
        for cfl in (EXPLICIT_CFL_FINEST if h == min(FINEST_CELLS) else EXPLICIT_CFL_COARSE):
            runs.append(("explicit", h, cfl, None))
        for dt in IMPLICIT_DT:
            runs.append(("implicit", h, None, dt))
    return runs


def predicted_steps(scheme, h, cfl, dt):
    if scheme == "implicit":
        return math.ceil(T_END / dt)
    # Explicit diffusive limit on the stiffest (frozen) phase: cfl · h² / (2 · dim · α).
    return math.ceil(T_END / (cfl * h * h / (4.0 * A2)))


def tag(scheme, h, cfl, dt):
    return f"{scheme}_h{h:g}_" + (f"cfl{cfl:g}" if scheme == "explicit" else f"dt{dt:g}")


def command(frostmpm, out, scheme, h, cfl, dt):
    n = round(LENGTH / h)
    cmd = [frostmpm, "run", SCENE, "-o", out,
           "--set", f"grid.cells=[1,{n}]",
           "--set", f"grid.cell_size={h:g}",
           "--set", f"regions.0.shape={{box: {{min: [0,0], max: [{h:g}, {LENGTH:g}]}}}}",
           "--set", f"physics.thermal.scheme={scheme}"]
    if scheme == "explicit":
        cmd += ["--set", f"physics.thermal.cfl={cfl:g}"]
    else:
        cmd += ["--set", f"time.dt={dt:g}"]
    return cmd


def evaluate(out):
    """Errors of one finished run directory against the analytic solution at 1 d."""
    with open(os.path.join(out, "run.json")) as f:
        info = json.load(f)
    with open(os.path.join(out, "metrics.csv")) as f:
        rows = list(csv.DictReader(f))
    last = rows[-1]
    if abs(float(last["time_s"]) - T_END) > 1e-6 * T_END:
        raise RuntimeError(f"{out}: last metrics row at t = {last['time_s']} s, not {T_END:g}")
    with h5py.File(os.path.join(out, "fields.h5"), "r") as f:
        frame = max(f.values(), key=lambda g: int(g.attrs["step"]))
        t = float(frame.attrs["time"])
        if abs(t - T_END) > 1e-6 * T_END:
            raise RuntimeError(f"{out}: last field frame at t = {t} s, not {T_END:g}")
        y = frame["coordinates"][:, 1]
        flip = frame["temperature"][:]
        pic = frame["temperature_pic"][:] if "temperature_pic" in frame else None
    exact = temperature(LENGTH - y, T_END)
    X = front(T_END)
    sim_front = float(last["half_thawed_depth"])
    run = info["run"]
    counters = run.get("counters", {})
    return {
        "particles": int(run["particles"]),
        "steps": int(run["steps"]),
        "dt_mean_s": float(run["dt"]["mean"]),
        "wall_s": float(info["wall_seconds"]),
        "front_m": sim_front,
        "front_exact_m": X,
        "front_error_m": sim_front - X,
        "front_error_rel": (sim_front - X) / X,
        "rmse_C": float(np.sqrt(np.mean((flip - exact) ** 2))),
        "rmse_pic_C": float(np.sqrt(np.mean((pic - exact) ** 2))) if pic is not None else float("nan"),
        "max_error_C": float(np.max(np.abs(flip - exact))),
        "nonlinear_iterations": int(counters.get("thermal.nonlinear_iterations_total", 0)),
        "linear_iterations": int(counters.get("thermal.linear_iterations_total", 0)),
        "rejected_halves": int(counters.get("thermal.rejected_substeps", 0)),
    }


COLUMNS = ["scheme", "cell_size_m", "cfl", "dt_requested_s", "dt_mean_s", "steps", "particles",
           "wall_s", "front_m", "front_exact_m", "front_error_m", "front_error_rel", "rmse_C",
           "rmse_pic_C", "max_error_C", "nonlinear_iterations", "linear_iterations", "rejected_halves",
           "status"]


def fmt_row(r):
    setting = f"cfl {r['cfl']:g}" if r["scheme"] == "explicit" else f"dt {r['dt_requested_s']:g}"
    if r["status"] != "ok":
        return f"{r['scheme']:<8} {r['cell_size_m']:>7g} {setting:>9}   {r['status']}"
    return (f"{r['scheme']:<8} {r['cell_size_m']:>7g} {setting:>9} {r['dt_mean_s']:>8.3f} {r['steps']:>7d} "
            f"{r['wall_s']:>8.2f} {r['front_m']:>9.5f} {r['front_error_m']:>+10.5f} "
            f"{100 * r['front_error_rel']:>+7.2f}% {r['rmse_C']:>8.4f} {r['max_error_C']:>8.4f} "
            f"{r['nonlinear_iterations']:>7d} {r['rejected_halves']:>7d}")


HEADER = (f"{'scheme':<8} {'Δx [m]':>7} {'setting':>9} {'Δt [s]':>8} {'steps':>7} {'wall s':>8} "
          f"{'front [m]':>9} {'err [m]':>10} {'rel':>8} {'RMSE °C':>8} {'max °C':>8} {'Newton':>7} {'retried':>7}")


def summary(rows, finest):
    """Lines on the explicit cost and the explicit/implicit wall ratio at the finest Δx."""
    ok = [r for r in rows if r["status"] == "ok" and r["cell_size_m"] == finest]
    ex = [r for r in ok if r["scheme"] == "explicit"]
    im = [r for r in ok if r["scheme"] == "implicit"]
    lines = [f"finest Δx = {finest:g} m"]
    if not ex:
        return lines + ["  no explicit run at the finest Δx"]
    e = min(ex, key=lambda r: r["wall_s"])  # the cfl 0.9 run
    rate = e["particles"] * e["steps"] / e["wall_s"]
    lines.append(f"  explicit cfl {e['cfl']:g}: {e['particles']} particles × {e['steps']} steps / "
                 f"{e['wall_s']:.2f} s = {rate:.3g} particle-steps/s "
                 f"(RMSE {e['rmse_C']:.4f} °C, front error {e['front_error_m']:+.5f} m)")
    for criterion, good in (
            ("profile RMSE ≤ explicit", lambda r: r["rmse_C"] <= e["rmse_C"]),
            ("profile RMSE and |front error| ≤ explicit",
             lambda r: r["rmse_C"] <= e["rmse_C"] and abs(r["front_error_m"]) <= abs(e["front_error_m"]))):
        candidates = [r for r in im if good(r)]
        if not candidates:
            lines.append(f"  {criterion}: no implicit run at this Δx qualifies")
            continue
        i = min(candidates, key=lambda r: r["wall_s"])
        lines.append(f"  {criterion}: fastest implicit is dt {i['dt_requested_s']:g} s, "
                     f"{i['wall_s']:.2f} s (RMSE {i['rmse_C']:.4f} °C, front error {i['front_error_m']:+.5f} m); "
                     f"wall ratio explicit/implicit = {e['wall_s'] / i['wall_s']:.2f}")
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="only Δx = 0.01 and 0.005 m")
    parser.add_argument("--out", default=os.path.join(REPO, "build", "bench", "neumann_sweep"),
                        help="output directory (default build/bench/neumann_sweep)")
    parser.add_argument("--budget", type=float, default=480.0,
                        help="total wall-time budget for the runs [s] (default 480)")
    parser.add_argument("--frostmpm", default=os.environ.get("FROSTMPM", os.path.join(REPO, "build", "bin", "frostmpm")),
                        help="frostmpm executable (default build/bin/frostmpm or $FROSTMPM)")
    parser.add_argument("--reuse", action="store_true",
                        help="re-evaluate existing run directories instead of running them again")
    args = parser.parse_args()

    check_reference()
    if not os.access(args.frostmpm, os.X_OK):
        sys.exit(f"neumann_sweep.py: no executable {args.frostmpm}; build first (cmake --build build)")
    out_dir = os.path.abspath(args.out)
    os.makedirs(os.path.join(out_dir, "runs"), exist_ok=True)
    cells = QUICK_CELLS if args.quick else FINEST_CELLS
    print(f"Neumann thaw, t = 1 d: λ = {LAMBDA:.6f}, X(1 d) = {front(T_END):.6f} m, "
          f"α_thawed = {A1:.6g} m²/s, α_frozen = {A2:.6g} m²/s", flush=True)
    print(HEADER, flush=True)

    previous = {}
    spent = 0.0
    rows = []
    for scheme, h, cfl, dt in plan(cells):
        out = os.path.join(out_dir, "runs", tag(scheme, h, cfl, dt))
        row = {"scheme": scheme, "cell_size_m": h, "cfl": cfl if cfl else float("nan"),
               "dt_requested_s": dt if dt else float("nan"), "status": "ok"}
        reuse = args.reuse and os.path.exists(os.path.join(out, "run.json"))
        guess = predict(scheme, h, cfl, dt, previous)
        if not reuse and spent + guess > args.budget:
            row["status"] = f"skipped (predicted {guess:.0f} s, {spent:.0f} s of {args.budget:.0f} s spent)"
        else:
            if not reuse:
                cmd = command(args.frostmpm, out, scheme, h, cfl, dt)
                shutil.rmtree(out, ignore_errors=True)  # frostmpm refuses to overwrite an earlier run
                start = time.monotonic()
                proc = subprocess.run(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                spent += time.monotonic() - start
                if proc.returncode != 0:
                    sys.stdout.write(proc.stdout)
                    sys.exit(f"neumann_sweep.py: exit {proc.returncode} from: {' '.join(cmd)}")
            row.update(evaluate(out))
            previous[(scheme, cfl if scheme == "explicit" else dt)] = (h, row["wall_s"])
        rows.append(row)
        print(fmt_row(row), flush=True)

    csv_path = os.path.join(out_dir, "neumann_sweep.csv")
    with open(csv_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    print()
    for line in summary(rows, min(cells)):
        print(line)
    print(f"\nwrote {csv_path} (runs in {os.path.join(out_dir, 'runs')}; {spent:.0f} s of runs)")


if __name__ == "__main__":
    main()
