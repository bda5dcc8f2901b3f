#!/usr/bin/env python3
"""An independent axisymmetric fretting-wear reference (method of dimensionality reduction).

Owns: a rigid sphere on an isotropic elastic flat, uncoupled, Coulomb friction,
Archard or energy wear, fretting cycles under force or displacement control, in
1-D by the MDR (Popov & Hess; Dimaki et al. 2014; Willert 2021). Shares no code
with the product and must not import it; numpy only. Run with --check.

Units: SI throughout (m, N, Pa); wear coefficients k in m^3/(N m) = 1/Pa
(1 mm^3/(N m) = 1e-9 m^3/(N m)) and alpha in m^3/J.

Discretisation (one grid for r and x): nodes r_j = x_j = j h, j = 0..n-1.
Every field (3-D profile f(r), worn depth h(r), 1-D profile g(x), 1-D spring
displacements w(x), u(x)) is piecewise linear in s = r^2 (resp. x^2) between
nodes; where the 1-D normal displacement changes sign inside a cell the root is
inserted as an extra breakpoint. Every Abel-type integral of such data against
the kernels 1/sqrt(x^2 - r^2) and 1/sqrt(r^2 - x^2) is done in closed form, so
the square-root singularities cost nothing and a quadratic profile (Hertz) is
represented exactly. Second order in h for smooth data (exact for quadratics);
a stick/slip kink inside a cell is smeared over that cell (first order in the
position of c, second order in integrals).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass, field

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")  # one core: the matrices are small

import numpy as np  # noqa: E402


# ----------------------------------------------------------------------------
# Material, load, grid
# ----------------------------------------------------------------------------

@dataclass
class Setup:
    R: float = 0.01          # sphere radius [m]
    E: float = 210e9         # flat's Young's modulus [Pa]
    nu: float = 0.0          # flat's Poisson ratio (MDR tangential exact for 0)
    mu: float = 0.5          # Coulomb friction coefficient
    P: float = 100.0         # normal force [N]
    n: int = 400             # radial nodes
    rmax_over_a: float = 1.25  # grid extent in units of the Hertz radius

    @property
    def Estar(self) -> float:
        return self.E / (1.0 - self.nu ** 2)

    @property
    def G(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def Gstar(self) -> float:
        return 4.0 * self.G / (2.0 - self.nu)

    @property
    def a_hertz(self) -> float:
        return (3.0 * self.P * self.R / (4.0 * self.Estar)) ** (1.0 / 3.0)

    @property
    def delta_star(self) -> float:
        """Mindlin's slip displacement 3 mu P K/(16 a), K = (2-nu)/G = 4/G*."""
        return 3.0 * self.mu * self.P * (4.0 / self.Gstar) / (16.0 * self.a_hertz)


# ----------------------------------------------------------------------------
# Piecewise-linear-in-s calculus (s = x^2): closed-form kernels
# ----------------------------------------------------------------------------

def _seg_coeffs(X, V):
    """On each segment [X_k, X_k+1], V = alpha + beta x^2. Returns alpha, beta."""
    s = X * X
    ds = np.diff(s)
    beta = np.diff(V) / ds
    alpha = V[:-1] - beta * s[:-1]
    return alpha, beta


def line_integral(X, V):
    """int_0^Xmax V(x) dx for V linear in x^2 on each segment (exact)."""
    alpha, beta = _seg_coeffs(X, V)
    xa, xb = X[:-1], X[1:]
    return float(np.sum(alpha * (xb - xa) + beta * (xb ** 3 - xa ** 3) / 3.0))


def line_weights(X):
    """Weights w with sum(w * V) = line_integral(X, V)."""
    xa, xb = X[:-1], X[1:]
    ds = xb * xb - xa * xa
    # V = V_a + (V_b - V_a)(x^2 - xa^2)/ds
    m = ((xb ** 3 - xa ** 3) / 3.0 - xa * xa * (xb - xa)) / ds
    w = np.zeros_like(X)
    w[:-1] += (xb - xa) - m
    w[1:] += m
    return w


def area_weights(r):
    """Weights for int f 2 pi r dr = pi int f ds, f linear in s: trapezoid in s."""
    s = r * r
    w = np.zeros_like(r)
    w[:-1] += 0.5 * np.diff(s)
    w[1:] += 0.5 * np.diff(s)
    return np.pi * w


def abel_down(X, V, r):
    """-(1/pi) int_r^Xmax V'(x)/sqrt(x^2 - r^2) dx at each r (V linear in x^2).

    With V = alpha + beta x^2, V' = 2 beta x and the integral is
    2 beta [sqrt(x^2 - r^2)] in closed form (no singularity left).
    V may be (k, len(X)): k fields at once; returns (k, len(r)) then."""
    V = np.asarray(V)
    one = V.ndim == 1
    V2 = np.atleast_2d(V)
    beta = np.diff(V2, axis=1) / np.diff(X * X)
    Sq = np.sqrt(np.maximum(X[None, :] ** 2 - (r * r)[:, None], 0.0))
    out = -(2.0 / np.pi) * (beta @ np.diff(Sq, axis=1).T)
    return out[0] if one else out


