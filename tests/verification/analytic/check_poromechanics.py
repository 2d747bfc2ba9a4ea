#!/usr/bin/python3
"""Independent recomputation of the reference numbers behind poromechanics.hpp.

Runs with Debian's /usr/bin/python3 (numpy + scipy). Every published number is recomputed here
from scratch (brute-force series, scipy root finding, quadrature, an explicit finite-difference
wave solver) and compared with the printed value to half a unit of its last printed digit.
Exit status 1 if any check fails.

Sources: Terzaghi (1943); Mandel (1953), Cheng & Detournay (1988), Abousleiman et al. (1996);
Morgenstern & Nixon (1971); elastic column and vibrating bar: textbook 1-D wave equation.
"""
import sys

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq, minimize_scalar
from scipy.special import erf

failures = []
rows = []


def tol_of(printed: str) -> float:
    """Half a unit in the last printed digit of a decimal or e-notation literal."""
    mant, _, exp = printed.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 0.5 * 10.0 ** (-decimals + (int(exp) if exp else 0))


def check(group, label, value, printed, slack=1e-12):
    ref = float(printed)
    ok = abs(value - ref) <= tol_of(printed) * (1 + 1e-9) + slack
    rows.append((group, label, value, printed, ok))
    if not ok:
        failures.append(f"{group}: {label} = {value!r}, printed {printed}")


def check_close(group, label, value, expected, tol):
    ok = abs(value - expected) <= tol
    rows.append((group, label, value, f"{expected:.10g} (+-{tol:.0e})", ok))
    if not ok:
        failures.append(f"{group}: {label} = {value!r}, expected {expected!r} +- {tol}")


# ------------------------------------------------------------------------------------------------
# 1. Terzaghi: brute-force Fourier series with 200 000 terms (fine down to T_v = 0.008)
# ------------------------------------------------------------------------------------------------
M = np.pi * (2 * np.arange(200_000) + 1) / 2


def terz_U(Tv):
    return 1 - np.sum(2 / M**2 * np.exp(-M**2 * Tv))


def terz_u(z, Tv):
    return np.sum(2 / M * np.sin(M * z) * np.exp(-M**2 * Tv))


for Tv, p in zip([0.008, 0.031, 0.071, 0.126, 0.197, 0.286, 0.5, 0.848, 1.129],
                 ["0.89907", "0.80133", "0.69933", "0.59948", "0.49966", "0.40040", "0.23605",
                  "0.10002", "0.05000"]):
    check("Terzaghi", f"1-U(Tv={Tv})", 1 - terz_U(Tv), p)
for Tv, p in zip([0.05, 0.1, 0.2, 0.5, 1.0], ["0.99687", "0.94931", "0.77231", "0.37078", "0.10798"]):
    check("Terzaghi", f"u/u0(z=H,Tv={Tv})", terz_u(1.0, Tv), p)
for Tv, p in zip([0.01, 0.05, 0.2, 0.5, 1.0], ["0.112838", "0.252313", "0.504088", "0.763950", "0.931260"]):
    check("Terzaghi", f"U(Tv={Tv})", terz_U(Tv), p)
check_close("Terzaghi", "U(0.01) vs 2 sqrt(Tv/pi)", terz_U(0.01), 2 * np.sqrt(0.01 / np.pi), 1e-14)

# ------------------------------------------------------------------------------------------------
# 2. Mandel: roots of sin(a) - K a cos(a) on (n pi, n pi + pi/2), scipy brentq
# ------------------------------------------------------------------------------------------------


def mandel_roots(nu, nu_u, n):
    K = (1 - nu) / (nu_u - nu)
    g = lambda a: np.sin(a) - K * a * np.cos(a)
    return np.array([brentq(g, max(k * np.pi, 1e-9), k * np.pi + np.pi / 2, xtol=1e-15, rtol=1e-15)
                     for k in range(n)])


al = mandel_roots(0.3, 0.5, 40_000)
sa, ca = np.sin(al), np.cos(al)
an = sa / (al - sa * ca)


def p_centre(T):
    return 2 * np.sum(an * (1 - ca) * np.exp(-al**2 * T))


def p_field(xi, T):
    return 2 * np.sum(an * (np.cos(al * xi) - ca) * np.exp(-al**2 * T))


check("Mandel", "alpha_1 (nu=0.3)", al[0], "1.364368")
for T, p in zip([0.01, 0.05, 0.1, 0.2, 0.5, 1.0], ["1.03307", "1.07317", "1.05766", "0.91551", "0.52724", "0.20787"]):
    check("Mandel", f"p(0)/p0 (T={T})", p_centre(T), p)
res = minimize_scalar(lambda T: -p_centre(T), bounds=(0.01, 0.3), method="bounded",
                      options={"xatol": 1e-12})
