#!/usr/bin/env python3
"""Capped normal contact (pressure ≤ hardness H, issue #50) side by side with peers.

    MPCONTACT_EXE=target/release/mpcontact \\
      bench/.venv/bin/python bench/peers/hardness_peers.py --sizes 64,128 --ratios 0.8,0.4

The case: paper Table 1(a) (problem.py: rigid sphere R = 18 mm on Fe, E* =
230.8 GPa, P = 20 N, Hertz a_H = 105.4 µm, p0 = 860 MPa), frictionless, on
an elastic–perfectly plastic surface of hardness H = ratio × p0, N×N cells
over problem.py's domain (side 4.5 a_H, cell centres (i − (N−1)/2)·h, the
gap h0 = r²/2R − min). mpcontact (`solve`, `[materials.Fe] hardness_gpa`)
against

* contactmechanics 1.8.3 — `constrained_conjugate_gradients(...,
  hardness=H·h²)` on a `FreeFFTElasticHalfSpace` (non-periodic, zero-padded):
  the same discrete problem as ours;
* tamaas 2.9.0 `KatoSaturated` — (a) with the non-periodic "dcfft" operator
  on the same grid, (b) periodic (its default) on a grid `--pad` times wider
  at the same cell size, compared on the central N×N window.

tamaas's Kato iteration steps by one in whatever units the problem is posed
in (its iteration count scales with the length unit: measured, not read from
its source), so it converges only when posed dimensionless: pressures in
units of E* (E = 1, ν = 0), lengths in units of L (model size side/L; L =
a_H/2 here: L = side converges too but takes ~9× more iterations; 64²,
H = 0.8 p0: L = side/16 converged in 114, L = side/24 did not). Posed in SI units (E = 210e9,
metres) the pressure stays at its start, the uniform mean P/side², and the
error at its initial value (1.53 dcfft, 1.58 periodic); `--demo-si` shows it
(at 64² the SI solve also stopped logging after ~1500 iterations and did not
return). The periodic peer solves a different discrete problem: its
Westergaard operator applies the continuous kernel 2/(E*|q|) to the FFT of
the cell values, where ours and the others integrate a uniform pressure over
each cell (Love), so it differs from them by about 1 % of H at the contact
edge, shrinking with h; its domain effect (images of the contact) is far
smaller, ~7e-4 H at --pad 4, falling 8× per doubling of the pad.

Per row: the load check ΣpΔA/P − 1; the contact radius a (circle of the
area of the cells with p > 0) and the plastic radius b (cells at H) over
a_H; the approach δz (rigid-body normal displacement from the lowest cell
centre's gap; not defined for the periodic model, whose displacement has
zero mean); against mpcontact on the same grid: max |Δp|/H cell by cell,
max |Δdent| over mpcontact's largest dent, δz relative difference; and the
counts of contact and plastic cells. For the periodic
peer max |Δp| also holds the pressure outside the window.

Prints a markdown table (and with --json one JSON object per row).
Runs with one thread: set OMP_NUM_THREADS=1; mpcontact gets --threads 1.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # no __pycache__ in the work tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402

import problem as pb  # noqa: E402

CAP_REL = 1e-9  # a cell is "at H" when p ≥ H (1 − CAP_REL)
PEERS = ("contactmechanics", "tamaas-dcfft", "tamaas-periodic")
TOL = {"mpcontact": 1e-10, "contactmechanics": 1e-9, "tamaas": 1e-12}
MAX_ITER = 50000
# tamaas's Kato iteration steps by one in the units the problem is posed in, so
# the units set its step: with E* = 1 and lengths in units of a_H/2 (side/9 on
# problem.py's domain) it converges in 1–3 n iterations on n×n cells; in units
# of the side it needs ~9× more; at 64², H = 0.8 p0, side/16 converged (114
# iterations) and side/24 did not; in SI units it does not move.
TAMAAS_LENGTH_UNIT = pb.A_HERTZ / 2


def gap0(n, h):
    """Undeformed gap r²/2R − min on the n×n grid of cell size h (m)."""
    x = (np.arange(n) - 0.5 * (n - 1)) * h
    X, Y = np.meshgrid(x, x, indexing="ij")
    g = (X * X + Y * Y) / (2.0 * pb.R)
    return g - g.min()


# ---------------------------------------------------------------------- mpcontact
def run_mpcontact(exe, n, H, workdir):
    h = pb.SIDE / n
    cfg = os.path.join(workdir, f"case-{n}.toml")
    with open(cfg, "w") as f:
        f.write(
            f"""[grid]
points = {n}
spacing_um = {h * 1e6!r}

