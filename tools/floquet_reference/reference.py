#!/usr/bin/env python3
"""Independent reference periodic orbits and Floquet multipliers for hbal's tests.

Nothing here uses hbal. Every orbit is computed by time integration of the first-order ODE
y = (q, q') with scipy's solve_ivp (DOP853):

* the integration is restarted EXACTLY at every time discontinuity of a stiffness (the
  rectangular mesh profile) and at every contact switch of a backlash element (state events
  u = +-b located by solve_ivp's terminal events, direction-filtered);
* inside each piece the vector field of the current contact mode (extended smoothly past the
  switching surface) is integrated, so no step ever straddles a kink;
* the variational equations Phi' = A(t, mode) Phi are integrated with the state; Phi is reset to
  the identity at every restart and the pieces are multiplied. The models here have no contact
  damping, so the vector field is continuous across a contact switch and the saltation matrix is
  the identity; time-triggered stiffness jumps need no saltation either;
* the periodic orbit is found by Newton shooting on P(y0) - y0 (P the period map, Jacobian
  Phi(T) - I); symmetric orbits of the odd chain can also be found on the half-period map
  G(y) = -P_{T/2}(y) (P_T = G o G);
* the Floquet multipliers are the eigenvalues of the monodromy matrix at the converged orbit.

Each orbit is recomputed at rtol 1e-10 and 1e-12 and the multiplier moduli are compared; the
monodromy matrix is also checked against central finite differences of the period map, and the
linear two-shaft cases against an exact piecewise matrix-exponential solution and Liouville's
formula.

Run `python3 reference.py` (regenerates every file in tests/data/floquet/) or
`python3 reference.py NAME ...` for a subset (see CASES at the bottom).
"""

import json
import math
import os
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp
from scipy.linalg import expm

TAU = 2.0 * math.pi
HERE = os.path.dirname(os.path.abspath(__file__))
OUT_DIR = os.path.normpath(os.path.join(HERE, "..", "..", "tests", "data", "floquet"))


# --------------------------------------------------------------------------------------------
# Model description (mirrors hbal's scene conventions, but is written from the equations)
# --------------------------------------------------------------------------------------------


def frac(x):
    return x - math.floor(x)


class Profile:
    """Stiffness over the mesh angle phi: constant, rectangular (hbal convention: two-tooth
    contact while frac(phi / 2 pi) < contact_ratio - 1) or cosine (mean + amplitude cos phi)."""

    def __init__(self, shape, **p):
        self.shape = shape
        self.p = p

    def jump_fractions(self):
        if self.shape == "rectangular":
            cr = self.p["contact_ratio"]
            if self.p["one_tooth"] != self.p["two_tooth"] and 1.0 < cr < 2.0:
                return [0.0, cr - 1.0]
        return []

    def value(self, phi):
        if self.shape == "constant":
            return self.p["stiffness"]
        if self.shape == "rectangular":
            if frac(phi / TAU) < self.p["contact_ratio"] - 1.0:
                return self.p["two_tooth"]
            return self.p["one_tooth"]
        if self.shape == "cosine":
            return self.p["mean"] + self.p["amplitude"] * math.cos(phi)
        raise ValueError(self.shape)

    def as_dict(self):
        return dict(shape=self.shape, **self.p)


class Element:
    """kind 'mesh': f = k(phi) u + d(phi) u'  (d = beta k or a constant);
    kind 'backlash': f = k(phi) g(u), dead zone of half width b (no contact damping)."""

    def __init__(self, kind, w, profile, teeth=1, phase=0.0, beta=0.0, c=0.0, b=0.0):
        self.kind = kind
        self.w = np.asarray(w, dtype=float)
        self.profile = profile
        self.teeth = teeth
        self.phase = phase
        self.beta = beta
        self.c = c
        self.b = b