def abel_up(X, V, r):
    """(2/pi) int_0^min(r, Xmax) V(x)/sqrt(r^2 - x^2) dx at each r > 0.

    The inverse MDR map: the 3-D surface displacement from the 1-D one.
    int (alpha + beta x^2)/sqrt(r^2 - x^2) dx
      = alpha asin(x/r) + beta [r^2/2 asin(x/r) - x/2 sqrt(r^2 - x^2)].
    V may be (k, len(X)); returns (k, len(r)) then."""
    V = np.asarray(V)
    one = V.ndim == 1
    V2 = np.atleast_2d(V)
    s = X * X
    beta = np.diff(V2, axis=1) / np.diff(s)
    alpha = V2[:, :-1] - beta * s[:-1]
    out = np.zeros((V2.shape[0], r.size))
    pos = r > 0
    rr = r[pos][:, None]
    xc = np.minimum(X[None, :], rr)
    T = np.arcsin(np.minimum(xc / rr, 1.0))
    Sx = 0.5 * xc * np.sqrt(np.maximum(rr * rr - xc * xc, 0.0))
    dT = np.diff(T, axis=1)                       # (n_r, n_seg)
    dB = 0.5 * rr * rr * dT - np.diff(Sx, axis=1)
    out[:, pos] = (2.0 / np.pi) * (alpha @ dT.T + beta @ dB.T)
    out[:, ~pos] = V2[:, :1]
    return out[0] if one else out


def mdr_profile_matrix(r):
    """Matrix A with g = A f: g(x) = |x| int_0^|x| f'(r)/sqrt(x^2 - r^2) dr.

    f = alpha + beta r^2 on each segment, f' = 2 beta r,
    int 2 beta r/sqrt(x^2 - r^2) dr = -2 beta sqrt(x^2 - r^2)."""
    n = r.size
    s = r * r
    A = np.zeros((n, n))
    for i in range(1, n):
        x = r[i]
        ra, rb = r[:i], r[1:i + 1]
        coef = 2.0 * x * (np.sqrt(x * x - ra * ra) - np.sqrt(np.maximum(x * x - rb * rb, 0.0))) / (s[1:i + 1] - s[:i])
        # beta_j = (f_{j+1} - f_j)/(s_{j+1} - s_j)
        A[i, 1:i + 1] += coef
        A[i, :i] -= coef
    return A


# ----------------------------------------------------------------------------
# The model
# ----------------------------------------------------------------------------

@dataclass
class CycleRecord:
    cycle: float             # physical cycles completed
    r: np.ndarray
    h: np.ndarray            # worn depth h(r) [m]
    volume: float            # worn volume [m^3]
    max_depth: float
    a: float                 # contact radius at the cycle's end: edge of {w > 0} (the scar's edge once worn)
    c: float                 # stick radius at the +A turning point
    F_amp: float             # tangential force amplitude (max-min)/2
    d_amp: float             # displacement amplitude (max-min)/2
    energy: float            # energy dissipated in the cycle (1-D springs)
    energy3d: float          # energy from 3-D tau and slip
    wear_volume_cycle: float  # volume worn in this simulated cycle (per physical cycle)
    regime: str
    dh_cycle: np.ndarray      # wear depth of this simulated cycle, per physical cycle
    loop: np.ndarray = field(repr=False, default=None)  # (delta, Q) samples


