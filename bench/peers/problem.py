"""Paper Table 1a Hertz / Cattaneo–Mindlin problem shared by the peer scripts.

Rigid sphere (parabolic profile r²/2R) on an elastic half-space
E = 210 GPa, ν = 0.3; R = 18 mm, P = 20 N; square domain of side 4.5·a
centred on the contact, N×N cells, cell centres at (i − (N−1)/2)·h (the
contact centre is a cell corner, as in mpcontact's `Grid`).
Partial slip: μ = 0.28571, F = 0.6 μP, Cattaneo–Mindlin c/a = (1 − F/μP)^(1/3).

Also: running one peer job in a forked child (a crash or hang of a peer's
C++ code then gives an "ok": false line instead of killing the script), and
the JSON-line output.
"""

import json
import math
import multiprocessing as mp
import os
import sys
import time
import traceback

import numpy as np

E = 210e9
NU = 0.3
R = 18e-3
P = 20.0
E_STAR = E / (1.0 - NU**2)
A_HERTZ = (3.0 * P * R / (4.0 * E_STAR)) ** (1.0 / 3.0)
P_MAX_HERTZ = 3.0 * P / (2.0 * math.pi * A_HERTZ**2)
DELTA_HERTZ = A_HERTZ**2 / R  # Hertz approach
SIDE = 4.5 * A_HERTZ  # domain side, m

MU = 0.28571
F_RATIO = 0.6  # F = 0.6 μP
C_OVER_A_CM = (1.0 - F_RATIO) ** (1.0 / 3.0)  # 0.73681
STICK_MARGIN = 1e-6  # stick cells: |q| < μ p (1 − 1e-6)


def threads():
    """OMP_NUM_THREADS as set by the caller (int when it is one)."""
    v = os.environ.get("OMP_NUM_THREADS")
    if v is None:
        return None
    try:
        return int(v)
    except ValueError:
        return v


def grid(n, length_unit=1.0):
    """(h, X, Y, gap0) on the n×n grid; gap0 = r²/2R − min ≥ 0, in length_unit."""
    side = SIDE / length_unit
    h = side / n
    x = (np.arange(n) - 0.5 * (n - 1)) * h
    X, Y = np.meshgrid(x, x, indexing="ij")
    gap = (X * X + Y * Y) / (2.0 * R / length_unit)
    gap -= gap.min()
    return h, X, Y, gap


def normal_metrics(p, h):
    """Errors of a pressure field p (Pa, n×n) on cells of side h (m) vs Hertz."""
    contact = p > 0.0
    radius = math.sqrt(contact.sum() * h * h / math.pi)
    return {
        "pmax_err": float(p.max() / P_MAX_HERTZ - 1.0),
        "radius_err": float(radius / A_HERTZ - 1.0),
        "load_err": float(p.sum() * h * h / P - 1.0),
    }


def slip_metrics(p, qx, qy, h, mu=MU):
    """normal_metrics plus c/a: stick radius over contact radius (equivalent circles)."""
    m = normal_metrics(p, h)
    contact = p > 0.0
    q = np.hypot(qx, qy)
    stick = contact & (q < mu * p * (1.0 - STICK_MARGIN))
    c_over_a = math.sqrt(stick.sum() / contact.sum()) if contact.any() else float("nan")
    m.update(
        {
            "c_over_a": c_over_a,
            "c_over_a_err": c_over_a / C_OVER_A_CM - 1.0,
            "fx_err": float(qx.sum() * h * h / (F_RATIO * mu * P) - 1.0),
            "fy_over_f": float(qy.sum() * h * h / (F_RATIO * mu * P)),
        }
    )
    return m


def emit(obj):
    """One JSON object per line on stdout."""
    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, (np.floating, np.integer)):
            return clean(v.item())
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    sys.stdout.write(json.dumps(clean(obj)) + "\n")
    sys.stdout.flush()


def _child(conn, fn, args):
    try:
        conn.send(("ok", fn(*args)))
    except BaseException as e:  # noqa: BLE001 — report everything to the parent
        conn.send(("err", f"{type(e).__name__}: {e}", traceback.format_exc()))
    finally:
        conn.close()


def run_isolated(fn, args, timeout=None):
    """Run fn(*args) in a forked child. Returns (result, None) or (None, error)."""
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(child, fn, args))
    t0 = time.perf_counter()
    proc.start()
    child.close()
    msg = None
    try:
        if parent.poll(timeout):
            msg = parent.recv()
    except EOFError:
        msg = None
    if msg is None and proc.is_alive():
        proc.kill()
        proc.join()
        return None, f"exceeded the time budget of {timeout:g} s (killed after {time.perf_counter() - t0:.1f} s)"
    proc.join()
    if msg is None:
        return None, f"peer process died (exit code {proc.exitcode})"
    if msg[0] == "ok":
        return msg[1], None
    sys.stderr.write(msg[2])
    return None, msg[1]


class CaptureFds:
    """Redirect fds 1 and 2 (C++ loggers write there) into a file; .text afterwards."""

    def __enter__(self):
        import tempfile

        sys.stdout.flush()
        sys.stderr.flush()
        self._f = tempfile.TemporaryFile()
        self._saved = (os.dup(1), os.dup(2))
        os.dup2(self._f.fileno(), 1)
        os.dup2(self._f.fileno(), 2)
        return self

    def __exit__(self, *exc):
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(self._saved[0], 1)
        os.dup2(self._saved[1], 2)
        for fd in self._saved:
            os.close(fd)
        self._f.seek(0)
        self.text = self._f.read().decode(errors="replace")
        self._f.close()
        return False