class Model:
    """M q'' + D q' + K q + sum_e w_e f_e(theta, w_e.q, w_e.q') = f(t), theta = Omega t,
    loads cos*cos(order Omega t) + sin*sin(order Omega t)."""

    def __init__(self, name, M, D, K, Omega, loads, elements, scale, max_chunk=None):
        self.name = name
        self.M = np.atleast_2d(np.asarray(M, dtype=float))
        self.n = self.M.shape[0]
        self.D = np.atleast_2d(np.asarray(D, dtype=float))
        self.K = np.atleast_2d(np.asarray(K, dtype=float))
        self.Minv = np.linalg.inv(self.M)
        self.Omega = float(Omega)
        self.T = TAU / self.Omega
        self.loads = loads  # list of (dof, order, cos, sin)
        self.elements = elements
        self.backlash = [e for e in elements if e.kind == "backlash"]
        self.scale = np.asarray(scale, dtype=float)  # typical |q_i|, |q'_i| (for atol)
        self.max_chunk = max_chunk  # longest piece (restart Phi = I), for strong decay

    # -- time structure ---------------------------------------------------------------------
    def breakpoints(self, t0, t1):
        """Times in (t0, t1) where a piecewise-constant stiffness jumps."""
        out = []
        for e in self.elements:
            fr = e.profile.jump_fractions()
            if not fr:
                continue
            # phi = teeth Omega t + phase = 2 pi (j + f)
            rate = e.teeth * self.Omega
            jmin = math.floor((rate * t0 + e.phase) / TAU) - 1
            jmax = math.ceil((rate * t1 + e.phase) / TAU) + 1
            for j in range(jmin, jmax + 1):
                for f in fr:
                    t = (TAU * (j + f) - e.phase) / rate
                    if t0 < t < t1:
                        out.append(t)
        return sorted(out)

    def force_vector(self, t):
        f = np.zeros(self.n)
        for dof, order, c, s in self.loads:
            f[dof] += c * math.cos(order * self.Omega * t) + s * math.sin(order * self.Omega * t)
        return f

    # -- contact modes ------------------------------------------------------------------------
    def mode_of(self, y):
        q, v = y[: self.n], y[self.n : 2 * self.n]
        mode = []
        for e in self.backlash:
            u, du = e.w @ q, e.w @ v
            if u > e.b or (u == e.b and du > 0):
                mode.append(1)
            elif u < -e.b or (u == -e.b and du < 0):
                mode.append(-1)
            else:
                mode.append(0)
        return tuple(mode)

    def piece_field(self, t_mid, mode):
        """The affine field y' = A(t) y + c(t) of one piece (between two restarts), as a
        function returning (A, c). Piecewise-constant stiffnesses are frozen at t_mid."""
        n = self.n
        Kc, Dc = self.K.copy(), self.D.copy()
        fc = np.zeros(n)
        varying = []  # (w w^T, beta-or-0, s b w, element) with k(t) = cosine profile
        bi = 0
        for e in self.elements:
            ww = np.outer(e.w, e.w)
            if e.kind == "backlash":
                s = mode[bi]
                bi += 1
                if s == 0:
                    continue
                offset = s * e.b * e.w  # force k (u - s b): + k s b w on the right side
                beta, cdamp = 0.0, 0.0
            else:
                offset = np.zeros(n)
                beta, cdamp = e.beta, e.c
            Dc += cdamp * ww
            if e.profile.shape == "cosine":
                varying.append((ww, beta, offset, e))
            else:
                k = e.profile.value(e.teeth * self.Omega * t_mid + e.phase)
                Kc += k * ww
                Dc += beta * k * ww
                fc += k * offset
        Minv = self.Minv
        A0 = np.zeros((2 * n, 2 * n))
        A0[:n, n:] = np.eye(n)
        A0[n:, :n] = -Minv @ Kc
        A0[n:, n:] = -Minv @ Dc
        c0 = np.concatenate([np.zeros(n), Minv @ fc])
        vparts = []
        for ww, beta, offset, e in varying:
            Ae = np.zeros((2 * n, 2 * n))
            Ae[n:, :n] = -Minv @ ww
            Ae[n:, n:] = -beta * (Minv @ ww)
            ce = np.concatenate([np.zeros(n), Minv @ offset])
            vparts.append((Ae, ce, e.profile.p["mean"], e.profile.p["amplitude"],
                           e.teeth * self.Omega, e.phase))
        lparts = []
        for dof, order, c, s in self.loads:
            g = np.zeros(2 * n)
            g[n:] = Minv[:, dof]
            lparts.append((g, order * self.Omega, c, s))

        def field(t):
            A = A0
            c = c0
            if vparts:
                A = A0.copy()
                c = c0.copy()
                for Ae, ce, mean, amp, rate, ph in vparts:
                    k = mean + amp * math.cos(rate * t + ph)
                    A += k * Ae
                    c += k * ce
            else:
                c = c0.copy()
            for g, w, cc, ss in lparts:
                c += (cc * math.cos(w * t) + ss * math.sin(w * t)) * g
            return A, c

        return field


# --------------------------------------------------------------------------------------------
# Piecewise integration with restarts
# --------------------------------------------------------------------------------------------


class Flow:
    """Result of integrating from t0 to t1: end state, monodromy and the dense pieces."""

    def __init__(self, y, Phi, pieces, switches, nfev):
        self.y, self.Phi, self.pieces, self.switches, self.nfev = y, Phi, pieces, switches, nfev

    def sample(self, times):
        m = len(self.pieces[0][3](self.pieces[0][0]))
        out = np.empty((len(times), m))
        starts = np.array([p[0] for p in self.pieces])
        idx = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(self.pieces) - 1)
        for i, t in enumerate(times):
            out[i] = self.pieces[idx[i]][3](t)
        return out


def integrate(model, y0, t0, t1, rtol, variational=True, dense=False, max_switches=100000):
    n2 = 2 * model.n
    y = np.array(y0, dtype=float)
    Phi = np.eye(n2)
    atol_y = 1e-3 * rtol * model.scale
    atol_P = (1e-3 * rtol * np.outer(model.scale, 1.0 / model.scale)).ravel()
    atol = np.concatenate([atol_y, atol_P]) if variational else atol_y
    bounds = [t0] + model.breakpoints(t0, t1) + [t1]
    if model.max_chunk:
        fine = [t0]
        for a, b in zip(bounds[:-1], bounds[1:]):
            m = max(1, math.ceil((b - a) / model.max_chunk))
            fine += [a + (b - a) * (j + 1) / m for j in range(m)]
            fine[-1] = b
        bounds = fine
    pieces, switches, nfev = [], [], 0
    mode = model.mode_of(y)
    eye_flat = np.eye(n2).ravel()
    for ta, tb in zip(bounds[:-1], bounds[1:]):
        t = ta
        while tb - t > 1e-13 * model.T:
            field = model.piece_field(0.5 * (t + tb), mode)
            if variational:
                def rhs(tt, Y, field=field):
                    A, c = field(tt)
                    dy = A @ Y[:n2] + c
                    dP = A @ Y[n2:].reshape(n2, n2)
                    return np.concatenate([dy, dP.ravel()])
                Y0 = np.concatenate([y, eye_flat])
            else:
                def rhs(tt, Y, field=field):
                    A, c = field(tt)
                    return A @ Y + c
                Y0 = y
            events = []
            for i, (e, s) in enumerate(zip(model.backlash, mode)):
                w, b = e.w, e.b
                if s >= 0:  # leaving u > b downwards, or reaching u = b upwards
                    ev = (lambda tt, Y, w=w, b=b: w @ Y[: model.n] - b)
                    ev.terminal, ev.direction = True, (-1.0 if s == 1 else 1.0)
                    events.append((ev, i, +1))
                if s <= 0:
                    ev = (lambda tt, Y, w=w, b=b: w @ Y[: model.n] + b)
                    ev.terminal, ev.direction = True, (1.0 if s == -1 else -1.0)
                    events.append((ev, i, -1))
            sol = solve_ivp(rhs, (t, tb), Y0, method="DOP853", rtol=rtol, atol=atol,
                            events=[ev for ev, _, _ in events] or None, dense_output=dense)
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed: {sol.message}")
            nfev += sol.nfev
            t_end = sol.t[-1]
            Yend = sol.y[:, -1]
            if dense:
                pieces.append((t, t_end, mode, sol.sol))
            y = Yend[:n2].copy()
            if variational:
                Phi = Yend[n2:].reshape(n2, n2) @ Phi
            if sol.status == 1:  # a contact switch
                hit = [k for k, te in enumerate(sol.t_events) if len(te)]
                k = min(hit, key=lambda k: sol.t_events[k][0])
                _, i, side = events[k]
                new = list(mode)
                new[i] = 0 if mode[i] != 0 else side
                switches.append((t_end, i, mode[i], new[i], float(model.backlash[i].w @ y[model.n:])))
                mode = tuple(new)
                if len(switches) > max_switches:
                    raise RuntimeError("too many contact switches (chattering?)")
            t = t_end
    if dense:
        pieces = [(a, b, m, (lambda tt, s=s: s(tt)[:n2])) for a, b, m, s in pieces]
    return Flow(y, Phi, pieces, switches, nfev)


