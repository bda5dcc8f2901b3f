#!/usr/bin/env python3
"""A rigid sphere pressed into a measured rough surface: mpcontact against
contactmechanics 1.8.3 on the same scan, levelled, non-periodic on both
sides, on the same grid (issue #61).

    scan_peers.py SCAN [--exe target/release/mpcontact] [--cells 512]
                       [--radius-mm 5] [--load-n 20] [--tol 1e-10]

SCAN is a public sample scan in any format SurfaceTopography reads (the
numbers in docs/validation.md use `plu-1.plu` of SurfaceTopography's test
suite, `test/file_format_examples`: a Sensofar confocal scan, 768 x 576
pixels of 1.66 µm, Sq 2.8 µm; it is not part of this repository). Run it
in a virtualenv outside the repository with `pip install
contactmechanics==1.8.3` (which brings SurfaceTopography).

The problem: E = 210 GPa, ν = 0.3 (E* = E/(1 − ν²)); the scan's least-
squares plane removed over the whole scan; the central CELLS x CELLS
pixels are the grid (cells = pixels, so neither code resamples); the
sphere's apex over the scan's centre. mpcontact reads the scan as an
`.npy` with its pixel size (`shape = "scan"`, `levelling = "plane"`) and
levels and crops it itself; contactmechanics gets SurfaceTopography's
`detrend("height")` of the same scan, cropped, as the rigid surface
`−r²/2R + h` on a `FreeFFTElasticHalfSpace`. Compared: the real contact
area (cells with p > 0 times the cell area), the approach from first
touch and the largest pressure; times are each code's whole solve on one
thread (mpcontact: the `mpcontact solve` process, kernel build included;
contactmechanics: `constrained_conjugate_gradients` alone).

Prints a markdown table.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True
import numpy as np  # noqa: E402

E, NU = 210e9, 0.3
E_STAR = E / (1.0 - NU**2)


def read_levelled(path):
    """SurfaceTopography's reading and plane levelling, in m, (nx, ny)."""
    from SurfaceTopography import read_topography
    from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

    topo = read_topography(path)
    f = get_unit_conversion_factor(topo.unit, "m")
    levelled = topo.detrend(detrend_mode="height")
    h = np.asarray(levelled.heights(), dtype=np.float64) * f
    raw = np.asarray(topo.heights(), dtype=np.float64) * f
    dx, dy = (float(v) * f for v in topo.pixel_size)
    return raw, h, dx, dy


def centre(a, n):
    nx, ny = a.shape
    i, j = (nx - n) // 2, (ny - n) // 2
    return a[i : i + n, j : j + n]


def sphere(n, h, radius):
    x = (np.arange(n) - 0.5 * (n - 1)) * h
    X, Y = np.meshgrid(x, x, indexing="ij")
    return (X * X + Y * Y) / (2.0 * radius)


def run_mpcontact(exe, raw, dx, n, radius, load, tol, workdir):
    # The raw scan in µm, rows along y: mpcontact levels and crops it.
    np.save(os.path.join(workdir, "scan.npy"), np.ascontiguousarray(raw.T * 1e6))
    cfg = os.path.join(workdir, "scan.toml")
    with open(cfg, "w") as f:
        f.write(
            f"""[grid]
points = {n}
spacing_um = {dx * 1e6!r}

[indenter]
radius_mm = {radius * 1e3!r}

[load]
normal_n = {load!r}
friction = 0.0
tangential_ratio = 0.0

[sweep]
materials = ["steel"]
surfaces = ["measured"]
angles_deg = [0.0]

[surfaces.measured]
shape = "scan"
file = "scan.npy"
pixel_um = {dx * 1e6!r}
levelling = "plane"

[solver]
coupling = false
tolerance = {tol!r}
max_iterations = 20000
"""
        )
    out = os.path.join(workdir, "out")
    t0 = time.perf_counter()
    subprocess.run(
        [exe, "solve", cfg, "--out", out, "--threads", "1", "--quiet"],
        check=True,
        stdout=subprocess.DEVNULL,
    )
    secs = time.perf_counter() - t0
    case = json.load(open(os.path.join(out, "case.json")))
    p = np.load(os.path.join(out, "p.npy")).T  # (x, y)
    return {
        "p": p,
        "approach": case["delta_z_m"],
        "iterations": case["normal"]["iterations"],
        "seconds": secs,
        "scan": case["surface_scan"],
    }