class MDRContact:
    """Rigid sphere on an isotropic flat, in 1-D by the MDR, with wear."""

    def __init__(self, setup: Setup):
        self.S = setup
        a0 = setup.a_hertz
        self.r = np.linspace(0.0, setup.rmax_over_a * a0, setup.n)
        self.A = mdr_profile_matrix(self.r)
        self.f0 = self.r ** 2 / (2.0 * setup.R)
        self.h = np.zeros_like(self.r)   # worn depth (added to the gap)
        self.area_w = area_weights(self.r)
        self.u = np.zeros_like(self.r)   # 1-D tangential spring displacements
        self.delta = 0.0                 # rigid tangential shift
        self.d = None
        self.solve_normal()

    # -- normal ------------------------------------------------------------
    def g(self):
        return self.A @ (self.f0 + self.h)

    def _w_breakpoints(self, d, g):
        """Breakpoints X (nodes + roots of d - g) and W = (d - g)_+ on them."""
        r, s = self.r, self.r ** 2
        v = d - g
        va, vb = v[:-1], v[1:]
        cross = (va * vb < 0)
        k = np.nonzero(cross)[0]
        sr = s[k] + (s[k + 1] - s[k]) * va[k] / (va[k] - vb[k])
        X = np.concatenate([r, np.sqrt(sr)])
        order = np.argsort(X, kind="stable")
        X = X[order]
        W = np.concatenate([np.maximum(v, 0.0), np.zeros(k.size)])[order]
        is_node = np.concatenate([np.ones(r.size, bool), np.zeros(k.size, bool)])[order]
        # drop duplicate abscissae (root exactly on a node)
        keep = np.concatenate([[True], np.diff(X) > 0])
        return X[keep], W[keep], is_node[keep]

    def load(self, d, g):
        X, W, _ = self._w_breakpoints(d, g)
        return 2.0 * self.S.Estar * line_integral(X, W)

    def solve_normal(self):
        """Force control: d with 2 E* int (d - g)_+ dx = P. Newton from above
        on a convex increasing function converges monotonically."""
        S, g = self.S, self.g()
        d = g.min() + 2.0 * (self.S.a_hertz ** 2 / S.R) + (0.0 if self.d is None else max(self.d - g.min(), 0.0))
        for _ in range(200):
            X, W, _ = self._w_breakpoints(d, g)
            P = 2.0 * S.Estar * line_integral(X, W)
            # dP/dd = 2 E* |{g < d}|
            inside = W > 0
            seg_in = inside[:-1] | inside[1:]
            dP = 2.0 * S.Estar * float(np.sum(np.diff(X)[seg_in]))
            step = (P - S.P) / dP
            d -= step
            if abs(step) < 1e-15 * max(abs(d), 1e-30) or abs(P - S.P) < 1e-13 * S.P:
                break
        self.d = d
        self._set_contact(g)

    def _set_contact(self, g):
        S = self.S
        X, W, is_node = self._w_breakpoints(self.d, g)
        self.X, self.W, self.is_node = X, W, is_node
        self.w_nodes = np.maximum(self.d - g, 0.0)
        self.L = S.mu * (S.Estar / S.Gstar) * self.w_nodes          # slip limits |u| <= L
        self.qw = 2.0 * line_weights(X)[is_node]                    # int over -x..x of node values
        pos = np.nonzero(W > 0)[0]
        if pos.size and X[pos[-1]] >= self.r[-1]:
            raise ValueError("the contact reaches the grid's edge r = %.4g m: raise rmax_over_a" % self.r[-1])
        # the contact edge is the breakpoint after the last positive one (a root)
        self.a = float(X[min(pos[-1] + 1, X.size - 1)]) if pos.size else 0.0
        # a spring leaving contact carries nothing; one whose limit shrank slips
        self.u = np.clip(self.u, -self.L, self.L)

    def pressure(self, r=None):
        r = self.r if r is None else r
        return self.S.Estar * abel_down(self.X, self.W, r)

    def _fields(self, u_old, u_new):
        """p, tau, 3-D u(u_old), 3-D u(u_new) at the nodes, computed only on
        the nodes and breakpoints up to the contact edge (zero beyond)."""
        nX = int(np.searchsorted(self.X, self.a, side="right"))
        nX = max(min(nX, self.X.size), 2)
        X = self.X[:nX]
        nr = int(np.searchsorted(self.r, self.a, side="right"))
        r = self.r[:nr]
        Vu = np.zeros((2, self.X.size))
        Vu[0, self.is_node] = u_old
        Vu[1, self.is_node] = u_new
        Vu = Vu[:, :nX]
        d = abel_down(X, np.vstack([self.S.Estar * self.W[:nX], self.S.Gstar * Vu[1]]), r)
        up = abel_up(X, Vu, r)
        out = np.zeros((4, self.r.size))
        out[0, :nr], out[1, :nr], out[2, :nr], out[3, :nr] = d[0], d[1], up[0], up[1]
        return out

    def _on_X(self, nodal):
        V = np.zeros_like(self.X)
        V[self.is_node] = nodal
        return V

    def shear(self, r=None):
        r = self.r if r is None else r
        return self.S.Gstar * abel_down(self.X, self._on_X(self.u), r)

    def u3d(self, u=None):
        """3-D tangential surface displacement at the nodes from the 1-D one."""
        u = self.u if u is None else u
        return abel_up(self.X, self._on_X(u), self.r)

    def Q(self, u=None):
        u = self.u if u is None else u
        return self.S.Gstar * float(self.qw @ u)

    # -- tangential ----------------------------------------------------------
    def _trial(self, dd):
        return np.clip(self.u + dd, -self.L, self.L)

    def shift_for_force(self, Qt):
        """Rigid increment dd giving tangential force Qt (exact: Q(dd) is
        piecewise linear between the springs' slip thresholds)."""
        act = self.L > 0
        u, L, w = self.u[act], self.L[act], self.qw[act]
        B = np.unique(np.concatenate([L - u, -L - u]))
        Qs = self.S.Gstar * (np.clip(u[None, :] + B[:, None], -L, L) @ w)
        if not (Qs[0] < Qt < Qs[-1]):
            raise ValueError("tangential force %.6g outside (-muP, muP) = (%.6g, %.6g)" % (Qt, Qs[0], Qs[-1]))
        j = np.searchsorted(Qs, Qt)
        j = min(max(j, 1), B.size - 1)
        return B[j - 1] + (Qt - Qs[j - 1]) * (B[j] - B[j - 1]) / (Qs[j] - Qs[j - 1])

    def stick_radius(self, trial_before_clip):
        """c from phi = L - |trial| (>0: stick) by root in s between nodes."""
        act = self.L > 0
        phi = self.L - np.abs(trial_before_clip)
        idx = np.nonzero(act)[0]
        if idx.size == 0:
            return 0.0
        ph = phi[idx]
        if ph[0] <= 0:
            return 0.0
        bad = np.nonzero(ph <= 0)[0]
        if bad.size == 0:
            return self.a
        j = idx[bad[0]]
        i = j - 1
        s = self.r ** 2
        sc = s[i] + (s[j] - s[i]) * phi[i] / (phi[i] - phi[j])
        return math.sqrt(sc)

    def step(self, target, control, k_wear=0.0, alpha_wear=0.0, M=1.0, apply_wear=True):
        """One increment: move to force (control='force') or shift
        (control='disp') `target`; returns dict of increment results."""
        if control == "force":
            dd = self.shift_for_force(target)
        else:
            dd = target - self.delta
        trial = self.u + dd
        u_old = self.u
        u_new = np.clip(trial, -self.L, self.L)
        # 1-D dissipated energy: each spring slips by dd - du at its end force
        slip1d = dd - (u_new - u_old)
        e1d = self.S.Gstar * float(self.qw @ np.abs(u_new * slip1d))
        # 3-D slip of the substrate relative to the sphere
        self.u = u_new
        self.delta += dd
        p, tau, us_old, us_new = self._fields(u_old, u_new)
        ds = dd - (us_new - us_old)
        incontact = self.w_nodes > 0
        ds = np.where(incontact, ds, 0.0)
        e3d = float(self.area_w @ np.abs(tau * ds))
        dh = np.maximum(k_wear * p * np.abs(ds) + alpha_wear * np.abs(tau * ds), 0.0)
        c = self.stick_radius(trial)
        out = dict(dd=dd, Q=self.Q(), delta=self.delta, e1d=e1d, e3d=e3d, c=c,
                   dV=float(self.area_w @ dh), dh=dh, p=p, tau=tau, ds=ds)
        if apply_wear and np.any(dh > 0):
            out["dh"] = self._apply_wear(M, k_wear, alpha_wear, ds, dh)
            out["dV"] = float(self.area_w @ out["dh"])
        return out

    substeps_max = 0      # the most sub-steps one increment needed (diagnostic)
    theta = 0.5           # sub-step bound on M (k + alpha mu) |ds| E*/h_cell

    def _apply_wear(self, M, k_wear, alpha_wear, ds, dh):
        """Apply M times this increment's wear, in sub-steps small enough for
        the explicit update to be stable: the pressure answers a depth change
        on one cell of width h_cell with about E*/h_cell per unit depth, so a
        step of M (k + alpha mu)|ds| E*/h_cell above O(1) overshoots (the
        oscillation of PHYSICS.md 5d). Between sub-steps the normal problem
        is re-solved and p (and tau) re-evaluated; ds is held. Returns the
        wear depth applied per physical cycle."""
        hx = self.r[1] - self.r[0]
        lam = M * (k_wear + alpha_wear * self.S.mu) * np.abs(ds) * self.S.Estar / hx
        nsub = max(1, int(math.ceil(float(lam.max()) / self.theta)))
        self.substeps_max = max(self.substeps_max, nsub)
        total = np.zeros_like(dh)
        for i in range(nsub):
            if i > 0:
                p = self.pressure()
                tau = self.shear()
                dh = np.maximum(k_wear * p * np.abs(ds) + alpha_wear * np.abs(tau * ds), 0.0)
            self.h = self.h + (M / nsub) * dh
            total += dh / nsub
            self.solve_normal()
        return total


