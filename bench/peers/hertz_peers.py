#!/usr/bin/env python3
"""Hertz normal contact (paper Table 1a) with the established PyPI solvers.

    hertz_peers.py --peers tamaas,contactmechanics,aspher --sizes 256,512,1024 --reps 3

Prints one JSON object per line and peer mode × size:
  {"solver", "mode", "kind": "hertz", "n", "threads", "tol", "iterations",
   "seconds", "pmax_err", "radius_err", "ok", ...}
or, when a peer fails, {"solver", "mode", "n", "ok": false, "error"}.

"seconds" is the median over --reps of the solve alone: model, operator and
solver construction are outside the timer (for aspher's nested solve, whose
single call builds its hierarchy, its own `timings["build"]` is subtracted;
"seconds_incl_setup" keeps the whole call). Threads come from the environment
(OMP_NUM_THREADS …, recorded in "threads"); tamaas 2.9.0's wheel is built
without OpenMP ("backend": "cpp") and contactmechanics runs numpy + muFFT, so
only aspher reacts to it.

Errors: pmax_err = max p / p_Hertz − 1, radius_err = sqrt(A_c/π)/a − 1 with
A_c = (cells with p > 0)·h², load_err = ΣpΔA/P − 1 (all signed).

Tolerances (--tol-preset): all three peers converge to the same discrete
solution (exact Love-element influence coefficients, zero-padded FFT), so each
tolerance was set by comparing against that solution (aspher, tol 1e-14):
"matched" (default) makes the relative L1 pressure error Σ|p − p*|/Σp* about
1e-8 or below at 128² and 256² (the quantity mpcontact's own stop tests):
  tamaas  1e-9  → 7e-9 / 1.3e-8     contactmechanics 1e-9 → 3.9e-9 / 9.8e-9
  aspher  1e-10 → 5e-9 / 4e-9 (plain), 3e-9 / 2.6e-9 (nested)
"nominal" uses 1e-8 for every peer, as in shared/docs/peers.md (then the L1
error is 4e-8 – 4.6e-7, the max-norm error up to 4e-6 of p_max).
--check re-measures these errors on every run (keys p_err_l1, p_err_max) against
a reference computed by aspher at tol 1e-13 (not timed).
"""

import argparse
import os
import re
import statistics
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the work tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402

import problem as pb  # noqa: E402

PEERS = ("tamaas", "contactmechanics", "aspher")
MODES = {
    "tamaas": ["pkr-dcfft"],
    "contactmechanics": ["ccg-free-fft"],
    "aspher": ["pk-fft", "nested-fft-precond"],
}
TOL_PRESETS = {
    "matched": {"tamaas": 1e-9, "contactmechanics": 1e-9, "aspher": 1e-10},
    "nominal": {"tamaas": 1e-8, "contactmechanics": 1e-8, "aspher": 1e-8},
}
MAX_ITER = 20000


def _timed_reps(reps, reset, solve):
    """Median of reps timed solve() calls, reset() untimed before each."""
    times, out = [], None
    for _ in range(reps):
        reset()
        t0 = time.perf_counter()
        out = solve()
        times.append(time.perf_counter() - t0)
    return times, out


# --------------------------------------------------------------------------- tamaas
def run_tamaas(mode, n, tol, reps):
    import tamaas as tm

    h, _, _, gap = pb.grid(n)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [pb.SIDE, pb.SIDE], [n, n])
    model.E = pb.E
    model.nu = pb.NU
    # Non-periodic Boussinesq operator (zero-padded DC-FFT), used by the solver by name.
    tm.ModelFactory.registerNonPeriodic(model, "dcfft")
    surface = np.ascontiguousarray(-gap)  # tamaas: gap = u − surface, surface max 0
    tm.set_log_level(tm.LogLevel.info)  # the final log line carries the iteration count
    solver = tm.PolonskyKeerRey(model, surface, tol)
    solver.setIntegralOperator("dcfft")
    solver.max_iter = MAX_ITER
    mean_p = pb.P / pb.SIDE**2
    logs = []

    def reset():
        model.traction[...] = 0.0  # the solver warm-starts from the model's traction
        model.displacement[...] = 0.0

    def solve():
        with pb.CaptureFds() as cap:
            solver.solve(mean_p)
        logs.append(cap.text)

    times, _ = _timed_reps(reps, reset, solve)
    its = [int(m.group(1)) for m in re.finditer(r"^\s*(\d+)\s+\S+\s+(\S+)\s*$", logs[-1], re.M)]
    errs = [float(m.group(2)) for m in re.finditer(r"^\s*(\d+)\s+\S+\s+(\S+)\s*$", logs[-1], re.M)]
    p = np.array(model.traction, dtype=float).reshape(n, n)
    res = {"iterations": its[-1] if its else None, "solver_error": errs[-1] if errs else None}
    if its and its[-1] >= MAX_ITER:
        res["warning"] = "hit max_iter"
    return times, p, h, res