def run_contactmechanics(levelled, dx, n, radius, load, tol):
    from ContactMechanics import FreeFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography

    side = n * dx
    rigid = -sphere(n, dx, radius) + centre(levelled, n)
    substrate = FreeFFTElasticHalfSpace((n, n), E_STAR, (side, side))
    topo = Topography(np.ascontiguousarray(rigid), physical_sizes=(side, side))
    t0 = time.perf_counter()
    r = constrained_conjugate_gradients(
        substrate,
        topo,
        external_force=load,
        pentol=tol * 1e-6,
        forcetol=tol * load / n,
        maxiter=20000,
    )
    secs = time.perf_counter() - t0
    if not r.success:
        raise RuntimeError(f"contactmechanics did not converge: {r.message}")
    p = np.asarray(r.jac, dtype=float) / (dx * dx)
    return {
        "p": p,
        "approach": float(r.offset) + float(rigid.max()),
        "iterations": int(r.nit),
        "seconds": secs,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scan")
    ap.add_argument("--exe", default="target/release/mpcontact")
    ap.add_argument("--cells", type=int, default=512)
    ap.add_argument("--radius-mm", type=float, default=5.0)
    ap.add_argument("--load-n", type=float, default=20.0)
    ap.add_argument("--tol", type=float, default=1e-10)
    a = ap.parse_args()
    raw, levelled, dx, dy = read_levelled(a.scan)
    if abs(dx / dy - 1.0) > 1e-9:
        sys.exit(f"{a.scan}: pixels {dx} x {dy} m are not square (mpcontact's cells are)")
    n, radius = a.cells, a.radius_mm * 1e-3
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    with tempfile.TemporaryDirectory() as work:
        ours = run_mpcontact(os.path.abspath(a.exe), raw, dx, n, radius, a.load_n, a.tol, work)
    theirs = run_contactmechanics(levelled, dx, n, radius, a.load_n, a.tol)
    area = lambda r: float((r["p"] > 0).sum()) * dx * dx  # noqa: E731
    rows = [
        ("real contact area (µm²)", area(ours) * 1e12, area(theirs) * 1e12),
        ("approach from first touch (µm)", ours["approach"] * 1e6, theirs["approach"] * 1e6),
        ("largest pressure (GPa)", ours["p"].max() / 1e9, theirs["p"].max() / 1e9),
        ("load Σ p ΔA (N)", ours["p"].sum() * dx * dx, theirs["p"].sum() * dx * dx),
        ("iterations", ours["iterations"], theirs["iterations"]),
        ("time (s)", ours["seconds"], theirs["seconds"]),
    ]
    s = ours["scan"]
    print(
        f"{os.path.basename(a.scan)}: {s['pixels'][0]} x {s['pixels'][1]} pixels of "
        f"{s['pixel_um'][0]:.4g} µm, plane levelled; Sq {s['scan']['sq_um']:.4g} µm, "
        f"Sdq {s['scan']['sdq']:.4g}; grid {n}² of the centre; R = {a.radius_mm} mm, "
        f"P = {a.load_n} N, E = 210 GPa, ν = 0.3; tol {a.tol}"
    )
    print()
    print("| quantity | mpcontact | contactmechanics 1.8.3 | relative difference |")
    print("|---|---|---|---|")
    for name, x, y in rows:
        diff = "" if name in ("iterations", "time (s)") else f"{x / y - 1:+.1e}"
        print(f"| {name} | {x:.8g} | {y:.8g} | {diff} |")


if __name__ == "__main__":
    main()