# --------------------------------------------------------------------------------------------
# Shooting, multipliers, checks
# --------------------------------------------------------------------------------------------


def shoot(model, y0, rtol, half=False, tol=1e-13, max_iter=40, verbose=False):
    """Newton shooting for P_T(y) = y, or (half=True) for the symmetric orbit -P_{T/2}(y) = y.
    Returns (y*, residual history)."""
    y = np.array(y0, dtype=float)
    n2 = 2 * model.n
    t1 = model.T / 2 if half else model.T
    hist = []
    sgn = -1.0 if half else 1.0
    for it in range(max_iter):
        fl = integrate(model, y, 0.0, t1, rtol)
        r = sgn * fl.y - y
        res = np.max(np.abs(r) / model.scale)
        hist.append(res)
        if verbose:
            print(f"    shoot it {it}: residual {res:.3e}", flush=True)
        if res < tol:
            break
        J = sgn * fl.Phi - np.eye(n2)
        dy = np.linalg.lstsq(J, -r, rcond=None)[0]
        # damped step: accept the first step that reduces the residual
        lam = 1.0
        for _ in range(30):
            yt = y + lam * dy
            try:
                ft = integrate(model, yt, 0.0, t1, rtol, variational=False)
                rt = np.max(np.abs(sgn * ft.y - yt) / model.scale)
            except RuntimeError:
                rt = np.inf
            if rt < res or res < 1e-9:
                break
            lam *= 0.5
        y = yt
    return y, hist


def multipliers(Phi):
    lam = np.linalg.eigvals(Phi)
    order = np.argsort(-np.abs(lam), kind="stable")
    return lam[order]


def fd_monodromy(model, y, rtol, h_rel=1e-6):
    n2 = 2 * model.n
    J = np.zeros((n2, n2))
    for j in range(n2):
        h = h_rel * model.scale[j]
        e = np.zeros(n2)
        e[j] = h
        yp = integrate(model, y + e, 0.0, model.T, rtol, variational=False).y
        ym = integrate(model, y - e, 0.0, model.T, rtol, variational=False).y
        J[:, j] = (yp - ym) / (2 * h)
    return J


def match_moduli(a, b):
    a, b = np.sort(np.abs(a)), np.sort(np.abs(b))
    return float(np.max(np.abs(a - b)))


def match_values(a, b):
    """max over a of the distance to the nearest b (multipliers as complex numbers)."""
    return float(max(np.min(np.abs(b - x)) for x in a))


def fourier(flow, model, N=16384, H=8):
    t = np.arange(N) * model.T / N
    Y = flow.sample(t)
    n = model.n
    out = []
    for i in range(n):
        c = np.fft.rfft(Y[:, i]) / N
        a = [float(c[0].real)] + [float(2 * c[k].real) for k in range(1, H + 1)]
        b = [0.0] + [float(-2 * c[k].imag) for k in range(1, H + 1)]
        out.append({"cos": a, "sin": b})
    return out, Y


def regime_of(model, Y, switches=()):
    n = model.n
    if not model.backlash:
        return {"class": "linear"}
    per = []
    for e in model.backlash:
        u = Y[:, :n] @ e.w
        drive = float(np.mean(u > e.b))
        back = float(np.mean(u < -e.b))
        sep = 1.0 - drive - back
        if back == 0.0 and sep == 0.0:
            cls = "no_impact (drive flank, u > b throughout)"
        elif drive == 0.0 and sep == 0.0:
            cls = "no_impact (coast flank, u < -b throughout)"
        elif drive > 0 and back > 0:
            cls = "double_sided_impact"
        elif drive > 0 or back > 0:
            cls = "single_sided_impact (contact loss, one flank)"
        else:
            cls = "no_contact (inside the backlash throughout)"
        per.append({"class": cls, "u_min": float(u.min()), "u_max": float(u.max()),
                    "fraction_drive_contact": drive, "fraction_separated": sep,
                    "fraction_back_contact": back,
                    })
        if sep == 0.0:
            per[-1]["grazing_margin"] = float(np.min(np.abs(u)) - e.b)
        else:
            speeds = [abs(sw[4]) for sw in switches if sw[1] == len(per) - 1]
            per[-1]["min_crossing_speed"] = float(min(speeds)) if speeds else None
    if len(per) == 1:
        return per[0]
    return {"class": "; ".join(p["class"] for p in per), "elements": per}


def liouville(model):
    """det(monodromy) = exp(-T tr(M^-1 D_mean)) (Liouville); no contact damping here, so the
    trace does not depend on the contact mode, and a proportional mesh damping averages to
    beta * mean stiffness."""
    Dm = model.D.copy()
    for e in model.elements:
        ww = np.outer(e.w, e.w)
        if e.kind == "mesh":
            p = e.profile
            if p.shape == "rectangular":
                cr = p.p["contact_ratio"]
                kbar = (cr - 1) * p.p["two_tooth"] + (2 - cr) * p.p["one_tooth"]
            elif p.shape == "cosine":
                kbar = p.p["mean"]
            else:
                kbar = p.p["stiffness"]
            Dm += (e.beta * kbar + e.c) * ww
    return float(math.exp(-model.T * np.trace(model.Minv @ Dm)))