# ----------------------------------------------------------------------------
# Fretting cycles with cycle jumping
# ----------------------------------------------------------------------------

def cycle_targets(A, N):
    """0 -> +A -> -A -> 0 with N increments per quarter (2N for the half)."""
    up = A * np.arange(1, N + 1) / N
    down = A - 2.0 * A * np.arange(1, 2 * N + 1) / (2 * N)
    back = -A + A * np.arange(1, N + 1) / N
    return np.concatenate([up, down, back]), N  # index N-1 is the +A turning point


def fretting(setup: Setup, amplitude, control="force", cycles=1, N=20,
             k_wear=0.0, alpha_wear=0.0, M=1.0, save_every=1, apply_wear=True,
             model: MDRContact | None = None, jump="increment"):
    """Simulate `cycles` computed cycles 0 -> +A -> -A -> 0; each stands for M
    physical cycles. Cycle jumping: each increment's wear is multiplied by M
    and applied at once, the normal problem re-solved before the next
    increment (the wear is spread over the 4N increments of the cycle, not
    applied as one block at its end: see README, PHYSICS.md 5d).
    jump="block" applies the cycle's wear times M at the cycle's end instead
    (kept to show the block scheme's behaviour, not recommended)."""
    m = model or MDRContact(setup)
    tg, iA = cycle_targets(amplitude, N)
    recs = []
    phys = 0.0
    for cyc in range(cycles):
        e1 = e3 = 0.0
        Qs, ds_, cA, gross = [], [], None, False
        dh_cyc = np.zeros_like(m.r)
        loop = [(m.delta, m.Q())]
        for i, t in enumerate(tg):
            o = m.step(t, control, k_wear, alpha_wear, M, apply_wear and jump == "increment")
            e1 += o["e1d"]
            e3 += o["e3d"]
            dh_cyc += o["dh"]
            Qs.append(o["Q"])
            ds_.append(o["delta"])
            loop.append((o["delta"], o["Q"]))
            if o["c"] == 0.0:
                gross = True
            if i == iA - 1:
                cA = o["c"]
        phys += M
        if apply_wear and jump == "block" and np.any(dh_cyc > 0):
            m.h = m.h + M * dh_cyc
            m.solve_normal()
        Vc = float(m.area_w @ dh_cyc)
        if (cyc + 1) % save_every == 0 or cyc == cycles - 1 or cyc == 0:
            recs.append(CycleRecord(
                cycle=phys, r=m.r.copy(), h=m.h.copy(), volume=float(m.area_w @ m.h),
                max_depth=float(m.h.max()), a=m.a, c=cA,
                F_amp=0.5 * (max(Qs) - min(Qs)), d_amp=0.5 * (max(ds_) - min(ds_)),
                energy=e1, energy3d=e3, wear_volume_cycle=Vc,
                regime="gross" if gross else "partial", dh_cycle=dh_cyc, loop=np.array(loop)))
    return m, recs


# ----------------------------------------------------------------------------
# Closed forms
# ----------------------------------------------------------------------------

def md_first(S, Q):
    return S.delta_star * (1.0 - (1.0 - Q / (S.mu * S.P)) ** (2.0 / 3.0))


def md_unload(S, Qs, Q):
    mP = S.mu * S.P
    return S.delta_star * (2.0 * (1.0 - (Qs - Q) / (2.0 * mP)) ** (2.0 / 3.0) - (1.0 - Qs / mP) ** (2.0 / 3.0) - 1.0)


def md_energy(S, Qs):
    mP = S.mu * S.P
    x = Qs / mP
    K = 4.0 / S.Gstar
    return 9.0 * S.mu ** 2 * S.P ** 2 * K / (10.0 * S.a_hertz) * (
        1.0 - (1.0 - x) ** (5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + (1.0 - x) ** (2.0 / 3.0)))


def ciavarella_hills(S, c, r):
    """Limit pressure of partial-slip fretting under force control."""
    out = np.zeros_like(r)
    m = r < c
    rr = r[m]
    out[m] = 2.0 * S.Estar / (np.pi * S.R) * np.sqrt(c * c - rr * rr) + \
        (S.P - 4.0 * S.Estar * c ** 3 / (3.0 * S.R)) / (2.0 * np.pi * c * np.sqrt(c * c - rr * rr))
    return out


# ----------------------------------------------------------------------------
# Checks
# ----------------------------------------------------------------------------