[indenter]
radius_mm = {pb.R * 1e3!r}

[load]
normal_n = {pb.P!r}
friction = 0.0
tangential_ratio = 0.0

[sweep]
materials = ["Fe"]
surfaces = ["flat"]
angles_deg = [0.0]

[solver]
coupling = false
tolerance = {TOL["mpcontact"]!r}
max_iterations = 5000

[materials.Fe]
hardness_gpa = {H / 1e9!r}
"""
        )
    out = os.path.join(workdir, f"out-{n}-{H:.0f}")
    t0 = time.perf_counter()
    subprocess.run([exe, "solve", cfg, "--out", out, "--threads", "1", "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)
    secs = time.perf_counter() - t0
    case = json.load(open(os.path.join(out, "case.json")))
    if not case.get("converged"):
        raise RuntimeError(f"mpcontact did not converge: {out}/case.json")
    if abs(case["spacing_m"] / h - 1.0) > 1e-12:
        raise RuntimeError(f"mpcontact's cell {case['spacing_m']} m is not {h} m")
    p = np.load(os.path.join(out, "p.npy"))
    dent = np.load(os.path.join(out, "plastic.npy"))
    return {"p": p, "dent": dent, "delta": case["delta_z_m"], "iterations": case["normal"]["iterations"],
            "seconds": secs, "h": h}


# ---------------------------------------------------------------- contactmechanics
def run_contactmechanics(n, H, tol):
    from ContactMechanics import FreeFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography

    h = pb.SIDE / n
    g0 = gap0(n, h)
    # young = contact modulus E* (poisson left at 0 means "young is E*").
    substrate = FreeFFTElasticHalfSpace((n, n), pb.E_STAR, (pb.SIDE, pb.SIDE))
    heights = np.ascontiguousarray(-g0)  # the rigid surface, highest point 0
    topo = Topography(heights, physical_sizes=(pb.SIDE, pb.SIDE))
    t0 = time.perf_counter()
    r = constrained_conjugate_gradients(
        substrate, topo, hardness=H * h * h,  # a force per pixel
        external_force=pb.P, pentol=tol * pb.DELTA_HERTZ, forcetol=tol * pb.P_MAX_HERTZ * h * h,
        thermotol=tol, maxiter=MAX_ITER)
    secs = time.perf_counter() - t0
    if not r.success:
        raise RuntimeError(f"CCG did not converge: {r.message} after {r.nit} iterations")
    p = np.asarray(r.jac, dtype=float) / (h * h)  # jac: pixel forces, compressive > 0
    u = np.asarray(r.x, dtype=float)[:n, :n]  # the padded displacement's physical part
    gap = u - heights - r.offset  # < 0 where the surface flowed
    dent = np.where(np.asarray(r.plastic, dtype=bool), np.maximum(-gap, 0.0), 0.0)
    return {"p": p, "dent": dent, "delta": float(r.offset), "iterations": int(r.nit), "seconds": secs, "h": h}


# ------------------------------------------------------------------------- tamaas
def run_tamaas(n, H, tol, periodic, pad, max_iter=MAX_ITER, si_units=False):
    """KatoSaturated on n×n (dcfft) or (pad·n)² (periodic) cells of the same size.

    Dimensionless: lengths / TAMAAS_LENGTH_UNIT, pressures / E* (si_units=True
    poses it in SI instead, to show that the fixed-step iteration then does not
    move)."""
    import tamaas as tm

    h = pb.SIDE / n
    m = n * (pad if periodic else 1)
    side = m * h
    g0 = gap0(m, h)
    L, S = (1.0, 1.0) if si_units else (TAMAAS_LENGTH_UNIT, pb.E_STAR)  # length and stress units
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [side / L, side / L], [m, m])
    if si_units:
        model.E, model.nu = pb.E, pb.NU
    else:
        model.E, model.nu = 1.0, 0.0  # E* = 1
    if not periodic:
        tm.ModelFactory.registerNonPeriodic(model, "dcfft")
    surface = np.ascontiguousarray(-g0 / L)  # tamaas: the rigid surface, gap = u − surface − offset
    solver = tm.KatoSaturated(model, surface, tol, H / S)
    if not periodic:
        solver.setIntegralOperator("dcfft")
    solver.max_iter = max_iter
    tm.set_log_level(tm.LogLevel.info)  # its log lines carry the iteration count
    t0 = time.perf_counter()
    with pb.CaptureFds() as cap:
        solver.solve(pb.P / side**2 / S)  # the mean pressure over the model
    secs = time.perf_counter() - t0
    rows = [ln.split() for ln in cap.text.splitlines()]
    rows = [r for r in rows if len(r) == 3 and r[0].isdigit()]
    its = max(int(r[0]) for r in rows) if rows else None
    err = float(solver.computeError())
    p_full = np.array(model.traction, dtype=float).reshape(m, m) * S
    res = {"iterations": its, "seconds": secs, "h": h, "solver_error": err, "first_error": float(rows[0][2]) if rows else None}
    if err > tol:
        raise RuntimeError(f"KatoSaturated did not converge: error {err:.3g} > {tol:g} after {its} iterations")
    if periodic:
        lo = (m - n) // 2
        p = p_full[lo:lo + n, lo:lo + n]
        res["p_outside"] = float(p_full.sum() - p.sum()) * h * h
        res.update({"p": p, "dent": None, "delta": None})
        res["p_outside_max"] = float(np.abs(np.delete(p_full.ravel(),
                                     np.ravel_multi_index(np.indices((n, n)).reshape(2, -1) + lo, (m, m)))).max())
        return res
    # displacement of the solved pressure by the same non-periodic operator
    u = np.zeros((m, m))
    model.operators["dcfft"](np.ascontiguousarray(p_full / S), u)
    u *= L
    elastic = (p_full > 0) & (p_full < H * (1 - CAP_REL))
    delta = float(np.mean((u + g0)[elastic]))  # the approach: u + h0 = δ on the elastic contact
    dent = np.where(p_full >= H * (1 - CAP_REL), np.maximum(delta - g0 - u, 0.0), 0.0)
    res.update({"p": p_full, "dent": dent, "delta": delta})
    return res


# ------------------------------------------------------------------------ metrics
def metrics(r, H):
    p, h = r["p"], r["h"]
    cap = p >= H * (1 - CAP_REL)
    return {
        "load_err": float(p.sum() * h * h / pb.P - 1.0),
        "a_over_aH": math.sqrt((p > 0).sum() * h * h / math.pi) / pb.A_HERTZ,
        "b_over_aH": math.sqrt(cap.sum() * h * h / math.pi) / pb.A_HERTZ,
        "n_contact": int((p > 0).sum()),
        "n_plastic": int(cap.sum()),
        "delta_m": r["delta"],
        "dent_max_m": None if r["dent"] is None else float(r["dent"].max()),
        "p_max_over_H": float(p.max() / H),
    }


def versus(r, ours, H, extra_max=0.0):
    d = {"dp_max_over_H": float(max(np.abs(r["p"] - ours["p"]).max(), extra_max) / H)}
    if r["dent"] is not None and ours["dent"].max() > 0:
        d["ddent_max_rel"] = float(np.abs(r["dent"] - ours["dent"]).max() / ours["dent"].max())
    if r["delta"] is not None:
        d["ddelta_rel"] = float(r["delta"] / ours["delta"] - 1.0)
    return d


def fmt(v, spec):
    return "—" if v is None else format(v, spec)


def table(rows):
    out = ["| N (cells per a_H) | H/p0 | code | iters | s | ΣpΔA/P − 1 | a/a_H | b/a_H | cells c / H | δz (nm) | "
           "max \\|Δp\\|/H | max \\|Δdent\\|/dent | Δδz/δz |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if not r.get("ok", True):
            out.append(f"| {r['n']} | {r['ratio']} | {r['code']} | failed: {r['error']} |||||||||")
            continue
        out.append(
            f"| {r['n']} ({r['n'] * pb.A_HERTZ / pb.SIDE:.1f}) | {r['ratio']} | {r['code']} | {fmt(r['iterations'], 'd')} | "
            f"{r['seconds']:.2f} | {r['load_err']:.1e} | {r['a_over_aH']:.4f} | {r['b_over_aH']:.4f} | "
            f"{r['n_contact']} / {r['n_plastic']} | {fmt(None if r['delta_m'] is None else r['delta_m'] * 1e9, '.3f')} | "
            f"{fmt(r.get('dp_max_over_H'), '.1e')} | {fmt(r.get('ddent_max_rel'), '.1e')} | {fmt(r.get('ddelta_rel'), '.1e')} |")
    return "\n".join(out)


def demo_si(n, ratio, iters):
    """tamaas posed in SI units vs dimensionless: its error after `iters` iterations."""
    H = ratio * pb.P_MAX_HERTZ
    for si in (True, False):
        res, e = pb.run_isolated(_demo_one, (n, H, si, iters), timeout=600)
        label = "SI units (E = 210e9 Pa, metres)" if si else "dimensionless (E* = 1, lengths / (a_H/2))"
        print(f"tamaas KatoSaturated dcfft {n}², {label}: "
              + (e if e else f"error {res[0]:.3g} at iteration 0, {res[1]:.3g} after {res[2]} iterations"))


def _demo_one(n, H, si, iters):
    """(error at iteration 0, error at the end, iterations) of one KatoSaturated solve."""
    import tamaas as tm

    h = pb.SIDE / n
    g0 = gap0(n, h)
    L, S = (1.0, 1.0) if si else (TAMAAS_LENGTH_UNIT, pb.E_STAR)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [pb.SIDE / L] * 2, [n, n])
    model.E, model.nu = (pb.E, pb.NU) if si else (1.0, 0.0)
    tm.ModelFactory.registerNonPeriodic(model, "dcfft")
    solver = tm.KatoSaturated(model, np.ascontiguousarray(-g0 / L), 1e-12, H / S)
    solver.setIntegralOperator("dcfft")
    solver.max_iter = iters
    tm.set_log_level(tm.LogLevel.info)
    with pb.CaptureFds() as cap:
        solver.solve(pb.P / pb.SIDE**2 / S)
    rows = [ln.split() for ln in cap.text.splitlines()]
    rows = [r for r in rows if len(r) == 3 and r[0].isdigit()]
    return float(rows[0][2]), float(solver.computeError()), max(int(r[0]) for r in rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="64,128", help="N of the N×N grids over the same domain")
    ap.add_argument("--ratios", default="0.8,0.4", help="H / p0 (p0: Hertz's peak)")
    ap.add_argument("--peers", default=",".join(PEERS))
    ap.add_argument("--pad", type=int, default=4, help="the periodic peer's domain: this many times the side")
    ap.add_argument("--timeout", type=float, default=900, help="seconds per peer solve")
    ap.add_argument("--json", action="store_true", help="also print one JSON object per row")
    ap.add_argument("--demo-si", action="store_true",
                    help="only show tamaas's error posed in SI units against dimensionless (64², H = 0.8 p0, "
                         "at most 1000 iterations; in SI units 2000 hung after ~1500)")
    args = ap.parse_args()
    if args.demo_si:
        demo_si(64, 0.8, 1000)
        return

    exe = os.environ.get("MPCONTACT_EXE", "target/release/mpcontact")
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    ratios = [float(s) for s in args.ratios.split(",") if s.strip()]
    peers = [s.strip() for s in args.peers.split(",") if s.strip()]
    work = tempfile.mkdtemp(prefix="hardness-peers-")
    rows = []
    for n in sizes:
        for ratio in ratios:
            H = ratio * pb.P_MAX_HERTZ
            ours = run_mpcontact(exe, n, H, work)
            rows.append({"n": n, "ratio": ratio, "code": "mpcontact", "iterations": ours["iterations"],
                         "seconds": ours["seconds"], **metrics(ours, H)})
            for peer in peers:
                if peer == "contactmechanics":
                    fn, fargs = run_contactmechanics, (n, H, TOL["contactmechanics"])
                elif peer == "tamaas-dcfft":
                    fn, fargs = run_tamaas, (n, H, TOL["tamaas"], False, 1)
                elif peer == "tamaas-periodic":
                    fn, fargs = run_tamaas, (n, H, TOL["tamaas"], True, args.pad)
                else:
                    raise SystemExit(f"unknown peer {peer} (known: {', '.join(PEERS)})")
                code = peer if peer != "tamaas-periodic" else f"tamaas-periodic ({args.pad * n}²)"
                res, err = pb.run_isolated(fn, fargs, timeout=args.timeout)
                if err:
                    rows.append({"n": n, "ratio": ratio, "code": code, "ok": False, "error": err})
                    continue
                row = {"n": n, "ratio": ratio, "code": code, "iterations": res["iterations"],
                       "seconds": res["seconds"], **metrics(res, H),
                       **versus(res, ours, H, res.get("p_outside_max", 0.0))}
                for k in ("solver_error", "p_outside"):
                    if k in res:
                        row[k] = res[k]
                rows.append(row)
            sys.stderr.write(f"done N = {n}, H = {ratio} p0\n")
    print(f"Table 1(a) frictionless, H = ratio × p0 (p0 = {pb.P_MAX_HERTZ / 1e6:.1f} MPa), "
          f"domain {pb.SIDE * 1e6:.1f} µm = 4.5 a_H; differences against mpcontact on the same grid\n")
    print(table(rows))
    if args.json:
        for r in rows:
            pb.emit(r)


if __name__ == "__main__":
    main()