def cnum(z):
    return [float(z.real), float(z.imag)]


def reference_orbit(model, y_guess, extra, half=False, fd_check=True, exact=None,
                    verbose=True):
    """Converge the orbit at rtol 1e-10 and 1e-12, compute the multipliers and the checks."""
    t_start = time.time()
    res = {}
    for rtol in (1e-10, 1e-12):
        y, hist = shoot(model, y_guess, rtol, half=half, verbose=False)
        if half:  # polish on the full map as well (same orbit, full-period residual)
            y, hist2 = shoot(model, y, rtol, half=False)
            hist = hist + hist2
        fl = integrate(model, y, 0.0, model.T, rtol, dense=(rtol == 1e-12))
        res[rtol] = (y, hist, fl)
        y_guess = y
    y10, h10, f10 = res[1e-10]
    y12, h12, f12 = res[1e-12]
    lam10, lam12 = multipliers(f10.Phi), multipliers(f12.Phi)
    conv = {
        "rtol_1e-10_vs_1e-12_max_modulus_diff": match_moduli(lam10, lam12),
        "rtol_1e-10_vs_1e-12_max_multiplier_diff": match_values(lam12, lam10),
        "rtol_1e-10_vs_1e-12_max_state_diff_scaled": float(np.max(np.abs(y10 - y12) / model.scale)),
        "shooting_residual": float(np.max(np.abs(f12.y - y12) / model.scale)),
        "shooting_residual_note": "max_i |P_T(y0)-y0|_i / scale_i at rtol 1e-12",
        "state_scale": [float(s) for s in model.scale],
        "newton_history_rtol_1e-12": [float(h) for h in h12],
    }
    if fd_check:
        Jfd = fd_monodromy(model, y12, 1e-12)
        conv["finite_difference_vs_variational_max_modulus_diff"] = match_moduli(
            multipliers(Jfd), lam12)
        conv["finite_difference_note"] = ("central differences of the period map, step 1e-6 "
                                          "* scale_i, rtol 1e-12 (limited by integration "
                                          "noise / step, up to about 2e-8)")
    liou = liouville(model)
    conv["liouville_product_of_multipliers"] = liou
    conv["liouville_relative_diff"] = float(abs(abs(np.prod(lam12)) - liou) / liou)
    if exact is not None:
        conv.update(exact(model, y12, lam12))
    four, Y = fourier(f12, model)
    n = model.n
    out = dict(extra)
    out.update({
        "W": model.Omega,
        "period": model.T,
        "initial_state": {"q": [float(v) for v in y12[:n]], "v": [float(v) for v in y12[n:]]},
        "fourier": [{"dof": i, "cos": four[i]["cos"], "sin": four[i]["sin"]} for i in range(n)],
        "max_abs": [float(np.max(np.abs(Y[:, i]))) for i in range(n)],
        "max_abs_velocity": [float(np.max(np.abs(Y[:, n + i]))) for i in range(n)],
        "mean": [float(np.mean(Y[:, i])) for i in range(n)],
        "regime": regime_of(model, Y, f12.switches),
        "contact_switches_per_period": len(f12.switches),
        "multipliers": [cnum(z) for z in lam12],
        "moduli": [float(abs(z)) for z in lam12],
        "stable": bool(np.max(np.abs(lam12)) < 1.0),
        "convergence": conv,
        "wall_seconds": round(time.time() - t_start, 2),
    })
    if verbose:
        print(f"  {model.name} W={model.Omega:.6g}: moduli {[f'{abs(z):.10g}' for z in lam12]}"
              f"  d(rtol)={conv['rtol_1e-10_vs_1e-12_max_modulus_diff']:.2e}"
              f"  fd={conv.get('finite_difference_vs_variational_max_modulus_diff', float('nan')):.2e}"
              f"  res={conv['shooting_residual']:.1e}  [{out['regime']['class']}]"
              f"  {out['wall_seconds']}s", flush=True)
    return out


def steady_state(model, y0, periods, rtol=1e-9):
    """Plain time integration over `periods` periods (restarts as above); returns the state at
    the start of the last period and the last change per period (scaled)."""
    y = np.array(y0, dtype=float)
    d = np.inf
    for _ in range(periods):
        y1 = integrate(model, y, 0.0, model.T, rtol, variational=False).y
        d = np.max(np.abs(y1 - y) / model.scale)
        y = y1
        if d < 1e-10:
            break
    return y, d


# --------------------------------------------------------------------------------------------
# Models
# --------------------------------------------------------------------------------------------

TWO_SHAFT = dict(M=1e-3, K1=2.5e5, K2=5e5, contact_ratio=1.5, beta=5.1639777949e-6, L0=10.0,
                 e_a=5e-4, Z=4)


def two_shaft(rpm):
    p = TWO_SHAFT
    Omega = p["Z"] * rpm * TAU / 60.0  # mesh frequency = the scene's fundamental
    L1 = p["M"] * p["e_a"] * Omega ** 2
    prof = Profile("rectangular", one_tooth=p["K1"], two_tooth=p["K2"],
                   contact_ratio=p["contact_ratio"])
    mesh = Element("mesh", [1.0], prof, beta=p["beta"])
    wn = math.sqrt(p["K2"] / p["M"])
    model = Model(f"two_shaft_{rpm}rpm", [[p["M"]]], [[0.0]], [[0.0]], Omega,
                  [(0, 0, p["L0"], 0.0), (0, 1, L1, 0.0)], [mesh], scale=[5e-5, 5e-5 * wn],
                  max_chunk=20 * TAU / wn)
    params = dict(p, rpm=rpm, L1=L1, Omega_mesh_rad_s=Omega, shaft_rad_s=rpm * TAU / 60.0)
    return model, params