class Checker:
    def __init__(self):
        self.fails = 0
        self.rows = []

    def rel(self, name, value, ref, tol):
        err = abs(value - ref) / abs(ref)
        ok = err < tol
        self.fails += (not ok)
        print("%-62s %14.7e  ref %14.7e  rel.err %.2e < %.0e  %s" % (name, value, ref, err, tol, "PASS" if ok else "FAIL"))
        sys.stdout.flush()
        return ok

    def cond(self, name, ok, detail):
        self.fails += (not ok)
        print("%-62s %s  %s" % (name, detail, "PASS" if ok else "FAIL"))
        sys.stdout.flush()
        return ok


def check_transform(ch):
    """MDR transform of f = r^4/R^3: g = (8/3) x^4/R^3; second order in h."""
    R = 1.0
    errs = []
    for n in (100, 200, 400):
        r = np.linspace(0.0, 1.0, n)
        g = mdr_profile_matrix(r) @ (r ** 4 / R ** 3)
        errs.append(np.max(np.abs(g - 8.0 / 3.0 * r ** 4)) / (8.0 / 3.0))
    order = math.log2(errs[1] / errs[2])
    # pointwise order 1.5: the interpolation error of f' in the last cell
    # meets the kernel's 1/sqrt(x - r) singularity
    ch.cond("MDR transform f=r^4 -> g=(8/3)x^4, max err n=100/200/400",
            errs[2] < 2e-4 and 1.3 < order < 2.2,
            "%.2e %.2e %.2e (order %.2f)" % (*errs, order))
    # inverse map back (abel_up) of g = x^2/R gives f = r^2/(2R)
    r = np.linspace(0.0, 1.0, 200)
    f = abel_up(r, r ** 2, r)
    e = np.max(np.abs(f - r ** 2 / 2.0))
    ch.cond("inverse MDR map of g=x^2 -> f=r^2/2 (exact for quadratics)", e < 1e-12, "%.1e" % e)


def check_hertz(ch, S):
    m = MDRContact(S)
    a_ex = S.a_hertz
    d_ex = a_ex ** 2 / S.R
    ch.rel("Hertz a = sqrt(R d)", m.a, math.sqrt(S.R * m.d), 1e-3)
    ch.rel("Hertz a = (3PR/4E*)^(1/3)", m.a, a_ex, 1e-3)
    ch.rel("Hertz P = 4/3 E* sqrt(R) d^1.5 (at the solved d)", 4.0 / 3.0 * S.Estar * math.sqrt(S.R) * m.d ** 1.5, S.P, 1e-3)
    ch.rel("Hertz d = a^2/R", m.d, d_ex, 1e-3)
    p = m.pressure()
    pe = 2 * S.Estar / (np.pi * S.R) * np.sqrt(np.maximum(a_ex ** 2 - m.r ** 2, 0))
    e = np.max(np.abs(p - pe)) / pe[0]
    ch.cond("Hertz max|p - 2E*/(pi R) sqrt(a^2-r^2)| / p0 < 1e-3", e < 1e-3, "%.2e" % e)
    ch.rel("Hertz int p dA = P", float(m.area_w @ p), S.P, 1e-3)
    # convergence of the load integral of the (discrete) pressure
    errs = []
    for n in (100, 200, 400, 800):
        mm = MDRContact(Setup(**{**S.__dict__, "n": n}))
        errs.append(abs(float(mm.area_w @ mm.pressure()) - S.P) / S.P)
    ch.cond("Hertz: |int p dA - P|/P with n = 100/200/400/800 shrinks",
            all(errs[i + 1] < errs[i] for i in range(3)),
            " ".join("%.2e" % e for e in errs))


def check_mindlin(ch, S, label, N=20):
    mP = S.mu * S.P
    Qs = 0.6 * mP
    m = MDRContact(S)
    # first loading to Q*
    for t in Qs * np.arange(1, N + 1) / N:
        o = m.step(t, "force")
    ch.rel("%s c/a = (1 - Q/muP)^(1/3), Q = 0.6 muP" % label, o["c"] / m.a, (1 - Qs / mP) ** (1 / 3), 5e-3)
    ch.rel("%s delta = delta*[1-(1-Q/muP)^(2/3)]" % label, m.delta, md_first(S, Qs), 2e-3)
    # 3-D traction: Mindlin q = mu p - mu p_c (ellipsoids of radii a, c)
    c = S.a_hertz * (1 - Qs / mP) ** (1 / 3)
    tau = m.shear()
    qex = S.mu * 2 * S.Estar / (np.pi * S.R) * (np.sqrt(np.maximum(S.a_hertz ** 2 - m.r ** 2, 0))
                                                 - np.sqrt(np.maximum(c ** 2 - m.r ** 2, 0)))
    err = float(m.area_w @ np.abs(tau - qex)) / Qs
    ch.cond("%s int|tau - Mindlin q| dA / Q < 1e-2" % label, err < 1e-2, "%.2e" % err)
    # 3-D displacement in the stick zone equals the rigid shift
    us = m.u3d()
    st = m.r < 0.95 * c
    e = np.max(np.abs(us[st] - m.delta)) / m.delta
    ch.cond("%s 3-D u_x = delta in the stick zone" % label, e < 1e-9, "%.1e" % e)
    # unloading to Q = 0 and on to -Q*
    Qp = np.concatenate([Qs - 2 * Qs * np.arange(1, 2 * N + 1) / (2 * N)])
    qd = [(m.delta, m.Q())]
    for t in Qp:
        o = m.step(t, "force")
        qd.append((m.delta, m.Q()))
        if abs(t) < 1e-12 * Qs:
            ch.rel("%s Mindlin-Deresiewicz unloading delta(Q*->0)" % label, m.delta, md_unload(S, Qs, 0.0), 2e-3)
    # a full closed cycle -Q* -> +Q* -> -Q* : energy
    e1 = 0.0
    e3 = 0.0
    pts = []
    for t in np.concatenate([-Qs + 2 * Qs * np.arange(1, 2 * N + 1) / (2 * N), Qs - 2 * Qs * np.arange(1, 2 * N + 1) / (2 * N)]):
        o = m.step(t, "force")
        e1 += o["e1d"]
        e3 += o["e3d"]
        pts.append((m.delta, m.Q()))
    pts = np.array([qd[-1]] + pts)
    loop = float(np.sum(0.5 * (pts[1:, 1] + pts[:-1, 1]) * np.diff(pts[:, 0])))
    Wex = md_energy(S, Qs)
    ch.rel("%s energy/cycle (1-D springs) vs Mindlin-Deresiewicz" % label, e1, Wex, 5e-3)
    ch.rel("%s energy/cycle (3-D |tau.ds| dA) vs Mindlin-Deresiewicz" % label, e3, Wex, 1e-2)
    ch.cond("%s loop area |oint Q d delta| vs MD (trapezoid in N=%d)" % (label, N), abs(abs(loop) - Wex) / Wex < 2e-2,
            "%.4e vs %.4e (rel %.1e)" % (abs(loop), Wex, abs(abs(loop) - Wex) / Wex))


