#!/usr/bin/env python3
"""Independent reference for a period-doubling bifurcation of the forced backlash gear pair.

Model (1 DOF, the scene format of examples/scenes/gear_backlash.toml):

    x'' + 2 zeta x' + (1 + eps cos W t) g(x) = Fm + Fa cos W t,
    g(x) = x - b (x > b), 0 (|x| <= b), x + b (x < -b),

with zeta = 0.05, eps = 0.4, Fm = 0.3, Fa = 0.05, b = 1 (PARAMS below). The mesh stiffness
varies at W, so near W = 2 (twice the natural frequency 1) lies the principal parametric
(Mathieu) tongue. The period-1 orbit (forced response, x > b throughout, i.e. permanent
contact, so the motion is that of a LINEAR Mathieu-Hill equation) has a real Floquet multiplier
through -1 at both edges of the tongue, W ~ 1.82 and W_pd ~ 2.1654. At the upper edge W_pd the
period-2 branch is born (for W < W_pd) and is stable; it loses contact once per 2T (single-sided
contact loss, x_min < b). Because the in-contact dynamics is linear, the period-2 branch leaves
the period-1 orbit "vertically" at W_pd (a whole segment of in-contact period-2 orbits exists
at W = W_pd exactly) and turns into W < W_pd when it reaches the contact boundary x = b
(softening): for W -> W_pd^- the period-2 orbit tends to the grazing member of that segment
(x_min -> b), its amplitude does NOT tend to zero. There is no period-2 orbit above W_pd (no
hysteresis, checked by time integration) and the period-2 orbit is stable for
1.51 <= W < W_pd at least (continuation in steps of 0.02, not followed further down; below
the lower tongue edge ~1.82 it coexists with the stable period-1 orbit).

Method (nothing here uses hbal; the integrator is reference.py's `integrate`):
* scipy solve_ivp DOP853, restarted exactly at every contact switch |x| = b (terminal,
  direction-filtered events), each contact mode's vector field extended smoothly past the
  switch; variational equations integrated with the state (saltation = identity, the contact
  force is continuous and there is no contact damping);
* W_pd: the period-1 orbit by Newton shooting over T = 2 pi / W, f(W) = min Re(multiplier) + 1
  (continuous through the collision of the complex pair on the negative real axis), zero by
  Brent's method (xtol 1e-12) at rtol 1e-10 and 1e-12;
* the period-2 orbit: reached by plain time integration from the static equilibrium at rest
  (x, x') = (1 + Fm, 0) (the period-1 orbit is unstable there and the motion lands on the
  period-2 attractor), then Newton shooting on P_{2T}(y) = y, 2T = 4 pi / W; of its two phases
  (y and P_T(y)) the one with the larger x(0) is stored (the other has the odd-k Fourier
  coefficients negated; its initial state is stored as well);
* multipliers: eigenvalues of the monodromy over 2T from the variational equations, checked
  against central finite differences of the 2T map;
* Fourier coefficients with respect to the fundamental W/2 from 32768 samples of the dense
  output over 2T: x(t) = a0 + sum_k a_k cos(k W t / 2) + b_k sin(k W t / 2), k <= 16, with
  t = 0 at a maximum of the forcing cos W t (and of the stiffness);
* accuracy: the whole computation (shooting, multipliers, Fourier) is repeated at rtol 1e-10,
  1e-11 and 1e-12 (atol = 1e-3 rtol) and the differences are stored; the Fourier sampling is
  repeated with 16384 samples.

Run `python3 tools/floquet_reference/period2.py` (about 20 s); writes
tests/data/period2/gear_backlash_pd.json.
"""

import json
import math
import os
import sys
import time

import numpy as np
from scipy.optimize import brentq

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from reference import (ENV, Element, Model, Profile, cnum, integrate,  # noqa: E402
                       match_moduli, match_values, multipliers)