def two_shaft_exact(model, y, lam):
    """Exact piecewise solution: per stiffness segment the augmented LTI system
    z = (q, q', 1, cos Wt, sin Wt) is advanced by a matrix exponential."""
    p = TWO_SHAFT
    W, T, M, beta = model.Omega, model.T, p["M"], p["beta"]
    L0 = model.loads[0][2]
    L1 = model.loads[1][2]
    E = np.eye(5)
    cuts = [0.0, (p["contact_ratio"] - 1.0) * T, T]
    for (a, b), k in zip(zip(cuts[:-1], cuts[1:]), (p["K2"], p["K1"])):
        G = np.zeros((5, 5))
        G[0, 1] = 1.0
        G[1, 0], G[1, 1], G[1, 2], G[1, 3] = -k / M, -beta * k / M, L0 / M, L1 / M
        G[3, 4], G[4, 3] = -W, W
        E = expm(G * (b - a)) @ E
    P, p0 = E[:2, :2], E[:2, 2:] @ np.array([1.0, 1.0, 0.0])
    y_exact = np.linalg.solve(np.eye(2) - P, p0)
    lam_e = multipliers(P)
    return {
        "exact_expm_max_state_diff_scaled": float(np.max(np.abs(y_exact - y) / model.scale)),
        "exact_expm_max_multiplier_diff": match_values(lam, lam_e),
        "exact_expm_max_relative_multiplier_diff": float(
            max(np.min(np.abs(lam_e - z)) / abs(z) for z in lam)),
        "exact_expm_multipliers": [cnum(z) for z in lam_e],
    }


KAHRAMAN = dict(zeta=0.05, eps=0.2, Fm=0.1, Fa=0.05, b=1.0)


def kahraman(W, Fa=None, Fm=None):
    p = dict(KAHRAMAN)
    if Fa is not None:
        p["Fa"] = Fa
    if Fm is not None:
        p["Fm"] = Fm
    prof = Profile("cosine", mean=1.0, amplitude=p["eps"])
    el = Element("backlash", [1.0], prof, b=p["b"])
    model = Model(f"gear_backlash_W{W}", [[1.0]], [[2 * p["zeta"]]], [[0.0]], W,
                  [(0, 0, p["Fm"], 0.0), (0, 1, p["Fa"], 0.0)], [el], scale=[1.0, 1.0])
    return model, dict(p, W=W)


def saddle_between(model, A, B, rtol=1e-10, periods=80, iterations=45, settle=10):
    """An unstable orbit between two stable ones: bisect the segment A-B on which attractor
    the time integration reaches (the basin boundary is the saddle's stable manifold), then
    follow the boundary point a few periods towards the saddle. Returns a shooting guess."""
    def fate(y):
        for _ in range(periods):
            y = integrate(model, y, 0.0, model.T, rtol, variational=False).y
            if np.max(np.abs(y - A) / model.scale) < 1e-4:
                return "A"
            if np.max(np.abs(y - B) / model.scale) < 1e-4:
                return "B"
        return "?"
    lo, hi = 0.0, 1.0  # y = B + a (A - B): a = 0 reaches B, a = 1 reaches A
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        f = fate(B + mid * (A - B))
        if f == "B":
            lo = mid
        elif f == "A":
            hi = mid
        else:
            break
    y = B + 0.5 * (lo + hi) * (A - B)
    for _ in range(settle):
        y = integrate(model, y, 0.0, model.T, rtol, variational=False).y
    return y


def attractor(model, y0, periods=400):
    y, d = steady_state(model, y0, periods, rtol=1e-9)
    if d > 1e-8:
        raise RuntimeError(f"{model.name}: no periodic steady state from {y0} (change {d})")
    return y


# --------------------------------------------------------------------------------------------
# Cases
# --------------------------------------------------------------------------------------------


def write(name, orbits):
    os.makedirs(OUT_DIR, exist_ok=True)
    path = os.path.join(OUT_DIR, name + ".json")
    with open(path, "w") as f:
        json.dump(orbits, f, indent=1)
        f.write("\n")
    print(f"wrote {path}", flush=True)


ENV = {"python": sys.version.split()[0], "numpy": np.__version__, "scipy": scipy.__version__,
       "integrator": "scipy solve_ivp DOP853, restarted at stiffness jumps and contact "
                     "switches; variational equations; atol_i = 1e-3 rtol scale_i"}


def case_two_shaft(rpm):
    model, params = two_shaft(rpm)
    extra = {
        "model": "two_shaft",
        "parameters": params,
        "equation": "M q'' + beta K(t) q' + K(t) q = L0 + L1 cos(W t), K(t) = K2 while "
                    "frac(W t / 2 pi) < contact_ratio - 1 else K1, W = Z * shaft speed",
        "scene_equivalent": f"examples/scenes/two_shaft_{rpm}rpm.toml (fundamental rpm = {rpm}, "
                            "order = 4, so W = 4 * 2 pi rpm / 60 is the mesh frequency and "
                            "harmonic k is shaft order 4k; mesh_stiffness element, teeth = 1, "
                            "rectangular profile, damping proportional beta)",
        "branch": "unique (linear system)",
        "environment": ENV,
    }
    orbit = reference_orbit(model, np.array([params["L0"] / 3.75e5, 0.0]), extra,
                            exact=two_shaft_exact)
    write(f"two_shaft_{rpm}rpm", [orbit])


KAHRAMAN_EQ = ("x'' + 2 zeta x' + (1 + eps cos(W t)) g(x) = Fm + Fa cos(W t), g(x) = x - b "
               "(x > b), 0 (|x| <= b), x + b (x < -b)")