check("Mandel", "T_peak", res.x, "0.0640")
check("Mandel", "p_peak/p0", -res.fun, "1.07638")
# T -> 0: the partial sums of the T = 0 series oscillate about 1 (mean of two successive sums)
ps = np.cumsum(2 * an * (1 - ca))
check_close("Mandel", "T=0 series (mean of last two partial sums)", 0.5 * (ps[-1] + ps[-2]), 1.0, 1e-4)
check_close("Mandel", "p(0)/p0 at T=1e-6", p_centre(1e-6), 1.0, 5e-4)
# sum a_n cos(a_n) at T = 0 equals (nu_u - nu)/(2(1 - nu_u)) for several Poisson ratios
for nu, nu_u in [(0.3, 0.5), (0.1, 0.5), (0.2, 0.4), (0.0, 0.33)]:
    r = mandel_roots(nu, nu_u, 40_000)
    s0 = np.sum(np.sin(r) * np.cos(r) / (r - np.sin(r) * np.cos(r)))
    check_close("Mandel", f"S0 nu={nu} nu_u={nu_u}", s0, (nu_u - nu) / (2 * (1 - nu_u)), 1e-5)

# Vertical strain: Abousleiman's series against an independent route (sigma_xx = 0, plate force
# balance, mean pressure by quadrature). Compressible case nu = 0.2, nu_u = 0.4, B = 0.8.
for nu, nu_u, B in [(0.3, 0.5, 1.0), (0.2, 0.4, 0.8)]:
    r = mandel_roots(nu, nu_u, 4000)
    sr, cr = np.sin(r), np.cos(r)
    ar = sr / (r - sr * cr)
    G, a, F = 1.0, 1.0, 1.0
    lam = 2 * G * nu / (1 - 2 * nu)
    alphaB = 3 * (nu_u - nu) / (B * (1 - 2 * nu) * (1 + nu_u))
    p0 = B * (1 + nu_u) * F / (3 * a)
    for T in [0.01, 0.1, 0.5]:
        pf = lambda x: p0 * 2 * np.sum(ar * (np.cos(r * x) - cr) * np.exp(-r**2 * T))
        pbar = quad(pf, 0, 1, limit=200, epsabs=1e-13)[0]
        eps_direct = -F * (lam + 2 * G) / (4 * a * G * (lam + G)) + alphaB * pbar / (2 * (lam + G))
        eps_series = F / (G * a) * (-(1 - nu) / 2 + (1 - nu_u) * np.sum(ar * cr * np.exp(-r**2 * T)))
        check_close("Mandel", f"eps_yy nu={nu} nu_u={nu_u} T={T}", eps_series, eps_direct, 1e-10)
        # sigma_yy: Abousleiman's series vs the constitutive law; and its integral = -2F
        for x in [0.0, 0.5, 0.9]:
            syy_series = F / a * (-1 - 2 * (nu_u - nu) / (1 - nu) * np.sum(ar * np.cos(r * x) * np.exp(-r**2 * T))
                                  + 2 * np.sum(ar * cr * np.exp(-r**2 * T)))
            syy_direct = eps_direct * 4 * G * (lam + G) / (lam + 2 * G) - alphaB * pf(x) * 2 * G / (lam + 2 * G)
            check_close("Mandel", f"sigma_yy nu={nu} T={T} x={x}", syy_series, syy_direct, 1e-9)
            # eps_xx from the u_x series (derivative) vs sigma_xx = 0
            dux = F / G * ((nu / (2 * a) - nu_u / a * np.sum(ar * cr * np.exp(-r**2 * T)))
                           + np.sum(cr / (r - sr * cr) * (r / a) * np.cos(r * x) * np.exp(-r**2 * T)))
            exx = (alphaB * pf(x) - lam * eps_direct) / (lam + 2 * G)
            check_close("Mandel", f"eps_xx nu={nu} T={T} x={x}", dux, exx, 1e-9)
# Mandel c for incompressible constituents reduces to kappa E_oed
nu, G = 0.3, 1.0
c_gen = 2 * 1.0 * G * (1 - nu) * 1.5**2 / (9 * 0.5 * (0.5 - nu))
check_close("Mandel", "c(B=1, nu_u=1/2) / (kappa E_oed)", c_gen / (2 * G * (1 - nu) / (1 - 2 * nu)), 1.0, 1e-14)

