#!/usr/bin/env python3
"""Fretting wear of the product (the mpcontact CLI) against the independent MDR
reference bench/references/mdr_fretting_wear.py (issue #49).

Python 3 + numpy only. The product runs as a subprocess (`mpcontact solve
CONFIG --out DIR --quiet`); the reference is imported (its file is not
touched, and it imports nothing of the product). The reference's contact
model (`MDRContact.step`: Coulomb springs, Archard wear per increment times
the jump M with its stability sub-steps, the normal problem re-solved) is
driven here along the product's load path, increment for increment:

    0 -> +A (first loading, S increments), then N x (+A -> -A -> +A),
    S increments per half cycle (the product's steps_per_segment),

so that both codes record the same states (the reference's own `fretting()`
runs 0 -> +A -> -A -> 0 per cycle with N increments per quarter; the driver
below reproduces it exactly on that path, checked at start-up). Each
simulated cycle's wear, first loading included, is applied times M in both.

Cases (rigid sphere R = 18 mm on an isotropic flat E = 210 GPa, nu = 0 so that
MDR is exact for the uncoupled problem; P = 20 N, mu = 0.28571; the product
uncoupled, domain 320 um square; the reference on 800 nodes on [0, 1.5 a_H]):

  unworn   (--cases unworn) two cycles, M = 1, tiny k: energy per cycle, delta*,
           c against Mindlin-Deresiewicz / 4 mu P (Delta - 0.8 delta*) and the
           reference, 10/20/40 increments per half cycle, 64^2/128^2/256^2;
  partial  force control, F* = 0.6 mu P, k = 1e-6 mm^3/(N m), M = 6e5
           (first cycle removes ~1.5 % of d0) x 20 simulated cycles on
           64^2 ... 512^2, M/2 x 40 on 256^2 (the cycle-jump study), and the
           reference again on 400 nodes (its own grid error);
  disp     partial slip under an imposed shift (the one giving F* = 0.6 mu P
           on the unworn sphere), 64^2/128^2: F* falls as the scar forms;
  gross    displacement control, Delta = 3 delta*, M = 1e4 x 10 (and M/2 x 20
           on 128^2): worn volume per physical cycle vs 4 k P (Delta - 0.8 delta*).

Product runs go to --work/<case>_n<grid>_M<jump>/ (config, case.json, wear.npy,
p.npy, stick.npy); --reuse takes a run from there when its config and the
binary's size are unchanged (its recorded wall and CPU times are printed).

Usage:
  python3 bench/wear_vs_mdr.py --bin target/release/mpcontact --work /tmp/wear_vs_mdr
          [--cases partial,disp,gross | unworn] [--partial-grids 64,128,256,512]
          [--grids 64,128] [--ref-nodes 800] [--ref-check-nodes 400] [--reuse]
Sections 2-4 of the write-up took ~40 min wall (about 15 min of product CPU,
most of it 512^2 and the displacement-controlled 128^2) on a shared 2-core machine.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")  # one core for the reference (as it sets itself), before numpy loads

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "references"))
import mdr_fretting_wear as ref  # noqa: E402  (the reference; numpy only)

# --- the case -----------------------------------------------------------------
R_MM, E_GPA, NU, MU, P_N = 18.0, 210.0, 0.0, 0.28571, 20.0
DOMAIN_UM = 320.0                 # the product's square domain (all grids)
K_MM3 = 1e-6                      # Archard k, mm^3/(N m)
K = K_MM3 * 1e-9                  # m^3/(N m)
REUSE = False                     # --reuse: take a product run from --work if its config and binary are unchanged
STEPS = 10                        # increments per half cycle (product), = 2 x the reference's per quarter


def setup(nodes, rmax=1.5):
    return ref.Setup(R=R_MM * 1e-3, E=E_GPA * 1e9, nu=NU, mu=MU, P=P_N, n=nodes, rmax_over_a=rmax)


# --- the reference along the product's path -----------------------------------

def _record(m, cyc, M, vol0, e1, e3, amps, c_end, gross, h_prev):
    vol = float(m.area_w @ m.h)
    return dict(cycle=cyc, physical=cyc * M, volume=vol, vol_per_cycle=(vol - vol0) / M,
                depth_max=float(m.h.max()), a=m.a, c=c_end, F=max(abs(q) for q, _ in amps),
                dshift=max(abs(d) for _, d in amps), energy=e1, energy3d=e3,
                regime="gross" if gross else "partial", h=m.h.copy(),
                dh_max=float((m.h - h_prev).max()), p=m.pressure())


def reference_history(S, control, amp, cycles, M, steps=STEPS, k=K):
    """The reference model driven along 0 -> +A, N x (+A -> -A -> +A);
    a record after every full cycle (at +A)."""
    m = ref.MDRContact(S)
    for j in range(1, steps + 1):
        m.step(amp * j / steps, control, k, 0.0, M, True)
    down = amp - 2.0 * amp * np.arange(1, steps + 1) / steps
    up = -amp + 2.0 * amp * np.arange(1, steps + 1) / steps
    recs = []
    for cyc in range(1, cycles + 1):
        vol0 = float(m.area_w @ m.h)
        h_prev = m.h.copy()
        e1 = e3 = 0.0
        amps = [(m.Q(), m.delta)]
        gross = False
        o = None
        for t in np.concatenate([down, up]):
            o = m.step(t, control, k, 0.0, M, True)
            e1 += o["e1d"]
            e3 += o["e3d"]
            amps.append((o["Q"], o["delta"]))
            gross |= o["c"] == 0.0
        recs.append(_record(m, cyc, M, vol0, e1, e3, amps, o["c"], gross, h_prev))
    return m, recs


def check_driver():
    """The driver reproduces the reference's own fretting() on its own path
    (0 -> +A -> -A -> 0, N per quarter): same step calls, same state."""
    S = setup(200)
    A = 0.6 * S.mu * S.P
    M = 3e5
    _, recs = ref.fretting(S, A, "force", cycles=2, N=5, k_wear=K, M=M)
    m = ref.MDRContact(S)
    tg, _ = ref.cycle_targets(A, 5)
    for _ in range(2):
        for t in tg:
            m.step(t, "force", K, 0.0, M, True)
    err = np.max(np.abs(m.h - recs[-1].h)) / recs[-1].h.max()
    assert err < 1e-12, err
    return err


# --- the product --------------------------------------------------------------

def product_config(n, control, amp, cycles, M, steps=STEPS, save_every=1, k_mm3=K_MM3):
    dx = DOMAIN_UM / n
    if control == "force":   # amp in N
        fret = "amplitude_ratio = %r" % round(amp / (MU * P_N), 12)
    else:                    # amp in m
        fret = "displacement_um = %r" % round(amp * 1e6, 12)
    return f"""[grid]