def kahraman_extra(params, branch):
    return {
        "model": "gear_backlash",
        "parameters": params,
        "equation": KAHRAMAN_EQ,
        "scene_equivalent": "examples/scenes/gear_backlash.toml with fundamental = { rad_s = W } "
                            f"and loads[1].cos = Fa = {params['Fa']}, loads[0].cos = Fm = "
                            f"{params['Fm']} (backlash element, half_backlash = b, cosine "
                            "stiffness mean 1, amplitude eps, damping [[2 zeta]], mass [[1]])",
        "branch": branch,
        "environment": ENV,
    }


def case_gear_backlash():
    orbits = []
    for W in (0.4, 0.5, 0.7, 0.8, 0.9, 1.0, 1.4):
        model, params = kahraman(W)
        A = attractor(model, np.array([1.1, 0.0]))  # from just above the backlash
        B = attractor(model, np.array([1.5, 0.0]))  # from further out (contact loss if any)
        A = shoot(model, A, 1e-10)[0]
        B = shoot(model, B, 1e-10)[0]
        if np.max(np.abs(A - B)) < 1e-7:
            orbits.append(reference_orbit(model, A, kahraman_extra(
                params, "unique found (time integration from (1.1, 0) and (1.5, 0) reach it)")))
            continue
        orbits.append(reference_orbit(model, A, kahraman_extra(
            params, "coexisting: stable no-impact orbit (time integration from (1.1, 0))")))
        S = saddle_between(model, A, B)
        orbits.append(reference_orbit(model, S, kahraman_extra(
            params, "coexisting: unstable orbit between the two stable ones (Newton shooting "
                    "from the basin boundary on the segment between them)")))
        orbits.append(reference_orbit(model, B, kahraman_extra(
            params, "coexisting: stable contact-loss orbit (time integration from (1.5, 0))")))
    write("gear_backlash_Fa0.05", orbits)


def case_gear_backlash_fa(Fa, Ws, name):
    orbits = []
    for W in Ws:
        model, params = kahraman(W, Fa=Fa)
        A = attractor(model, np.array([2.5, 1.0]))
        orbits.append(reference_orbit(model, A, kahraman_extra(
            params, "stable (reached by time integration from (2.5, 1.0))")))
    write(name, orbits)


CASES = {
    "two_shaft_60rpm": lambda: case_two_shaft(60),
    "two_shaft_600rpm": lambda: case_two_shaft(600),
    "two_shaft_6000rpm": lambda: case_two_shaft(6000),
    "gear_backlash_Fa0.05": case_gear_backlash,
    "gear_backlash_Fa0.1_W0.7": lambda: case_gear_backlash_fa(0.1, [0.7],
                                                              "gear_backlash_Fa0.1_W0.7"),
    "gear_backlash_Fa0.3_double_sided": lambda: case_gear_backlash_fa(
        0.3, [0.7, 0.8], "gear_backlash_Fa0.3_double_sided"),
}


# --------------------------------------------------------------------------------------------
# The symmetric 3-DOF chain with one backlash element (symmetry-breaking pitchfork)
# --------------------------------------------------------------------------------------------

CHAIN = dict(k_ground=1.0, k12=1.0, k23=1.0, rayleigh_mass=0.02, rayleigh_stiffness=0.04,
             kc=5.0, b=1.0, F=1.0)


def chain(W):
    p = CHAIN
    K = np.array([[p["k_ground"] + p["k12"], -p["k12"], 0.0],
                  [-p["k12"], p["k12"] + p["k23"], -p["k23"]],
                  [0.0, -p["k23"], p["k23"]]])
    M = np.eye(3)
    D = p["rayleigh_mass"] * M + p["rayleigh_stiffness"] * K
    el = Element("backlash", [0.0, -1.0, 1.0], Profile("constant", stiffness=p["kc"]), b=p["b"])
    model = Model(f"chain_backlash_W{W}", M, D, K, W, [(0, 1, p["F"], 0.0)], [el],
                  scale=[1.0] * 6)
    params = dict(p, W=W, mass=M.tolist(), damping=D.tolist(), stiffness=K.tolist(),
                  backlash_weights=[0.0, -1.0, 1.0], forced_dof=0)
    return model, params


CHAIN_EQ = ("q'' + D q' + K q + w kc g(w.q) = (F cos(W t), 0, 0), q = (x1, x2, x3), "
            "w = (0, -1, 1) (backlash between x2 and x3), K = chain x1-ground, x1-x2, x2-x3 "
            "springs, D = 0.02 I + 0.04 K (Rayleigh). Invariant under (q, t) -> (-q, t + T/2).")


def symmetric_branch(Ws, rtol=1e-10):
    """Symmetric orbits (-P_{T/2}(y) = y) by natural continuation in W from the steady state
    reached from rest at Ws[0]. Returns {W: y}."""
    model, _ = chain(Ws[0])
    y = attractor(model, np.zeros(6), periods=600)
    out = {}
    for W in Ws:
        model, _ = chain(W)
        y, hist = shoot(model, y, rtol, half=True)
        if hist[-1] > 1e-11:
            raise RuntimeError(f"symmetric branch lost at W = {W}")
        out[W] = y
    return out


def half_map_critical(W, y, rtol):
    """The real eigenvalue mu of d(-P_{T/2}) nearest -1 (full multiplier mu^2 -> +1)."""
    model, _ = chain(W)
    y, _ = shoot(model, y, rtol, half=True)
    mu = np.linalg.eigvals(-integrate(model, y, 0.0, model.T / 2, rtol).Phi)
    real = mu[np.abs(mu.imag) < 1e-12].real
    return real[np.argmin(np.abs(real + 1))], y


def symmetry_breaking_point(W_lo, W_hi, y_lo, rtol):
    from scipy.optimize import brentq
    state = {"y": y_lo}

    def f(W):
        mu, state["y"] = half_map_critical(W, state["y"], rtol)
        return mu + 1.0
    return brentq(f, W_lo, W_hi, xtol=1e-11, rtol=1e-14)