# ---------------------------------------------------------------- contactmechanics
def run_contactmechanics(mode, n, tol, reps):
    from ContactMechanics import FreeFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography

    h, _, _, gap = pb.grid(n)
    # young = contact modulus E* (poisson left at 0 means "young is E*").
    substrate = FreeFFTElasticHalfSpace((n, n), pb.E_STAR, (pb.SIDE, pb.SIDE))
    topo = Topography(np.ascontiguousarray(-gap), physical_sizes=(pb.SIDE, pb.SIDE))
    # Its three stop criteria, all scaled by one eps: penetration (m) against the
    # Hertz approach, pixel force (N) against p_max·h², relative load change.
    kw = dict(
        external_force=pb.P,
        pentol=tol * pb.DELTA_HERTZ,
        forcetol=tol * pb.P_MAX_HERTZ * h * h,
        thermotol=tol,
        maxiter=MAX_ITER,
    )
    times, r = _timed_reps(reps, lambda: None, lambda: constrained_conjugate_gradients(substrate, topo, **kw))
    if not r.success:
        raise RuntimeError(f"CCG did not converge: {r.message} after {r.nit} iterations")
    p = np.asarray(r.jac, dtype=float) / (h * h)  # jac = pixel forces (N), compressive > 0
    return times, p, h, {"iterations": int(r.nit), "pentol_m": kw["pentol"], "forcetol_n": kw["forcetol"]}


# ------------------------------------------------------------------------- aspher
def run_aspher(mode, n, tol, reps):
    import aspher

    h, _, _, gap = pb.grid(n)
    g = np.ascontiguousarray(gap.ravel())
    mean_p = pb.P / pb.SIDE**2
    if mode == "pk-fft":
        t0 = time.perf_counter()
        solver = aspher.ContactSolver(n, pb.SIDE, pb.E_STAR, backend="fft")
        setup = time.perf_counter() - t0
        times, r = _timed_reps(
            reps, lambda: None, lambda: solver.solve(g, mean_p, tol=tol, max_iter=MAX_ITER, precond="none")
        )
        extra = {"setup_seconds": setup}
    elif mode == "nested-fft-precond":
        # One call builds the coarse→fine hierarchy (coarsest 64², exact FFT operator
        # on every level) and warm-starts each level; |q| preconditioner on.
        walls, builds, r = [], [], None
        for _ in range(reps):
            t0 = time.perf_counter()
            r = aspher.solve_nested(
                n, g, mean_p, domain_size=pb.SIDE, E_star=pb.E_STAR, backend="fft",
                precond=True, tol=tol, max_iter=MAX_ITER,
            )
            walls.append(time.perf_counter() - t0)
            builds.append(float(r.timings.get("build", 0.0)))
        times = [w - b for w, b in zip(walls, builds)]
        coarse = [s for s in r.stage_stats if str(s["name"]).startswith("coarse")]
        extra = {
            "seconds_incl_setup": statistics.median(walls),
            "setup_seconds": statistics.median(builds),
            "coarse_iterations": int(sum(s["iterations"] for s in coarse)),
            "levels": len(r.stage_stats),
        }
    else:
        raise ValueError(f"unknown aspher mode {mode}")
    if not r.converged:
        raise RuntimeError(f"aspher status {r.status}: {r.status_reason}")
    p = np.asarray(r.pressure, dtype=float).reshape(n, n)
    extra.update({"iterations": int(r.iterations), "fw_error": float(r.fw_error)})
    return times, p, h, extra


RUNNERS = {"tamaas": run_tamaas, "contactmechanics": run_contactmechanics, "aspher": run_aspher}