OUT = os.path.normpath(os.path.join(HERE, "..", "..", "tests", "data", "period2",
                                    "gear_backlash_pd.json"))

PARAMS = dict(zeta=0.05, eps=0.4, Fm=0.3, Fa=0.05, b=1.0)
W_REF = (2.15, 2.10)          # period-2 references (W_pd - 0.015 and W_pd - 0.065)
RTOLS = (1e-10, 1e-11, 1e-12)
H = 16                        # harmonics of W/2 stored
NSAMP = 32768                 # samples over 2T for the Fourier coefficients
EQUATION = ("x'' + 2 zeta x' + (1 + eps cos(W t)) g(x) = Fm + Fa cos(W t), g(x) = x - b "
            "(x > b), 0 (|x| <= b), x + b (x < -b)")


def model(W):
    p = PARAMS
    el = Element("backlash", [1.0], Profile("cosine", mean=1.0, amplitude=p["eps"]), b=p["b"])
    return Model(f"gear_backlash_pd_W{W}", [[1.0]], [[2 * p["zeta"]]], [[0.0]], W,
                 [(0, 0, p["Fm"], 0.0), (0, 1, p["Fa"], 0.0)], [el], scale=[1.0, 1.0])


def shoot(m, y, rtol, periods=1, tol=1e-13, max_iter=40):
    """Newton shooting on P_{periods T}(y) = y. Returns (y, residual history)."""
    y = np.array(y, dtype=float)
    hist = []
    for _ in range(max_iter):
        fl = integrate(m, y, 0.0, periods * m.T, rtol)
        r = fl.y - y
        hist.append(float(np.max(np.abs(r))))
        if hist[-1] < tol:
            break
        y = y + np.linalg.solve(fl.Phi - np.eye(2), -r)
    else:
        raise RuntimeError(f"shooting did not converge at W = {m.Omega}: {hist[-3:]}")
    return y, hist


def period1(W, rtol, guess=None):
    m = model(W)
    y, _ = shoot(m, [1.0 + PARAMS["Fm"], 0.0] if guess is None else guess, rtol)
    fl = integrate(m, y, 0.0, m.T, rtol)
    return y, multipliers(fl.Phi), len(fl.switches)


def pd_function(W, rtol):
    y, lam, nsw = period1(W, rtol)
    assert nsw == 0, "the period-1 orbit should stay in contact"
    return float(np.min(lam.real)) + 1.0