def check_gross_wear(ch, S):
    ds = S.delta_star
    Delta = 3.0 * ds
    k = 1e-9 * 1e-12  # tiny so that the profile barely changes within two cycles
    m, recs = fretting(S, Delta, "disp", cycles=2, N=40, k_wear=k, save_every=1)
    V1 = recs[0].wear_volume_cycle
    V2 = recs[1].wear_volume_cycle
    ch.rel("gross slip: V1 = 4kP(Delta - delta*), Delta = 3 delta*", V1, 4 * k * S.P * (Delta - ds), 1e-2)
    ch.rel("gross slip: V  = 4kP(Delta - 0.8 delta*) [sliding 4(D-0.8d*)]", V2, 4 * k * S.P * (Delta - 0.8 * ds), 1e-2)
    ch.rel("gross slip: energy/cycle (1-D) = 4 mu P (Delta - 0.8 delta*)", recs[1].energy, 4 * S.mu * S.P * (Delta - 0.8 * ds), 1e-2)
    ch.cond("gross slip: regime flag", recs[1].regime == "gross", recs[1].regime)
    al = 1e-21
    m, recs = fretting(S, Delta, "disp", cycles=2, N=40, alpha_wear=al)
    ch.rel("energy law: V = alpha * (1-D energy per cycle)", recs[1].wear_volume_cycle, al * recs[1].energy, 1e-2)
    ch.rel("energy law: V = alpha * 4 mu P (Delta - 0.8 delta*)", recs[1].wear_volume_cycle, al * 4 * S.mu * S.P * (Delta - 0.8 * ds), 1e-2)
    # partial slip, displacement control: Archard V = (k/mu) * energy at fixed pressure
    m, recs = fretting(S, 0.5 * ds, "disp", cycles=2, N=40, k_wear=k)
    Qs = S.mu * S.P * (1 - (1 - 0.5) ** 1.5)
    ch.rel("partial slip, Delta = delta*/2: energy vs MD at Q*=muP[1-(1-D/d*)^1.5]", recs[1].energy, md_energy(S, Qs), 1e-2)
    ch.rel("partial slip: Archard V = (k/mu) * MD energy (constant p)", recs[1].wear_volume_cycle, k / S.mu * md_energy(S, Qs), 2e-2)


def run_ciavarella_hills(S, cycles=60, M=None, N=10, verbose=True, frac=0.6):
    """Force-controlled partial slip with strong wear; returns rows."""
    mP = S.mu * S.P
    A = frac * mP
    d0 = S.a_hertz ** 2 / S.R
    m = MDRContact(S)
    # wear scale: k*M such that the first cycle removes ~1.5% of d0 at the peak
    k = 1e-9 * 1e-9
    probe = MDRContact(S)
    _, r0 = fretting(S, A, "force", cycles=1, N=N, k_wear=k, apply_wear=False, model=probe)
    Mj = M if M is not None else 0.015 * d0 / r0[0].dh_cycle.max()
    c0 = S.a_hertz * (1 - frac) ** (1 / 3)
    rows = []
    done = 0
    marks = [1, 3, 10, 30, cycles]
    for mk in marks:
        if mk > cycles:
            continue
        _, recs = fretting(S, A, "force", cycles=mk - done, N=N, k_wear=k, M=Mj, save_every=10 ** 9, model=m)
        done = mk
        p = m.pressure()
        pch = ciavarella_hills(S, c0, m.r)
        fin = np.isfinite(pch)
        dist = float(m.area_w[fin] @ np.abs(p[fin] - pch[fin])) / S.P
        pan = float(m.area_w[m.r > c0] @ np.maximum(p[m.r > c0], 0)) / S.P
        rows.append((mk, recs[-1].c / c0, pan, dist, recs[-1].max_depth / d0, recs[-1].regime))
        if verbose:
            print("   computed cycles %4d: c/c0 = %.4f  load in r>c0: %.4f P  int|p-p_CH|dA/P = %.4f  max depth/d0 = %.4f  %s" % rows[-1])
            sys.stdout.flush()
    return rows, Mj


def check_ciavarella_hills(ch, S):
    rows, Mj = run_ciavarella_hills(S)
    d = [r[3] for r in rows]
    ch.cond("Ciavarella-Hills: distance int|p-p_CH|dA/P shrinks", all(d[i + 1] < d[i] for i in range(len(d) - 1)),
            " -> ".join("%.3f" % x for x in d))
    ch.cond("Ciavarella-Hills: load left in the slip annulus shrinks",
            rows[-1][2] < 0.5 * rows[0][2], "%.4f -> %.4f" % (rows[0][2], rows[-1][2]))
    ch.cond("Ciavarella-Hills: stick radius stays (|c/c0 - 1| < 2%)",
            all(abs(r[1] - 1) < 0.02 for r in rows), " ".join("%.4f" % r[1] for r in rows))