def chain_extra(params, branch):
    return {
        "model": "chain_backlash",
        "parameters": params,
        "equation": CHAIN_EQ,
        "scene_equivalent": "tests/data/floquet/chain_backlash.toml with fundamental = "
                            f"{{ rad_s = {params['W']} }}",
        "branch": branch,
        "environment": ENV,
    }


def case_chain():
    W_before, W_after = 1.34, 1.36
    grid = [round(1.20 + 0.02 * j, 2) for j in range(9)]  # 1.20 .. 1.36
    branch = symmetric_branch(grid)
    # the symmetry-breaking point: the real half-map eigenvalue through -1 (bisection/brent)
    Wc = {}
    for rtol in (1e-10, 1e-12):
        Wc[rtol] = symmetry_breaking_point(W_before, W_after, branch[W_before], rtol)
        print(f"  symmetry-breaking W (rtol {rtol:g}) = {Wc[rtol]:.12f}", flush=True)
    orbits = []
    model, params = chain(W_before)
    orbits.append(reference_orbit(model, branch[W_before], chain_extra(
        params, "symmetric orbit before the symmetry-breaking point (stable)"), half=True))
    model, params = chain(W_after)
    y_sym = branch[W_after]
    orbits.append(reference_orbit(model, y_sym, chain_extra(
        params, "symmetric orbit after the symmetry-breaking point (unstable: one real "
                "multiplier > 1)"), half=True))
    # asymmetric orbit: leave the symmetric one along the critical eigenvector of the
    # half-period map and let the time integration settle, then shoot
    mu, V = np.linalg.eig(-integrate(model, y_sym, 0.0, model.T / 2, 1e-10).Phi)
    v = V[:, np.argmin(np.abs(mu + 1.0))].real
    for sign, label in ((1.0, "a"), (-1.0, "b")):
        ya = attractor(model, y_sym + sign * 0.05 * v / np.max(np.abs(v)), periods=800)
        o = reference_orbit(model, ya, chain_extra(
            params, f"asymmetric orbit {label} after the symmetry-breaking point (one of the "
                    "two mirror images (q, t) -> (-q, t + T/2); reached by time integration "
                    "from the symmetric orbit displaced along the critical eigenvector)"))
        orbits.append(o)
    for o in orbits:
        o["symmetry_breaking_W"] = Wc[1e-12]
        o["symmetry_breaking_W_rtol_1e-10_vs_1e-12"] = abs(Wc[1e-10] - Wc[1e-12])
        if o is orbits[0] or o is orbits[1]:
            m, _ = chain(o["W"])
            y0 = np.array(o["initial_state"]["q"] + o["initial_state"]["v"])
            mu = multipliers(-integrate(m, y0, 0.0, m.T / 2, 1e-12).Phi)
            o["half_period_map_multipliers"] = [cnum(z) for z in mu]
            o["half_period_map_note"] = ("eigenvalues mu of d(-P_{T/2}) on the symmetric "
                                         "orbit; the full multipliers are mu^2. The "
                                         "symmetry-breaking point is the real mu through -1")
    write("chain_backlash", orbits)
    write_chain_scene(Wc[1e-12])


def write_chain_scene(Wc):
    p = CHAIN
    model, params = chain(1.36)
    D, K = params["damping"], params["stiffness"]
    fmt = lambda rows: "[" + ", ".join("[" + ", ".join(repr(float(x)) for x in r) + "]"
                                       for r in rows) + "]"
    text = f"""# Symmetric 3-DOF chain with one backlash element (tools/floquet_reference/reference.py).
# x1 is grounded by a spring, x1-x2 and x2-x3 springs, Rayleigh damping D = 0.02 M + 0.04 K,
# a backlash contact (half backlash b, constant contact stiffness kc) between x2 and x3, and a
# harmonic force on x1 with no static load. The model is invariant under (q, t) -> (-q, t + T/2):
# symmetric orbits have odd harmonics only. Along the symmetric branch a real Floquet multiplier
# crosses +1 at W = {Wc:.9f} rad/s (supercritical symmetry-breaking pitchfork): below it the
# symmetric orbit is stable, above it unstable, and two stable mirror-image asymmetric orbits
# (even harmonics, non-zero mean of x3) branch off. References: tests/data/floquet/chain_backlash.json
description = "symmetric 3-DOF chain with backlash between x2 and x3, W = 1.36 (past the symmetry-breaking point)"
dofs = ["x1", "x2", "x3"]
mass = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
damping = {fmt(D)}
stiffness = {fmt(K)}
fundamental = {{ rad_s = 1.36 }}
harmonics = {{ count = 64 }}
loads = [{{ dof = "x1", order = 1, cos = {p['F']!r} }}]

[[elements]]
name = "contact"
type = "backlash"
connects = {{ x2 = -1.0, x3 = 1.0 }}
half_backlash = {p['b']!r}
stiffness = {{ shape = "constant", stiffness = {p['kc']!r} }}

[solver]
method = "newton"
tolerance = 1e-10
"""
    path = os.path.join(OUT_DIR, "chain_backlash.toml")
    with open(path, "w") as f:
        f.write(text)
    print(f"wrote {path}", flush=True)


CASES["chain_backlash"] = case_chain