def settle(m, y, max_periods=4000, rtol=1e-10, tol=1e-11):
    """Plain time integration, compared every 2T; returns (state, 2T-periods used, change)."""
    y = np.array(y, dtype=float)
    d = np.inf
    for k in range(1, max_periods // 2 + 1):
        y1 = integrate(m, y, 0.0, 2 * m.T, rtol, variational=False).y
        d = float(np.max(np.abs(y1 - y)))
        y = y1
        if d < tol:
            return y, 2 * k, d
    return y, max_periods, d


def fourier2(fl, m, N=NSAMP):
    t = np.arange(N) * (2 * m.T) / N
    Y = fl.sample(t)
    c = np.fft.rfft(Y[:, 0]) / N
    a = [float(c[0].real)] + [float(2 * c[k].real) for k in range(1, H + 1)]
    b = [0.0] + [float(-2 * c[k].imag) for k in range(1, H + 1)]
    return np.array(a), np.array(b), Y


def orbit2(W, y_guess, rtol):
    m = model(W)
    y, hist = shoot(m, y_guess, rtol, periods=2)
    # the phase with the larger x(0)
    yT = integrate(m, y, 0.0, m.T, rtol, variational=False).y
    if yT[0] > y[0]:
        y, _ = shoot(m, yT, rtol, periods=2)
        yT = integrate(m, y, 0.0, m.T, rtol, variational=False).y
    fl = integrate(m, y, 0.0, 2 * m.T, rtol, dense=True)
    a, b, Y = fourier2(fl, m)
    return dict(y=y, yT=yT, hist=hist, lam=multipliers(fl.Phi), a=a, b=b, Y=Y, fl=fl, m=m)


def fd_monodromy2(m, y, rtol, h=1e-6):
    J = np.zeros((2, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        yp = integrate(m, y + e, 0.0, 2 * m.T, rtol, variational=False).y
        ym = integrate(m, y - e, 0.0, 2 * m.T, rtol, variational=False).y
        J[:, j] = (yp - ym) / (2 * h)
    return J


def reference_period2(W):
    t0 = time.time()
    m = model(W)
    # period-1 orbit at this W (unstable) and the landing of plain time integration
    y1, lam1, nsw1 = period1(W, 1e-12)
    start = np.array([1.0 + PARAMS["Fm"], 0.0])
    y_land, used, change = settle(m, start)
    res = {}
    guess = y_land
    for rtol in RTOLS:
        res[rtol] = orbit2(W, guess, rtol)
        guess = res[rtol]["y"]
    r = res[1e-12]
    y, lam, Y, fl = r["y"], r["lam"], r["Y"], r["fl"]
    # Fourier with half the samples (aliasing check)
    a_half, b_half, _ = fourier2(fl, m, N=NSAMP // 2)
    Jfd = fd_monodromy2(m, y, 1e-12)
    lam_fd = multipliers(Jfd)
    liou = math.exp(-2 * PARAMS["zeta"] * 2 * m.T)
    x = Y[:, 0]
    bb = PARAMS["b"]
    sw = [{"t": float(s[0]), "from_mode": s[2], "to_mode": s[3], "speed": float(s[4])}
          for s in fl.switches]

    def diffs(r_lo):
        return {
            "state": float(np.max(np.abs(r_lo["y"] - y))),
            "multiplier_complex": match_values(lam, r_lo["lam"]),
            "multiplier_modulus": match_moduli(lam, r_lo["lam"]),
            "fourier": float(max(np.max(np.abs(r_lo["a"] - r["a"])),
                                 np.max(np.abs(r_lo["b"] - r["b"])))),
        }
    out = {
        "W": W,
        "W_minus_W_pd": None,  # filled in by main
        "period_T": m.T,
        "period_2T": 2 * m.T,
        "fundamental_of_fourier": W / 2,
        "initial_state": {"x": float(y[0]), "v": float(y[1])},
        "initial_state_other_phase": {"x": float(r["yT"][0]), "v": float(r["yT"][1]),
                                      "note": "P_T(y0): the same orbit shifted by T = 2 pi / W;"
                                              " its Fourier coefficients are those below with "
                                              "the odd k negated"},
        "fourier": {"cos": [float(v) for v in r["a"]], "sin": [float(v) for v in r["b"]],
                    "convention": "x(t) = cos[0] + sum_{k=1..16} cos[k] cos(k W t / 2) + "
                                  "sin[k] sin(k W t / 2); sin[0] = 0; t = 0 at the maximum of "
                                  "cos(W t)"},
        "max_abs_x": float(np.max(np.abs(x))),
        "min_x": float(np.min(x)),
        "max_x": float(np.max(x)),
        "max_abs_v": float(np.max(np.abs(Y[:, 1]))),
        "mean_x": float(np.mean(x)),
        "regime": {
            "class": "single_sided_impact (contact loss once per 2T, drive flank only)",
            "fraction_of_2T_in_contact": float(np.mean(x > bb)),
            "fraction_of_2T_separated": float(np.mean(np.abs(x) <= bb)),
            "fraction_of_2T_back_contact": float(np.mean(x < -bb)),
            "contact_switches_per_2T": len(sw),
            "switches": sw,
            "min_crossing_speed": float(min(abs(s["speed"]) for s in sw)) if sw else None,
        },
        "distance_to_period1": {
            "max_abs_P_T_minus_identity": float(np.max(np.abs(r["yT"] - y))),
            "note": "|P_T(y0) - y0|: the orbit is genuinely period-2",
        },
        "multipliers": [cnum(z) for z in lam],
        "moduli": [float(abs(z)) for z in lam],
        "stable": bool(np.max(np.abs(lam)) < 1.0),
        "period1_at_same_W": {
            "initial_state": {"x": float(y1[0]), "v": float(y1[1])},
            "multipliers": [cnum(z) for z in lam1],
            "moduli": [float(abs(z)) for z in lam1],
            "stable": bool(np.max(np.abs(lam1)) < 1.0),
            "contact_switches_per_T": nsw1,
        },
        "landing": {
            "from": {"x": float(start[0]), "v": float(start[1])},
            "periods_T_integrated": used,
            "last_change_per_2T": change,
            "distance_to_stored_orbit": float(min(np.max(np.abs(y_land - y)),
                                                  np.max(np.abs(y_land - r["yT"])))),
        },
        "convergence": {
            "rtol_1e-11_vs_1e-12": diffs(res[1e-11]),
            "rtol_1e-10_vs_1e-12": diffs(res[1e-10]),
            "shooting_residual_rtol_1e-12": r["hist"][-1] if r["hist"] else None,
            "newton_history_rtol_1e-12": r["hist"],
            "fourier_16384_vs_32768_samples_max_diff": float(max(
                np.max(np.abs(a_half - r["a"])), np.max(np.abs(b_half - r["b"])))),
            "finite_difference_vs_variational_multiplier_diff": match_values(lam, lam_fd),
            "finite_difference_note": "central differences of the 2T map, step 1e-6, rtol 1e-12",
            "liouville_product_of_multipliers": liou,
            "liouville_relative_diff": float(abs(abs(np.prod(lam)) - liou) / liou),
        },
        "wall_seconds": round(time.time() - t0, 2),
    }
    print(f"  W={W}: x0={y} multipliers {lam} |.|={np.abs(lam)} min x={x.min():.6f} "
          f"period-1 multipliers {lam1}  d(1e-11)={out['convergence']['rtol_1e-11_vs_1e-12']}"
          f"  {out['wall_seconds']}s", flush=True)
    return out


def stable_interval(W_pd, y_start, W_start):
    """Natural continuation of the period-2 orbit down in W (step 0.02) and up to W_pd."""
    rows = []
    y = y_start
    grid_down = [round(W_start - 0.02 * j, 4) for j in range(0, 33)]  # 2.15 .. 1.51
    for W in grid_down:
        m = model(W)
        y, _ = shoot(m, y, 1e-10, periods=2)
        fl = integrate(m, y, 0.0, 2 * m.T, 1e-10, dense=True)
        x = fl.sample(np.linspace(0.0, 2 * m.T, 4096))[:, 0]
        lam = multipliers(fl.Phi)
        rows.append({"W": W, "max_modulus": float(np.max(np.abs(lam))), "min_x": float(x.min()),
                     "max_x": float(x.max()), "multipliers": [cnum(z) for z in lam]})
    y = y_start
    for dW in (0.01, 0.005, 0.002, 0.001, 0.0005, 0.0002):
        W = W_pd - dW
        m = model(W)
        y, _ = shoot(m, y, 1e-10, periods=2)
        fl = integrate(m, y, 0.0, 2 * m.T, 1e-10, dense=True)
        x = fl.sample(np.linspace(0.0, 2 * m.T, 4096))[:, 0]
        lam = multipliers(fl.Phi)
        rows.append({"W": W, "max_modulus": float(np.max(np.abs(lam))), "min_x": float(x.min()),
                     "max_x": float(x.max()), "multipliers": [cnum(z) for z in lam]})
    rows.sort(key=lambda r: r["W"])
    for r in rows:
        print(f"    W={r['W']:.6f} max|mu|={r['max_modulus']:.6f} min x={r['min_x']:.5f}",
              flush=True)
    return rows


def no_hysteresis(W_pd, y2):
    """Above W_pd: time integration from the period-2 orbit of W = 2.15 lands on period 1."""
    out = []
    for dW in (0.002, 0.01):
        W = W_pd + dW
        m = model(W)
        y, used, change = settle(m, y2, max_periods=20000, tol=1e-10)
        y1, lam1, _ = period1(W, 1e-12)
        yT = integrate(m, y, 0.0, m.T, 1e-10, variational=False).y
        out.append({"W": W, "periods_T_integrated": used,
                    "distance_to_period1_orbit": float(np.max(np.abs(y - y1))),
                    "max_abs_P_T_minus_identity": float(np.max(np.abs(yT - y))),
                    "period1_moduli": [float(abs(z)) for z in lam1]})
        print(f"    above W_pd: W={W:.6f} -> distance to period-1 "
              f"{out[-1]['distance_to_period1_orbit']:.2e} after {used} periods", flush=True)
    return out


def accuracy_note(orbits, dWpd):
    def mx(path):
        vals = []
        for o in orbits:
            v = o["convergence"]
            for k in path:
                v = v[k]
            vals.append(v)
        return max(vals)
    return (
        "Everything redone at rtol 1e-10, 1e-11 and 1e-12 (atol 1e-3 rtol). Max over the "
        f"stored orbits, rtol 1e-11 vs 1e-12: state {mx(['rtol_1e-11_vs_1e-12', 'state']):.1e}, "
        f"multipliers (complex) {mx(['rtol_1e-11_vs_1e-12', 'multiplier_complex']):.1e}, "
        f"Fourier coefficients {mx(['rtol_1e-11_vs_1e-12', 'fourier']):.1e}; rtol 1e-10 vs "
        f"1e-12: {mx(['rtol_1e-10_vs_1e-12', 'state']):.1e}, "
        f"{mx(['rtol_1e-10_vs_1e-12', 'multiplier_complex']):.1e}, "
        f"{mx(['rtol_1e-10_vs_1e-12', 'fourier']):.1e}. W_pd: rtol 1e-10 vs 1e-12 "
        f"{dWpd:.1e}. Finite-difference vs variational multipliers "
        f"{mx(['finite_difference_vs_variational_multiplier_diff']):.1e}; Fourier with 16384 "
        f"vs 32768 samples {mx(['fourier_16384_vs_32768_samples_max_diff']):.1e}. So the "
        "states, Fourier coefficients and W_pd are good to ~1e-10, the multipliers to ~1e-9 "
        "(the complex pair's modulus is exactly exp(-zeta 2T) by Liouville, so compare the "
        "complex values); tests can compare to 1e-6.")


def main():
    t0 = time.time()
    p = PARAMS
    print("== W_pd (upper edge of the principal parametric tongue)", flush=True)
    W_pd = {}
    for rtol in (1e-10, 1e-12):
        W_pd[rtol] = brentq(lambda W: pd_function(W, rtol), 2.15, 2.18, xtol=1e-12, rtol=1e-14)
        print(f"  W_pd (rtol {rtol:g}) = {W_pd[rtol]:.12f}", flush=True)
    W_low = brentq(lambda W: pd_function(W, 1e-12), 1.80, 1.85, xtol=1e-12, rtol=1e-14)
    print(f"  lower tongue edge (rtol 1e-12) = {W_low:.12f}", flush=True)
    Wp = W_pd[1e-12]
    around = []
    for W in (Wp - 0.01, Wp, Wp + 0.01):
        y1, lam1, nsw = period1(W, 1e-12)
        around.append({"W": W, "initial_state": {"x": float(y1[0]), "v": float(y1[1])},
                       "multipliers": [cnum(z) for z in lam1],
                       "moduli": [float(abs(z)) for z in lam1],
                       "stable": bool(np.max(np.abs(lam1)) < 1.0),
                       "contact_switches_per_T": nsw})
        print(f"  period-1 at W={W:.6f}: {lam1}", flush=True)
    # where the complex pair of the period-1 orbit collides on the negative real axis
    def disc(W):
        m = model(W)
        y, _ = shoot(m, [1.0 + p["Fm"], 0.0], 1e-12)
        Phi = integrate(m, y, 0.0, m.T, 1e-12).Phi
        return float(np.trace(Phi) ** 2 - 4 * np.linalg.det(Phi))
    W_collide = brentq(disc, Wp, 2.2, xtol=1e-10)
    print(f"  complex pair collides on the negative real axis at W = {W_collide:.8f}", flush=True)

    print("== period-2 references", flush=True)
    orbits = []
    for W in W_REF:
        o = reference_period2(W)
        o["W_minus_W_pd"] = W - Wp
        orbits.append(o)
    print("== stability of the period-2 branch", flush=True)
    y215 = np.array([orbits[0]["initial_state"]["x"], orbits[0]["initial_state"]["v"]])
    branch = stable_interval(Wp, y215, W_REF[0])
    above = no_hysteresis(Wp, y215)

    doc = {
        "model": "gear_backlash",
        "equation": EQUATION,
        "parameters": dict(p),
        "scene": "examples/scenes/gear_backlash_period_doubling.toml (fundamental rad_s = W; "
                 "damping [[2 zeta]], loads order 0 cos Fm and order 1 cos Fa, backlash "
                 "element with half_backlash b and cosine stiffness mean 1, amplitude eps)",
        "W_pd": Wp,
        "W_pd_rtol_1e-10_vs_1e-12": abs(W_pd[1e-10] - Wp),
        "W_pd_note": "period-1 orbit (permanent contact, x > b) real multiplier through -1, "
                     "upper edge of the principal parametric tongue; the period-1 orbit is "
                     "stable for W > W_pd and unstable (multiplier < -1) just below. Located by "
                     "Brent's method on min Re(multiplier) + 1, xtol 1e-12",
        "W_pd_lower_tongue_edge": W_low,
        "W_pd_lower_note": "the other -1 crossing of the period-1 orbit (stable again below); "
                           "there the period-2 orbit coexists with the stable period-1 orbit "
                           "(not a clean supercritical doubling)",
        "period1_complex_pair_collision_W": W_collide,
        "period1_complex_pair_collision_note": "above this W the period-1 multipliers are a "
                                               "complex pair of modulus exp(-zeta T); between "
                                               "W_pd and it they are real and negative, one "
                                               "moving to -1 as W decreases",
        "period1_around_W_pd": around,
        "bifurcation_structure": (
            "The period-1 orbit never loses contact here, so its dynamics and its linearisation "
            "are those of a linear Mathieu-Hill equation: at W = W_pd there is a whole segment "
            "of in-contact period-2 orbits (period-1 orbit + c times the 2T-periodic Floquet "
            "solution), up to the one grazing x = b. The stable period-2 branch exists for "
            "W < W_pd only (softening after contact loss), leaves W_pd from that grazing orbit "
            "(min x -> b as W -> W_pd^-, amplitude does not tend to zero) and loses contact "
            "once per 2T. No period-2 orbit above W_pd (see no_hysteresis_check)."),
        "orbits": orbits,
        "period2_branch_scan": branch,
        "period2_branch_note": "natural continuation (rtol 1e-10) of the stored period-2 "
                               "orbit: stable (complex pair of modulus exp(-zeta 2T)) "
                               "at every W in the scan, 1.51 <= W < W_pd",
        "no_hysteresis_check": above,
        "accuracy": accuracy_note(orbits, abs(W_pd[1e-10] - Wp)),
        "environment": ENV,
        "script": "tools/floquet_reference/period2.py",
        "wall_seconds": round(time.time() - t0, 1),
    }
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"wrote {OUT}", flush=True)


if __name__ == "__main__":
    main()