# ------------------------------------------------------------------------------------------------
# 3. Morgenstern & Nixon: degrees from quadrature of the printed excess pressure
# ------------------------------------------------------------------------------------------------
sw_print = ["0.8889", "0.6667", "0.4706", "0.3333", "0.1818", "0.1111"]
sc_print = ["0.9417", "0.8064", "0.6600", "0.5372", "0.3740", "0.2820"]
for R, psw, psc in zip([0.25, 0.5, 0.75, 1.0, 1.5, 2.0], sw_print, sc_print):
    cv, t, gam, P0 = 1.0, 1.0, 1.0, 1.0
    X = 2 * R * np.sqrt(cv * t)
    A = gam / (1 + 1 / (2 * R**2))
    Bc = P0 / (erf(R) + np.exp(-R**2) / (np.sqrt(np.pi) * R))
    u = lambda x: A * x + Bc * erf(x / (2 * np.sqrt(cv * t)))
    U_sw = 1 - quad(lambda x: A * x, 0, X)[0] / (gam * X**2 / 2)
    U_p0 = 1 - quad(lambda x: Bc * erf(x / (2 * np.sqrt(cv * t))), 0, X, epsabs=1e-14)[0] / (P0 * X)
    check("Thaw", f"U_sw (R={R}) by quadrature", U_sw, psw)
    check("Thaw", f"U_P0 (R={R}) by quadrature", U_p0, psc)
    check_close("Thaw", f"U_sw closed form R={R}", 1 / (1 + 2 * R**2), U_sw, 1e-13)
    check_close("Thaw", f"U_P0 closed form R={R}", 1 / (np.sqrt(np.pi) * R * erf(R) + np.exp(-R**2)), U_p0, 1e-12)
    # the field solves u_t = c_v u_xx, u(0) = 0 and sigma'(X) = (c_v / Xdot) u_x(X)
    alpha_t = 2 * R * np.sqrt(cv)
    uf = lambda x, tt: A * x + Bc * erf(x / (2 * np.sqrt(cv * tt)))
    h, x0 = 1e-4, 0.6 * X
    ut = (uf(x0, t + h) - uf(x0, t - h)) / (2 * h)
    uxx = (uf(x0 + h, t) - 2 * uf(x0, t) + uf(x0 - h, t)) / h**2
    check_close("Thaw", f"PDE residual R={R}", ut - cv * uxx, 0.0, 1e-6)
    ux = (uf(X + h, t) - uf(X - h, t)) / (2 * h)
    Xdot = alpha_t / (2 * np.sqrt(t))
    check_close("Thaw", f"front condition R={R}", (P0 + gam * X - uf(X, t)) - cv / Xdot * ux, 0.0, 1e-7)

# ------------------------------------------------------------------------------------------------
# 3b. Sealed melting (SealedMelting): scipy's adaptive integrator on the same ODE (the header's
#     RK4 must give its pressure, test_pressure_sources.cpp), and its first-order estimate.
# ------------------------------------------------------------------------------------------------
zeta, phi0, c_l = 1 - 917.0 / 1000.0, 0.4, 1e-9
M_sm = 1e8 * 0.7 / (1.3 * 0.4)
sfcc = lambda T: (1 + (917.0 * 3.34e5 / 1e5 * -np.log((T + 273.15) / 273.15)) ** (1 / 0.6)) ** -0.4
S0, S1 = sfcc(-5.0), sfcc(-1.0)


def sealed_rate(S, y):
    phi = 1 - (1 - phi0) * np.exp(-y[0])
    return [-zeta * phi / (1 - zeta * (1 - S) + phi * S * M_sm * c_l)]


sm = solve_ivp(sealed_rate, [S0, S1], [0.0], rtol=1e-12, atol=1e-15)
check("Sealed", "S_l(-5 C), Eq. 25 with lambda 0.4, p0 1e5", S0, "0.0678159")
check("Sealed", "S_l(-1 C)", S1, "0.1979718")
check("Sealed", "p = sigma'_yy = M ln J [Pa] (configs/verification/undrained_warming.yaml)", M_sm * sm.y[0, -1],
      "-619895.5")
check("Sealed", "settlement of 1 m [m]", 1 - np.exp(sm.y[0, -1]), "0.0045944")
Sm = 0.5 * (S0 + S1)
linear = -M_sm * zeta * phi0 * (S1 - S0) / (1 - zeta * (1 - Sm) + phi0 * Sm * M_sm * c_l)
check_close("Sealed", "first-order estimate within 0.5 %", linear / (M_sm * sm.y[0, -1]), 1.0, 5e-3)

# ------------------------------------------------------------------------------------------------
# 4. Elastic column under suddenly applied gravity
# ------------------------------------------------------------------------------------------------
E, nu, rho, H, g = 1e6, 0.3, 2000.0, 1.0, 9.81
Eoed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
s_static = rho * g * H**2 / (2 * Eoed)
cp = np.sqrt(Eoed / rho)
check("Column", "static settlement [m]", s_static, "7.2874e-3")
check("Column", "base stress [kPa]", rho * g * H / 1e3, "19.62")
check("Column", "period 4H/c_p [s]", 4 * H / cp, "0.15418")