def check_disp_partial_slip(ch, S, cycles=60):
    """Partial slip under an imposed displacement amplitude (the one that
    gives Q* = 0.6 muP on the unworn sphere): c grows by about 1.5% and
    stops (PHYSICS.md 5d), the force amplitude falls."""
    mP = S.mu * S.P
    d0 = S.a_hertz ** 2 / S.R
    k = 1e-18
    A = md_first(S, 0.6 * mP)
    _, r0 = fretting(S, A, "disp", cycles=1, N=10, k_wear=k, apply_wear=False)
    Mj = 0.015 * d0 / r0[0].dh_cycle.max()
    c0 = S.a_hertz * 0.4 ** (1 / 3)
    m = MDRContact(S)
    rows, done = [], 0
    for mk in (1, 3, 10, 30, cycles):
        _, rr = fretting(S, A, "disp", cycles=mk - done, N=10, k_wear=k, M=Mj, model=m, save_every=10 ** 9)
        done = mk
        x = rr[-1]
        rows.append((mk, x.c / c0, x.F_amp / mP, x.max_depth / d0, x.energy))
        print("   computed cycles %4d: c/c0 = %.4f  F*/muP = %.4f  max depth/d0 = %.4f  energy/cycle = %.3e J" % rows[-1])
        sys.stdout.flush()
    g = rows[-1][1] - 1.0
    ch.cond("imposed displacement: c grows by ~1.5% and stops (c/c0 - 1, last change)",
            0.01 < g < 0.02 and abs(rows[-1][1] - rows[-2][1]) < 1e-3,
            "%.4f, %.1e" % (g, abs(rows[-1][1] - rows[-2][1])))


def check_jump(ch, S):
    """Cycle jumping. The per-increment scheme (each increment's wear times M,
    normal problem re-solved at once) converges at first order in M: the
    worn profile after the same physical cycle count with M, M/2, M/4. The
    block scheme (one cycle's wear times M at the cycle's end) at the same M
    diverges on this grid (PHYSICS.md 5d's warning)."""
    S = Setup(**{**S.__dict__, "n": 200})
    mP = S.mu * S.P
    k = 1e-18
    A = 0.6 * mP
    d0 = S.a_hertz ** 2 / S.R
    _, r0 = fretting(S, A, "force", cycles=1, N=10, k_wear=k, apply_wear=False)
    M = 0.02 * d0 / r0[0].dh_cycle.max()   # first cycle removes 2% of d0
    hs = []
    for j, cyc in enumerate((3, 6, 12)):
        _, rr = fretting(S, A, "force", cycles=cyc, N=10, k_wear=k, M=M / 2 ** j, save_every=10 ** 9)
        hs.append(rr[-1].h)
    d1 = np.max(np.abs(hs[0] - hs[1])) / hs[2].max()
    d2 = np.max(np.abs(hs[1] - hs[2])) / hs[2].max()
    ch.cond("jump per increment, n=200: max|h_M - h_M/2|, max|h_M/2 - h_M/4| (/max h)",
            1.6 < d1 / d2 < 2.4 and d2 < 0.05,
            "%.3e %.3e (ratio %.2f: first order in M; M=%.3g, %.3g cycles)" % (d1, d2, d1 / d2, M, 3 * M))
    m = MDRContact(S)
    depth, status = [], "bounded"
    for _ in range(5):
        try:
            _, rr = fretting(S, A, "force", cycles=1, N=10, k_wear=k, M=M, jump="block", model=m)
            depth.append(rr[-1].max_depth / d0)
        except (ValueError, ZeroDivisionError, FloatingPointError):
            status = "solver broke down"
            break
    diverged = status != "bounded" or depth[-1] > 10.0
    ch.cond("block jump at the same M, n=200: max depth/d0 per cycle diverges (5d)", diverged,
            " ".join("%.3g" % x for x in depth) + (" " + status if status != "bounded" else ""))


def convergence_study(S=None, ns=(100, 200, 400, 800), cycles=10, first_cycle_depth=0.002):
    """Grid study of a force-controlled partial-slip wear run (Q* = 0.6 muP),
    the same M on every grid, M small (the first cycle removes
    `first_cycle_depth` of d0) so that the M error (first order) does not
    mask the grid error: worn volume, max depth, 1-D energy of the last cycle
    and c/c0, with relative differences between successive grids."""
    S = S or Setup()
    mP = S.mu * S.P
    k = 1e-18
    d0 = S.a_hertz ** 2 / S.R
    _, r0 = fretting(S, 0.6 * mP, "force", cycles=1, N=10, k_wear=k, apply_wear=False)
    M = first_cycle_depth * d0 / r0[0].dh_cycle.max()
    c0 = S.a_hertz * 0.4 ** (1 / 3)
    print("%d computed cycles, M = %.4g (%.4g physical cycles)" % (cycles, M, cycles * M))
    print("n      volume[m^3]    max depth[m]   energy[J]      c/c0     substeps")
    prev = None
    for n in ns:
        Sn = Setup(**{**S.__dict__, "n": n})
        m, rec = fretting(Sn, 0.6 * mP, "force", cycles=cycles, N=10, k_wear=k, M=M, save_every=10 ** 9)
        x = rec[-1]
        row = (x.volume, x.max_depth, x.energy, x.c / c0)
        print("%-6d %.6e   %.6e   %.6e   %.5f  %d" % ((n,) + row + (m.substeps_max,)) +
              ("" if prev is None else "   rel. diffs to previous: %.1e %.1e %.1e" % tuple(abs(row[i] - prev[i]) / abs(row[i]) for i in range(3))))
        sys.stdout.flush()
        prev = row