def reference(n, path):
    """Converged discrete solution (aspher, exact FFT operator, tol 1e-13), saved to path."""
    import aspher

    _, _, _, gap = pb.grid(n)
    s = aspher.ContactSolver(n, pb.SIDE, pb.E_STAR, backend="fft")
    r = s.solve(np.ascontiguousarray(gap.ravel()), pb.P / pb.SIDE**2, tol=1e-13, max_iter=20000, precond="none")
    np.save(path, np.asarray(r.pressure, dtype=float).reshape(n, n))
    return {"status": r.status, "fw_error": float(r.fw_error)}


def job(peer, mode, n, tol, reps, ref_path):
    # One small untimed solve first, so one-off library start-up (thread pools,
    # FFT plan caches, lazy imports) is not charged to the timed reps.
    RUNNERS[peer](mode, 64, 1e-6, 1)
    times, p, h, extra = RUNNERS[peer](mode, n, tol, reps)
    out = {
        "iterations": extra.pop("iterations"),
        "seconds": statistics.median(times),
        "seconds_all": times,
        **pb.normal_metrics(p, h),
        **extra,
    }
    if ref_path and os.path.exists(ref_path):
        pref = np.load(ref_path)
        out["p_err_l1"] = float(np.abs(p - pref).sum() / pref.sum())
        out["p_err_max"] = float(np.abs(p - pref).max() / pref.max())
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--peers", default=",".join(PEERS))
    ap.add_argument("--sizes", default="256,512,1024")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--modes", default="", help="restrict to these modes (comma list), e.g. pk-fft")
    ap.add_argument("--tol-preset", choices=sorted(TOL_PRESETS), default="matched")
    ap.add_argument("--tol", action="append", default=[], metavar="PEER=VALUE", help="override a peer's tolerance")
    ap.add_argument("--check", action="store_true", help="also measure the pressure error vs a converged reference")
    ap.add_argument("--timeout", type=float, default=None,
                    help="seconds allowed per peer mode × size (all reps); a mode that exceeds it is not run at larger sizes")
    ap.add_argument("--reps-one-from", type=int, default=None, help="sizes from this one on are solved once")
    ap.add_argument("--headline-from", type=int, default=None,
                    help="sizes from this one on run only each peer's fastest mode (aspher: nested-fft-precond)")
    args = ap.parse_args()

    tols = dict(TOL_PRESETS[args.tol_preset])
    for item in args.tol:
        k, v = item.split("=", 1)
        tols[k.strip()] = float(v)
    peers = [s.strip() for s in args.peers.split(",") if s.strip()]
    sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    only = {m.strip() for m in args.modes.split(",") if m.strip()}
    thr = pb.threads()

    refs = {}
    if args.check:
        import tempfile

        tmp = tempfile.mkdtemp(prefix="hertz-ref-")
        for n in sizes:
            path = os.path.join(tmp, f"ref-{n}.npy")
            res, err = pb.run_isolated(reference, (n, path))
            if err:
                sys.stderr.write(f"reference at {n}: {err}\n")
            else:
                refs[n] = path

    for peer in peers:
        if peer not in RUNNERS:
            pb.emit({"solver": peer, "kind": "hertz", "threads": thr, "ok": False, "error": "unknown peer"})
            continue
        for mode in MODES[peer]:
            if only and mode not in only:
                continue
            too_slow = None
            for n in sizes:
                if args.headline_from and n >= args.headline_from and mode != MODES[peer][-1]:
                    continue
                reps = 1 if args.reps_one_from and n >= args.reps_one_from else args.reps
                base = {"solver": peer, "mode": mode, "kind": "hertz", "n": n, "threads": thr,
                        "tol": tols[peer], "tol_preset": args.tol_preset, "reps": reps}
                if too_slow:
                    pb.emit({**base, "ok": False, "error": f"not run: exceeded the time budget at {too_slow}²"})
                    continue
                res, e = pb.run_isolated(job, (peer, mode, n, tols[peer], reps, refs.get(n)), timeout=args.timeout)
                if e:
                    pb.emit({**base, "ok": False, "error": e})
                    if "time budget" in e:
                        too_slow = n
                else:
                    pb.emit({**base, **res, "ok": True})


if __name__ == "__main__":
    main()