points = {n}
spacing_um = {dx!r}
[indenter]
radius_mm = {R_MM!r}
[load]
normal_n = {P_N!r}
friction = {MU!r}
[materials.nu0]
isotropic = {{ youngs_gpa = {E_GPA!r}, poisson = {NU!r} }}
[sweep]
materials = ["nu0"]
surfaces = ["flat"]
angles_deg = [0.0]
[solver]
coupling = false
[history]
fretting = {{ {fret}, cycles = {cycles} }}
steps_per_segment = {steps}
wear = {{ law = "archard", k_mm3_per_nm = {k_mm3!r}, physical_cycles = {cycles * M!r}, save_every = {save_every} }}
"""


def run_product(binary, work, name, n, control, amp, cycles, M, steps=STEPS, k_mm3=K_MM3):
    out = os.path.join(work, name)
    os.makedirs(work, exist_ok=True)
    cfg = os.path.join(work, name + ".toml")
    with open(cfg, "w") as f:
        f.write(product_config(n, control, amp, cycles, M, steps=steps, k_mm3=k_mm3))
    stamp = os.path.join(out, "wear_vs_mdr_run.json")
    text = open(cfg).read()
    cached = None
    if REUSE and os.path.exists(stamp):
        with open(stamp) as f:
            cached = json.load(f)
        if cached.get("config") != text or cached.get("binary_size") != os.path.getsize(binary):
            cached = None
    if cached is None:
        t0 = time.time()
        r0 = os.times()
        subprocess.run(["nice", "-n", "19", binary, "solve", cfg, "--out", out, "--quiet"], check=True,
                       stdout=subprocess.DEVNULL)
        r1 = os.times()
        wall = time.time() - t0
        cpu = (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system)
        with open(stamp, "w") as f:
            json.dump(dict(config=text, binary_size=os.path.getsize(binary), wall=wall, cpu=cpu), f)
    else:
        wall, cpu = cached["wall"], cached["cpu"]
    with open(os.path.join(out, "case.json")) as f:
        case = json.load(f)
    wear = np.load(os.path.join(out, "wear.npy"))
    p = np.load(os.path.join(out, "p.npy"))
    stick = np.load(os.path.join(out, "stick.npy"))
    return dict(case=case, wc=case["history"]["wear_cycles"], wear=wear, p=p, stick=stick,
                n=n, dx=DOMAIN_UM * 1e-6 / n, wall=wall, cpu=cpu, cfg=cfg, out=out)


def cell_r(n, dx):
    x = (np.arange(n) - (n - 1) / 2.0) * dx
    X, Y = np.meshgrid(x, x)
    return np.hypot(X, Y), x


def h_at(m_r, h, r):
    """The reference's h(r) at radii r (linear in s = r^2, as the reference
    represents it); 0 beyond its grid."""
    return np.interp(r * r, m_r * m_r, h, right=0.0)


def profile_errors(pr, m_r, h_ref):
    """Worn depth of the product's final map against the reference's h(r):
    per-cell integral error, azimuthal averages in rings of width dx, and the
    cuts along x and y through the centre."""
    n, dx = pr["n"], pr["dx"]
    rc, x = cell_r(n, dx)
    href_c = h_at(m_r, h_ref, rc)
    w = pr["wear"]
    V_ref = float(np.sum(href_c)) * dx * dx
    l1 = float(np.sum(np.abs(w - href_c))) / float(np.sum(href_c))
    ring = np.floor(rc / dx + 0.5).astype(int)   # rings of width dx centred on j dx
    nb = ring.max() + 1
    cnt = np.bincount(ring.ravel(), minlength=nb)
    hp = np.bincount(ring.ravel(), w.ravel(), minlength=nb) / np.maximum(cnt, 1)
    hr = np.bincount(ring.ravel(), href_c.ravel(), minlength=nb) / np.maximum(cnt, 1)
    rr = np.bincount(ring.ravel(), rc.ravel(), minlength=nb) / np.maximum(cnt, 1)
    ok = cnt > 0
    hmax = h_ref.max()
    ring_max = float(np.max(np.abs(hp - hr)[ok])) / hmax
    # cuts: the mean of the two middle rows (columns), cell centres at y = +-dx/2
    lo, hi = (n - 1) // 2, n // 2
    cx = 0.5 * (w[lo, :] + w[hi, :])
    cy = 0.5 * (w[:, lo] + w[:, hi])
    rcut = np.hypot(x, 0.5 * dx if n % 2 == 0 else 0.0)
    hcut = h_at(m_r, h_ref, rcut)
    cut_x = float(np.max(np.abs(cx - hcut))) / hmax
    cut_y = float(np.max(np.abs(cy - hcut))) / hmax
    spread = float(np.max(np.abs(cx - cy))) / hmax
    return dict(l1=l1, ring_max=ring_max, cut_x=cut_x, cut_y=cut_y, spread=spread, V_ref_cells=V_ref,
                rings=(rr[ok], hp[ok], hr[ok]))


def radii_from_fields(pr, p_scale):
    """Contact and stick radii of the product's final state (at +A) from its
    fields: equivalent-area radii sqrt(A/pi) of {p > 0} and of the stick cells ({stick} inside {p > 0})."""
    dA = pr["dx"] ** 2
    p, st = pr["p"], pr["stick"]
    a0 = math.sqrt(np.count_nonzero(p > 0) * dA / math.pi)
    c = math.sqrt(np.count_nonzero((st > 0.5) & (p > 0)) * dA / math.pi)
    return a0, c


# --- tables ---------------------------------------------------------------------

def rel(a, b):
    return (a - b) / b if b != 0 else float("nan")


def cut_error(pr, i, m_r, h_ref):
    """max |the saved cut along x of cycle i - h_ref(r)| / max h_ref."""
    cut = np.asarray(pr["wc"][i]["profile_x_m"])
    if cut.size == 0:
        return float("nan")
    n, dx = pr["n"], pr["dx"]
    x = (np.arange(n) - (n - 1) / 2.0) * dx
    r = np.hypot(x, 0.5 * dx if n % 2 == 0 else 0.0)
    return float(np.max(np.abs(cut - h_at(m_r, h_ref, r)))) / h_ref.max()


def per_cycle_table(title, prods, refs, every, m_r):
    """Per saved cycle: worn volume, max depth, delta* (or F*), energy, V/cycle."""
    print("\n### %s: per cycle (product grid %s vs reference)" % (title, ", ".join("%d^2" % p["n"] for p in prods)))
    hdr = "%5s %10s %12s" % ("cycle", "phys.cyc", "V_ref[m3]") + "".join(" %9s" % ("dV%d" % p["n"]) for p in prods)
    hdr += " %11s" % "hmax_ref[m]" + "".join(" %9s" % ("dh%d" % p["n"]) for p in prods)
    hdr += " %10s" % "F*_ref[N]" + "".join(" %9s" % ("dF%d" % p["n"]) for p in prods)
    hdr += " %11s" % "dlt*_ref[m]" + "".join(" %9s" % ("dd%d" % p["n"]) for p in prods)
    hdr += " %10s" % "W_ref[J]" + "".join(" %9s" % ("dW%d" % p["n"]) for p in prods)
    hdr += " %11s" % "Vcyc_ref" + "".join(" %9s" % ("dVc%d" % p["n"]) for p in prods)
    hdr += "".join(" %9s" % ("cut%d" % p["n"]) for p in prods)
    print(hdr)
    print("(dX: relative difference product/reference - 1; W: energy dissipated per cycle, reference 1-D springs; Vcyc: worn volume per physical cycle over the simulated cycle;"
          " cut: max |h along x through the centre - h_ref(r)| / max h_ref)")
    for i, r in enumerate(refs):
        if not ((i + 1) % every == 0 or i == 0 or i == len(refs) - 1):
            continue
        line = "%5d %10.4g %12.5e" % (r["cycle"], r["physical"], r["volume"])
        line += "".join(" %+9.2e" % rel(p["wc"][i]["worn_volume_m3"], r["volume"]) for p in prods)
        line += " %11.5e" % r["depth_max"] + "".join(" %+9.2e" % rel(p["wc"][i]["depth_max_m"], r["depth_max"]) for p in prods)
        line += " %10.5f" % r["F"] + "".join(" %+9.2e" % rel(p["wc"][i]["force_amplitude_n"], r["F"]) for p in prods)
        line += " %11.5e" % r["dshift"] + "".join(" %+9.2e" % rel(p["wc"][i]["shift_amplitude_m"], r["dshift"]) for p in prods)
        line += " %10.4e" % r["energy"] + "".join(" %+9.2e" % rel(p["wc"][i]["dissipated_j"], r["energy"]) for p in prods)
        line += " %11.4e" % r["vol_per_cycle"] + "".join(" %+9.2e" % rel(p["wc"][i]["worn_volume_per_cycle_m3"], r["vol_per_cycle"]) for p in prods)
        line += "".join(" %9.2e" % cut_error(p, i, m_r, r["h"]) for p in prods)
        print(line)


def final_table(title, prods, m, refs, S):
    r = refs[-1]
    p0 = 1.5 * S.P / (math.pi * S.a_hertz ** 2)
    print("\n### %s: final state (cycle %d = %.4g physical cycles, at +A)" % (title, r["cycle"], r["physical"]))
    print("reference: a (edge of w > 0) = %.4f um, c (at +A) = %.4f um, a_Hertz = %.4f um; energy of the last cycle: 1-D %.4e J, 3-D %.4e J"
          % (r["a"] * 1e6, r["c"] * 1e6, S.a_hertz * 1e6, r["energy"], r["energy3d"]))
    print("%6s %7s %9s %9s %9s %9s %9s %9s %9s %9s %9s %9s %9s %9s %9s %8s %8s" % (
        "grid", "dx[um]", "dV", "dhmax", "L1(h)", "ring", "cut x", "cut y", "x vs y",
        "a_p>0", "c", "a_mom", "c_mom", "W1d", "W3d", "wall[s]", "cpu[s]"))
    print("(dV, dhmax: relative to the reference; L1(h) = sum|h - h_ref| dA / sum h_ref dA over the cells; ring: max |ring-mean difference| / max h_ref (rings of width dx);"
          " cut x/y: max |cut - h_ref(r)| / max h_ref; x vs y: max |cut x - cut y| / max h_ref (non-axisymmetry);"
          " radii: relative to the reference's (a_p>0 = sqrt(area{p > 0}/pi) vs the edge of w > 0, c = sqrt(area{stick}/pi) vs c at +A; a_mom/c_mom the product's moments radii of case.json);"
          " W1d/W3d: the product's energy of the last cycle relative to the reference's 1-D and 3-D energies")
    for pr in prods:
        e = profile_errors(pr, m.r, r["h"])
        a0, c = radii_from_fields(pr, p0)
        wc = pr["wc"][-1]
        print("%6s %7.3f %+9.2e %+9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %+9.2e %+9.2e %+9.2e %+9.2e %+9.2e %+9.2e %8.1f %8.1f" % (
            "%d^2" % pr["n"], pr["dx"] * 1e6, rel(wc["worn_volume_m3"], r["volume"]), rel(wc["depth_max_m"], r["depth_max"]),
            e["l1"], e["ring_max"], e["cut_x"], e["cut_y"], e["spread"],
            rel(a0, r["a"]), rel(c, r["c"]) if r["c"] > 0 else float("nan"),
            rel(wc["contact_radius_m"], r["a"]), rel(wc["stick_radius_m"], r["c"]) if r["c"] > 0 else float("nan"),
            rel(wc["dissipated_j"], r["energy"]), rel(wc["dissipated_j"], r["energy3d"]),
            pr["wall"], pr["cpu"]))
        pr["_err"] = e
    # the azimuthally averaged profile on the finest grid, at a few radii
    fine = prods[-1]
    rr, hp, hr = fine["_err"]["rings"]
    print("\nazimuthal average of the final worn depth (rings of width dx = %.3f um on %d^2) vs the reference on the same cells, nm:"
          % (fine["dx"] * 1e6, fine["n"]))
    print("%8s %8s %10s %10s %10s" % ("r[um]", "r/a_H", "h_ref", "h_prod", "diff"))
    for j in range(0, rr.size, max(1, rr.size // 40)):
        if rr[j] > 1.35 * S.a_hertz:
            break
        print("%8.2f %8.3f %10.3f %10.3f %+10.3f" % (rr[j] * 1e6, rr[j] / S.a_hertz, hr[j] * 1e9, hp[j] * 1e9, (hp[j] - hr[j]) * 1e9))


def jump_table(title, pairs):
    """pairs: [(label, prod_rec_M, prod_rec_M2, ref_rec_M, ref_rec_M2)] at the same physical cycle."""
    print("\n### %s: cycle jump (same physical cycles; M and M/2 with twice the simulated cycles)" % title)
    print("%-26s %13s %13s %13s %13s %10s %10s %13s %13s %10s" % (
        "quantity", "prod M", "prod M/2", "ref M", "ref M/2", "diff M", "diff M/2", "prod extrap", "ref extrap", "diff extr"))
    for lab, a, b, c, d in pairs:
        pe, re_ = 2 * b - a, 2 * d - c
        print("%-26s %13.6e %13.6e %13.6e %13.6e %+10.2e %+10.2e %13.6e %13.6e %+10.2e" % (
            lab, a, b, c, d, rel(a, c), rel(b, d), pe, re_, rel(pe, re_)))


# --- main ---------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(HERE, "..", "target", "release", "mpcontact"))
    ap.add_argument("--work", default="/tmp/wear_vs_mdr")
    ap.add_argument("--grids", default="64,128", help="product grids of the displacement-controlled runs")
    ap.add_argument("--jump-grid", type=int, default=256, help="grid of the partial-slip M/2 run")
    ap.add_argument("--gross-jump-grid", type=int, default=128, help="grid of the gross-slip M/2 run")
    ap.add_argument("--cases", default="partial,disp,gross")
    ap.add_argument("--ref-nodes", type=int, default=800, help="reference nodes on [0, 1.5 a_H]")
    ap.add_argument("--ref-rmax", type=float, default=1.5, help="reference grid extent / a_H (the worn contact reaches 1.18 a_H)")
    ap.add_argument("--skip-jump", action="store_true", help="skip the M/2 runs")
    ap.add_argument("--partial-grids", default="64,128,256,512", help="product grids of the force-controlled partial-slip run")
    ap.add_argument("--unworn-grids", default="64,128,256", help="product grids of the before-wear energy check")
    ap.add_argument("--reuse", action="store_true", help="reuse product runs in --work with the same config and binary")
    ap.add_argument("--ref-check-nodes", type=int, default=400, help="the reference again at these nodes (its own grid error; 0: skip)")
    ap.add_argument("--cycles", type=int, default=20, help="simulated cycles at M (partial slip)")
    a = ap.parse_args(argv)
    grids = [int(g) for g in a.grids.split(",")]
    pgrids = [int(g) for g in a.partial_grids.split(",")]
    grids_unworn = [int(g) for g in a.unworn_grids.split(",")]
    global REUSE
    REUSE = a.reuse
    cases = a.cases.split(",")
    t_start = time.time()
    S = setup(a.ref_nodes, a.ref_rmax)
    mP = S.mu * S.P
    d0 = S.a_hertz ** 2 / S.R
    print("# rigid sphere R = %g mm on E = %g GPa, nu = %g; P = %g N, mu = %g; a_H = %.4f um, d0 = %.4e m, delta* = %.4e m"
          % (R_MM, E_GPA, NU, P_N, MU, S.a_hertz * 1e6, d0, S.delta_star))
    print("# Archard k = %g mm^3/(N m); %d increments per half cycle (reference: the same increments, driven along the product's path)"
          % (K_MM3, STEPS))
    print("# product: %s, domain %g um, grids %s (force-controlled partial slip), %s (displacement control), %s (before wear);"
          " reference: n = %d nodes on [0, %.2f a_H]"
          % (os.path.abspath(a.bin), DOMAIN_UM, pgrids, grids, grids_unworn, S.n, S.rmax_over_a))
    ver = subprocess.run([a.bin, "--version"], capture_output=True, text=True).stdout.strip()
    print("# %s" % ver)
    print("# driver check: reproduces the reference's fretting() to %.1e" % check_driver())

    def both(name, control, amp, cycles, M, grid_list, title):
        t0 = time.time()
        m, refs = reference_history(S, control, amp, cycles, M)
        t_ref = time.time() - t0
        print("\n## %s: %s control, amplitude %s, M = %g x %d simulated cycles (%g physical); reference %.1f s (max %d sub-steps)"
              % (title, control, ("%.6g mu P" % (amp / mP)) if control == "force" else ("%.6g um = %.4g delta*" % (amp * 1e6, amp / S.delta_star)),
                 M, cycles, M * cycles, t_ref, m.substeps_max))
        prods = []
        for n in grid_list:
            pr = run_product(a.bin, a.work, "%s_n%d_M%g" % (name, n, M), n, control, amp, cycles, M)
            prods.append(pr)
            print("# product %d^2: %.1f s wall, %.1f s CPU, wear_jump_ratio %.4f, converged %s, regime %s"
                  % (n, pr["wall"], pr["cpu"], pr["case"]["history"].get("wear_jump_ratio") or 0.0,
                     pr["case"]["converged"], pr["case"]["history"].get("regime")))
            sys.stdout.flush()
        print("# reference: first simulated cycle's max depth / d0 = %.4f (with the first loading), last %.4f; max depth / d0 at the end %.4f"
              % (refs[0]["depth_max"] / d0, refs[-1]["dh_max"] / d0, refs[-1]["depth_max"] / d0))
        return m, refs, prods

    if "unworn" in cases:
        # before wear (README item 1): two cycles, no jump, a tiny k; the
        # energy per cycle against Mindlin-Deresiewicz and the reference,
        # with the increments per half cycle doubled (the product's energy
        # is a trapezoidal rule in the increments, the reference's 1-D one
        # exact for piecewise-linear paths)
        kt = 1e-12
        Su = setup(400)
        A = 0.6 * mP
        Dg = 3.0 * S.delta_star
        print("\n## Before wear: 2 cycles, M = 1, k = %g mm^3/(N m); the second full cycle (from +A) against the closed forms and the reference (n = 400)" % kt)
        print("closed forms: force control 0.6 mu P: delta* = %.5e m, c = %.4f um, W = %.5e J (Mindlin-Deresiewicz);"
              " gross slip Delta = 3 delta*: F* = mu P = %.5f N, W = 4 mu P (Delta - 0.8 delta*) = %.5e J"
              % (ref.md_first(Su, A), Su.a_hertz * 0.4 ** (1 / 3) * 1e6, ref.md_energy(Su, A), mP, 4 * mP * (Dg - 0.8 * Su.delta_star)))
        print("%-8s %6s %6s %12s %10s %10s %10s %10s %10s %10s %10s %8s" % (
            "case", "steps", "grid", "W_ref1d[J]", "ref/cf-1", "prod/cf-1", "prod/ref-1", "loop/cf-1", "dd*", "dc", "dF*", "cpu[s]"))
        print("(cf: the closed form; dd*, dF*: the product's delta*, F* relative to the reference; dc: the product's c = sqrt(area{stick}/pi) at +A relative to the reference's c)")
        for label, control, amp, Wcf in (("partial", "force", A, ref.md_energy(Su, A)),
                                         ("gross", "disp", Dg, 4 * mP * (Dg - 0.8 * Su.delta_star))):
            for st in (10, 20, 40):
                mu_, ru = reference_history(Su, control, amp, 2, 1.0, steps=st, k=kt * 1e-9)
                r = ru[-1]
                for n in grids_unworn:
                    pr = run_product(a.bin, a.work, "unworn_%s_n%d_s%d" % (label, n, st), n, control, amp, 2, 1.0, steps=st, k_mm3=kt)
                    wc = pr["wc"][-1]
                    _, c = radii_from_fields(pr, 1.0)
                    loop = pr["case"]["history"]["loop_area_per_cycle_j"]
                    print("%-8s %6d %6s %12.5e %+10.2e %+10.2e %+10.2e %+10.2e %+10.2e %10s %+10.2e %8.1f" % (
                        label, st, "%d^2" % n, r["energy"], rel(r["energy"], Wcf), rel(wc["dissipated_j"], Wcf), rel(wc["dissipated_j"], r["energy"]),
                        rel(loop, Wcf) if loop else float("nan"), rel(wc["shift_amplitude_m"], r["dshift"]),
                        ("%+10.2e" % rel(c, r["c"])) if r["c"] > 0 else "gross", rel(wc["force_amplitude_n"], r["F"]), pr["cpu"]))
                    sys.stdout.flush()

    if "partial" in cases:
        M = 6e5
        N = a.cycles
        A = 0.6 * mP
        m, refs, prods = both("partial", "force", A, N, M, pgrids, "Partial slip")
        per_cycle_table("Partial slip (force control)", prods, refs, 5, m.r)
        final_table("Partial slip (force control)", prods, m, refs, S)
        # the Ciavarella-Hills limit: load left in the slip annulus r > c0
        c0 = S.a_hertz * 0.4 ** (1 / 3)
        pch = m.area_w[m.r > c0] @ np.maximum(m.pressure()[m.r > c0], 0) / S.P
        print("\nload in the slip annulus r > c0 = %.3f um (Ciavarella-Hills limit: 0): reference %.4f P;" % (c0 * 1e6, pch)
              + " product " + ", ".join("%d^2 %.4f P" % (pr["n"], float(np.sum(pr["p"][cell_r(pr["n"], pr["dx"])[0] > c0])) * pr["dx"] ** 2 / S.P) for pr in prods))
        # the reference's own grid error: the same run at other nodes
        if a.ref_check_nodes:
            t0 = time.time()
            mc, rc = reference_history(setup(a.ref_check_nodes, a.ref_rmax), "force", A, N, M)
            x, y = rc[-1], refs[-1]
            print("reference at n = %d relative to n = %d (%.0f s): final V %+.2e, max depth %+.2e, delta* %+.2e, c %+.2e, a %+.2e, W1d %+.2e;"
                  " max|h_%d - h_%d| / max h %.2e"
                  % (a.ref_check_nodes, S.n, time.time() - t0, rel(x["volume"], y["volume"]), rel(x["depth_max"], y["depth_max"]),
                     rel(x["dshift"], y["dshift"]), rel(x["c"], y["c"]), rel(x["a"], y["a"]), rel(x["energy"], y["energy"]),
                     a.ref_check_nodes, S.n, np.max(np.abs(h_at(mc.r, mc.h, m.r) - m.h)) / m.h.max()))
            for pr in prods:
                e = profile_errors(pr, mc.r, x["h"])
                print("  product %d^2 vs the reference at n = %d: V %+.2e, max depth %+.2e, L1(h) %.2e"
                      % (pr["n"], a.ref_check_nodes, rel(pr["wc"][-1]["worn_volume_m3"], x["volume"]),
                         rel(pr["wc"][-1]["depth_max_m"], x["depth_max"]), e["l1"]))
        # cycle jump: M/2, twice the cycles, on one grid
        if not a.skip_jump:
            m2, refs2, prods2 = both("partial", "force", A, 2 * N, M / 2, [a.jump_grid], "Partial slip, half jump")
            pj = [p for p in prods if p["n"] == a.jump_grid][0]
            pj2 = prods2[0]
            pairs = []
            for cyc in (N // 4, N // 2, N):
                i, i2 = cyc - 1, 2 * cyc - 1
                pairs.append(("V at %d M" % cyc, pj["wc"][i]["worn_volume_m3"], pj2["wc"][i2]["worn_volume_m3"], refs[i]["volume"], refs2[i2]["volume"]))
                pairs.append(("hmax at %d M" % cyc, pj["wc"][i]["depth_max_m"], pj2["wc"][i2]["depth_max_m"], refs[i]["depth_max"], refs2[i2]["depth_max"]))
                pairs.append(("delta* at %d M" % cyc, pj["wc"][i]["shift_amplitude_m"], pj2["wc"][i2]["shift_amplitude_m"], refs[i]["dshift"], refs2[i2]["dshift"]))
            jump_table("Partial slip, %d^2" % a.jump_grid, pairs)
            e1 = profile_errors(pj, m.r, refs[-1]["h"])
            e2 = profile_errors(pj2, m2.r, refs2[-1]["h"])
            h_mm = np.max(np.abs(m.h - m2.h)) / m2.h.max()
            print("final profile, %d^2: L1(h) vs the reference at the same M: M %.2e, M/2 %.2e; ring max %.2e, %.2e;"
                  " reference's own M vs M/2: max|h_M - h_M/2| / max h = %.2e" % (a.jump_grid, e1["l1"], e2["l1"], e1["ring_max"], e2["ring_max"], h_mm))
            # product M vs M/2 on the same grid
            w_mm = np.max(np.abs(pj["wear"] - pj2["wear"])) / pj2["wear"].max()
            print("product's own M vs M/2: max|h_M - h_M/2| / max h = %.2e" % w_mm)

    if "disp" in cases:
        M = 6e5
        N = a.cycles
        Delta = ref.md_first(S, 0.6 * mP)
        m, refs, prods = both("disp", "disp", Delta, N, M, grids, "Partial slip")
        per_cycle_table("Partial slip (displacement control)", prods, refs, 5, m.r)
        final_table("Partial slip (displacement control)", prods, m, refs, S)

    if "gross" in cases:
        M = 1e4
        N = 10
        Delta = 3.0 * S.delta_star
        m, refs, prods = both("gross", "disp", Delta, N, M, grids, "Gross slip")
        per_cycle_table("Gross slip (displacement control)", prods, refs, 1, m.r)
        Vcf = 4 * K * S.P * (Delta - 0.8 * S.delta_star)
        Wcf = 4 * S.mu * S.P * (Delta - 0.8 * S.delta_star)
        print("\nworn volume per physical cycle vs 4kP(Delta - 0.8 delta*) = %.5e m^3 (unworn sphere), energy vs 4 mu P (Delta - 0.8 delta*) = %.5e J:" % (Vcf, Wcf))
        print("%5s %12s %12s" % ("cycle", "ref/cf-1", "ref W/cf-1") + "".join(" %12s %12s" % ("%d^2 V/cf-1" % p["n"], "%d^2 W/cf-1" % p["n"]) for p in prods))
        for i, r in enumerate(refs):
            print("%5d %+12.3e %+12.3e" % (r["cycle"], rel(r["vol_per_cycle"], Vcf), rel(r["energy"], Wcf))
                  + "".join(" %+12.3e %+12.3e" % (rel(p["wc"][i]["worn_volume_per_cycle_m3"], Vcf), rel(p["wc"][i]["dissipated_j"], Wcf)) for p in prods))
        final_table("Gross slip (displacement control)", prods, m, refs, S)
        m2, refs2, prods2 = both("gross", "disp", Delta, 2 * N, M / 2, [a.gross_jump_grid], "Gross slip, half jump")
        pj = [p for p in prods if p["n"] == a.gross_jump_grid][0]
        pj2 = prods2[0]
        pairs = []
        for cyc in (N // 2, N):
            i, i2 = cyc - 1, 2 * cyc - 1
            pairs.append(("V at %d M" % cyc, pj["wc"][i]["worn_volume_m3"], pj2["wc"][i2]["worn_volume_m3"], refs[i]["volume"], refs2[i2]["volume"]))
            pairs.append(("hmax at %d M" % cyc, pj["wc"][i]["depth_max_m"], pj2["wc"][i2]["depth_max_m"], refs[i]["depth_max"], refs2[i2]["depth_max"]))
            pairs.append(("V/cycle at %d M" % cyc, pj["wc"][i]["worn_volume_per_cycle_m3"], pj2["wc"][i2]["worn_volume_per_cycle_m3"], refs[i]["vol_per_cycle"], refs2[i2]["vol_per_cycle"]))
        jump_table("Gross slip, %d^2" % a.gross_jump_grid, pairs)

    print("\n# total %.0f s" % (time.time() - t_start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