def run_case(args):
    """A fretting-wear history for one case, printed per saved cycle; the worn
    profiles and pressures go to a CSV if asked (columns r, then h and p per
    saved cycle)."""
    S = Setup(R=args.radius_mm * 1e-3, E=args.E_gpa * 1e9, nu=args.nu, mu=args.mu,
              P=args.normal_n, n=args.nodes, rmax_over_a=args.rmax_over_a)
    mP = S.mu * S.P
    if args.control == "force":
        A = args.amplitude_ratio * mP
    else:
        A = args.disp_um * 1e-6 if args.disp_um is not None else args.amplitude_ratio * S.delta_star
    m = MDRContact(S)
    print("# a_Hertz = %.6e m, d0 = %.6e m, delta* = %.6e m, E* = %.6e Pa, G* = %.6e Pa, %s amplitude %.6e"
          % (S.a_hertz, S.a_hertz ** 2 / S.R, S.delta_star, S.Estar, S.Gstar, args.control, A))
    print("# cycles are physical (computed cycles x M); k = %g m^3/(N m), alpha = %g m^3/J, M = %g, jump = %s"
          % (args.k_mm3_per_Nm * 1e-9, args.alpha_mm3_per_J * 1e-9, args.M, args.jump))
    print("cycle,volume_m3,max_depth_m,a_m,c_m,F_amp_N,delta_amp_m,energy_J,energy3d_J,wear_volume_per_cycle_m3,regime")
    cols, names = [m.r], ["r_m"]
    _, recs = fretting(S, A, args.control, cycles=args.cycles, N=args.steps, k_wear=args.k_mm3_per_Nm * 1e-9,
                       alpha_wear=args.alpha_mm3_per_J * 1e-9, M=args.M, save_every=args.save_every,
                       model=m, jump=args.jump)
    for x in recs:
        print("%.6g,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%s" % (
            x.cycle, x.volume, x.max_depth, x.a, x.c, x.F_amp, x.d_amp, x.energy, x.energy3d, x.wear_volume_cycle, x.regime))
        cols.append(x.h)
        names.append("h_m@%g" % x.cycle)
    cols.append(m.pressure())
    names.append("p_Pa@end")
    if args.csv:
        np.savetxt(args.csv, np.column_stack(cols), delimiter=",", header=",".join(names), comments="")
        print("# profiles written to %s" % args.csv)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="run the self-checks (exit 1 on any FAIL)")
    ap.add_argument("--convergence", action="store_true", help="grid study of a partial-slip wear run")
    ap.add_argument("--run", action="store_true", help="one fretting-wear history (options below)")
    g = ap.add_argument_group("case (--run)")
    g.add_argument("--radius-mm", type=float, default=10.0)
    g.add_argument("--E-gpa", type=float, default=210.0)
    g.add_argument("--nu", type=float, default=0.0)
    g.add_argument("--mu", type=float, default=0.5)
    g.add_argument("--normal-n", type=float, default=100.0)
    g.add_argument("--control", choices=("force", "disp"), default="force")
    g.add_argument("--amplitude-ratio", type=float, default=0.6,
                   help="force control: F*/(mu P); disp control without --disp-um: Delta/delta*")
    g.add_argument("--disp-um", type=float, default=None, help="disp control: amplitude in um")
    g.add_argument("--cycles", type=int, default=20, help="computed cycles")
    g.add_argument("--steps", type=int, default=10, help="increments per quarter cycle")
    g.add_argument("--k-mm3-per-Nm", type=float, default=1e-6, help="Archard coefficient, mm^3/(N m)")
    g.add_argument("--alpha-mm3-per-J", type=float, default=0.0, help="energy wear coefficient, mm^3/J")
    g.add_argument("--M", type=float, default=1.0, help="physical cycles per computed cycle")
    g.add_argument("--jump", choices=("increment", "block"), default="increment")
    g.add_argument("--save-every", type=int, default=1)
    g.add_argument("--nodes", type=int, default=400)
    g.add_argument("--rmax-over-a", type=float, default=1.5,
                   help="grid extent / Hertz radius (the scar can outgrow a_Hertz: 1.18 a in the checks' partial-slip runs)")
    g.add_argument("--csv", default=None, help="write r, h(r) per saved cycle and the final p(r)")
    a = ap.parse_args(argv)
    t0 = time.time()
    if a.check:
        ch = Checker()
        S0 = Setup(nu=0.0)
        S3 = Setup(nu=0.3)
        print("# transforms"); check_transform(ch)
        print("# Hertz (nu = 0.3, n = %d)" % S3.n); check_hertz(ch, S3)
        print("# Cattaneo-Mindlin / Mindlin-Deresiewicz, nu = 0 (MDR exact)"); check_mindlin(ch, S0, "nu=0  ")
        print("# nu = 0.3: MDR with G* = 4G/(2-nu) reproduces Mindlin's (approximate, uncoupled) closed forms")
        check_mindlin(ch, S3, "nu=0.3")
        print("# wear: gross slip (Archard, energy law) and partial slip"); check_gross_wear(ch, S0)
        print("# cycle jumping"); check_jump(ch, S0)
        print("# partial slip under an imposed displacement (cycle jump: 1.5% of d0 in the first cycle)")
        check_disp_partial_slip(ch, S0)
        print("# partial-slip limit (Ciavarella & Hills 1999), force control, Q* = 0.6 muP (cycle jump: 1.5% of d0 in the first cycle)")
        check_ciavarella_hills(ch, S0)
        print("%d checks failed; %.1f s" % (ch.fails, time.time() - t0))
        return 1 if ch.fails else 0
    if a.convergence:
        convergence_study()
        return 0
    if a.run:
        run_case(a)
        return 0
    ap.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