INDEX_HEAD = """# Floquet references (independent of hbal)

Periodic orbits and Floquet multipliers computed by `tools/floquet_reference/reference.py`
(scipy DOP853 time integration restarted at every stiffness jump and contact switch, Newton
shooting, variational equations; see that folder's README). Regenerate with
`python3 tools/floquet_reference/reference.py`; CI needs no Python.

## Layout

Every `*.json` file is a JSON **list of orbit objects** (one or more orbits of one model). Each
orbit object has:

| field | meaning |
|---|---|
| `model` | `two_shaft`, `gear_backlash` or `chain_backlash` |
| `parameters` | every number of the model (names as in `equation`) |
| `equation`, `scene_equivalent` | the equation, and how it maps onto an hbal scene |
| `branch` | which of several coexisting orbits this is and how it was found |
| `W`, `period` | fundamental angular frequency (rad/s; hbal's Ω) and T = 2π/W |
| `initial_state` | `{"q": [...], "v": [...]}` at t = 0, where all load (and stiffness) phases are zero |
| `fourier` | per DOF `{"dof": i, "cos": [a0, a1..a8], "sin": [0, b1..b8]}`: q_i(t) = a0 + Σ_k a_k cos(kWt) + b_k sin(kWt), from 16384 samples per period (aliasing < 1e-12) |
| `max_abs`, `max_abs_velocity`, `mean` | per DOF over one period (16384 samples) |
| `regime` | contact classification of each backlash element (`class`, `u_min`, `u_max`, fractions of the period in drive contact / separated / back contact, `grazing_margin` = min|u| - b for orbits that never separate, `min_crossing_speed` = min |u'| at the contact switches otherwise) |
| `contact_switches_per_period` | number of contact switches in one period |
| `multipliers` | `[[re, im], ...]` sorted by modulus, descending |
| `moduli`, `stable` | the moduli, and max modulus < 1 |
| `convergence` | `rtol_1e-10_vs_1e-12_max_modulus_diff` (the whole shooting + multipliers redone at both tolerances), `..._max_multiplier_diff` (complex), `..._max_state_diff_scaled`, `shooting_residual` (max_i |P_T(y0) - y0|_i / scale_i at rtol 1e-12), `finite_difference_vs_variational_max_modulus_diff` (central differences, step 1e-6 scale, rtol 1e-12: limited by the integration noise), `liouville_*` (det of the monodromy vs exp(-T tr(M^-1 D_mean))), and for the two-shaft model `exact_expm_*` (exact piecewise matrix-exponential solution) |
| `symmetry_breaking_W`, `half_period_map_multipliers` | chain only (see below) |

The multiplier moduli are good to about 1e-10 absolute or better (see `convergence`); the tests
compare to 1e-6. For the 60 rpm two-shaft case the moduli are about 7e-106 (one period spans
~750 strongly damped natural oscillations), relative accuracy ~5e-10 against the exact solution.

## Cases
"""

INDEX_TAIL = """
## Notes

- Gear pair, Fa = 0.05: for a complex pair of multipliers of this 1-DOF model the modulus is
  exactly exp(-zeta T) (Liouville: the damping is constant and the contact force continuous),
  so only real pairs (the saddles, the Fa = 0.3, W = 0.8 orbit) test the moduli non-trivially;
  compare the complex multipliers themselves as well.
- Gear pair, Fa = 0.05: the no-impact branch and the contact-loss branch coexist for roughly
  0.55 < W < 0.83 (natural continuation, step 0.02: the no-impact branch ends where it grazes
  u = b near W = 0.83; the contact-loss branch is lost near W = 0.55, not at a smooth fold since
  its multipliers stay complex there, so probably at a grazing too). The scene `examples/scenes/gear_backlash.toml`
  (W = 0.7) lies inside: it has two stable orbits and one saddle, all three stored here.
- Gear pair, Fa = 0.3, W = 0.8: this double-sided orbit lies just below a saddle-node of its
  branch (real multiplier 0.787 at W = 0.8, 0.862 at 0.802, 0.958 at 0.804, branch lost by
  W = 0.806, so the fold is near W = 0.805). Stable and well converged, but a solver needs a
  good start there. For Fa = 0.3, 0.9 <= W <= 1.6 the time integration from (1.5, 0) and
  (2.5, 1) did not settle to a T-periodic orbit in 300 periods (subharmonic or chaotic).
- No orbit here is close to grazing: the smallest distance of a non-crossing extremum of u to
  +-b is 0.012 (W = 0.8 no-impact orbit), the smallest |u'| at a contact switch is 0.091 (the
  W = 0.8 saddle).
- Chain: `chain_backlash.toml` is the scene at W = 1.36 (change `fundamental.rad_s` for the other
  orbits). Along the symmetric branch the half-period map G = -P_{T/2} (P_T = G o G) has a real
  eigenvalue mu through -1, i.e. a full multiplier mu^2 through +1, at the stored
  `symmetry_breaking_W`; the pitchfork is supercritical (the asymmetric orbits exist for
  W > W_c, their asymmetry grows like sqrt(W - W_c), and they are stable at W = 1.36).
"""


def write_index():
    rows = ["| file | model | W | branch / regime | moduli | stable | d(rtol 1e-10 vs 1e-12) | residual |",
            "|---|---|---|---|---|---|---|---|"]
    for fn in sorted(os.listdir(OUT_DIR)):
        if not fn.endswith(".json"):
            continue
        for o in json.load(open(os.path.join(OUT_DIR, fn))):
            c = o["convergence"]
            mods = ", ".join(f"{m:.10g}" for m in o["moduli"])
            extra = ""
            if o["model"] == "gear_backlash":
                extra = f" (Fa = {o['parameters']['Fa']})"
            rows.append(f"| `{fn}` | {o['model']}{extra} | {o['W']:.10g} | {o['branch'].split(' (')[0]}; "
                        f"{o['regime']['class']} | {mods} | {o['stable']} | "
                        f"{c['rtol_1e-10_vs_1e-12_max_modulus_diff']:.1e} | {c['shooting_residual']:.1e} |")
    sb = json.load(open(os.path.join(OUT_DIR, "chain_backlash.json")))[0]
    tail = INDEX_TAIL + (f"\nSymmetry-breaking point of the chain: W_c = {sb['symmetry_breaking_W']:.10f} "
                         f"(rtol 1e-10 vs 1e-12: {sb['symmetry_breaking_W_rtol_1e-10_vs_1e-12']:.1e}).\n")
    with open(os.path.join(OUT_DIR, "README.md"), "w") as f:
        f.write(INDEX_HEAD + "\n".join(rows) + "\n" + tail)
    print("wrote index", flush=True)


CASES["index"] = write_index


if __name__ == "__main__":
    names = sys.argv[1:] or list(CASES)
    for name in names:
        print(f"== {name}", flush=True)
        CASES[name]()