def column_series(t, n=4000):
    m = 2 * np.arange(1, n + 1) - 1
    sign = np.where(np.arange(1, n + 1) % 2 == 1, 1.0, -1.0)
    return s_static * (1 - 32 / np.pi**3 * np.sum(sign * np.cos(m * np.pi * cp * t / (2 * H)) / m**3))


def column_closed(t):
    tau = np.fmod(cp * t / H, 4.0)
    tau = 4 - tau if tau > 2 else tau
    return s_static * (tau**2 if tau <= 1 else 2 - (2 - tau) ** 2)


ts = np.linspace(0, 2.5 * 4 * H / cp, 201)
dev = max(abs(column_series(t) - column_closed(t)) for t in ts)
check_close("Column", "series vs piecewise parabola (max |diff|/s)", dev / s_static, 0.0, 1e-9)
check_close("Column", "free fall g t^2/2 at t = 0.5 H/c", column_closed(0.5 * H / cp), 0.5 * g * (0.5 * H / cp) ** 2, 1e-15)
# independent explicit finite-difference solution (leapfrog, 800 cells, CFL 0.5) over one period
nc = 800
dx = H / nc
dt = 0.5 * dx / cp
w = np.zeros(nc + 1)
wold = np.zeros(nc + 1)
nsteps = int(round(4 * H / cp / dt))
hist_dev = 0.0
t = 0.0
for k in range(nsteps):
    lap = np.zeros_like(w)
    lap[1:-1] = (w[2:] - 2 * w[1:-1] + w[:-2]) / dx**2
    lap[-1] = 2 * (w[-2] - w[-1]) / dx**2  # free end, ghost node
    acc = cp**2 * lap + g
    acc[0] = 0.0
    wnew = 2 * w - wold + dt**2 * acc if k > 0 else w + 0.5 * dt**2 * acc
    wold, w = w, wnew
    t += dt
    hist_dev = max(hist_dev, abs(w[-1] - column_closed(t)))
check_close("Column", "FD wave solution vs closed form (max |diff|/s, 800 cells)", hist_dev / s_static, 0.0, 5e-3)

# ------------------------------------------------------------------------------------------------
# 5. Vibrating bar
# ------------------------------------------------------------------------------------------------
L, Eb, rb, v0 = 25.0, 100.0, 1.0, 0.1
w1 = np.pi / (2 * L) * np.sqrt(Eb / rb)
check("Bar", "period [s]", 2 * np.pi / w1, "10.000")
check("Bar", "free-end amplitude v0/omega1 [m]", v0 / w1, "0.159155")

# ------------------------------------------------------------------------------------------------
# 6. Jaumann rate, forward Euler, sign of the spin term
# ------------------------------------------------------------------------------------------------


def euler(n, order=+1):
    omega = np.pi / 4  # unit total time
    Lg = np.array([[0.0, -omega], [omega, 0.0]])  # (grad v)_ij = d v_i / d x_j for v = omega (-y, x)
    W = 0.5 * (Lg - Lg.T)
    s = np.diag([1.0, 0.0])
    h = 1.0 / n
    for _ in range(n):
        s = s + h * order * (W @ s - s @ W)
    return s


Rq = expm(np.array([[0.0, -np.pi / 4], [np.pi / 4, 0.0]]))
exact = Rq @ np.diag([1.0, 0.0]) @ Rq.T
check_close("Jaumann", "exact R sigma0 R^T, xy", exact[0, 1], 0.5, 1e-15)
check_close("Jaumann", "exact R sigma0 R^T, xx", exact[0, 0], 0.5, 1e-15)
for n, p in zip([100, 1000, 10000], ["0.50621", "0.50062", "0.50006"]):
    s = euler(n)
    check("Jaumann", f"sigma_xy Euler n={n}", s[0, 1], p)
    check_close("Jaumann", f"trace Euler n={n}", np.trace(s), 1.0, 1e-12)
check_close("Jaumann", "opposite order sigma + dt(sigma W - W sigma) gives -sigma_xy", euler(100, -1)[0, 1],
            -euler(100)[0, 1], 1e-15)
# closed form of the Euler sequence
for n in [100, 1000, 10000]:
    d = 0.5 * (1 + 2j * (np.pi / 4) / n) ** n
    check_close("Jaumann", f"Euler closed form n={n}", d.imag, euler(n)[0, 1], 1e-12)

# ------------------------------------------------------------------------------------------------
print(f"{'group':9s} {'quantity':60s} {'computed':>22s}  {'printed / expected':24s} ok")
for grp, label, val, printed, ok in rows:
    print(f"{grp:9s} {label:60s} {val:22.12g}  {printed:24s} {'ok' if ok else 'MISMATCH'}")
if failures:
    print(f"\n{len(failures)} mismatch(es):")
    for f in failures:
        print("  " + f)
    sys.exit(1)
print(f"\nall {len(rows)} checks passed")
