#!/usr/bin/env python3
"""mpcontact's shear limit tau_c beside CONTACT's interfacial (plasticity) layer (issue #50).

The case: Cattaneo-Mindlin of Table 1(a), rigid sphere R = 18 mm on Fe (E = 210 GPa, nu = 0.3),
P = 20 N, mu = 0.3, F = 0.6 mu P along x in one step from rest (or in NINC force increments after
the normal load), no normal-tangential coupling; the surface's shear traction bounded by
min(mu p, tau_c), tau_c = RATIO * mu * p0 (p0 the Hertz peak).

Both codes solve the same discrete problem on the same cells: h = 2a/NCELLS (a the Hertz radius),
a square of NCELLS + 2*MARGIN cells centred on the apex (NCELLS odd puts a row of cells on the
load axis y = 0).
  CONTACT (E.A.H. Vollebregt; the peer kit ../shared/peers/contact): gen_catt.py's input with the
    material digit M = 4 (elastic bodies with an interfacial layer and tangential plasticity) and
    the line  GG3 LAYTHK TAU_C0 K_TAU  = 1, 0, tau_c, 0:  LAYTHK = 0 is CONTACT's "plasticity at the
    surface without a third-body layer" (no layer compliance h3/G3), K_TAU = 0 perfectly plastic.
    Its element states: 1 adhesion (stick), 2 slip (|q| = mu p), 3 plastic (|q| = tau_c).
  mpcontact: [materials.Fe] shear_limit_gpa = tau_c, [solver] coupling = false; its slip cells are
    those at the bound min(mu p, tau_c), split here into capped (|q| = tau_c < mu p) and Coulomb.
Checks besides: each code without the limit, and with tau_c = 1000 GPa (CONTACT: M = 4 with
TAU_C0 = 1e6 N/mm^2), which must equal the run without it; and CONTACT with a real but thin layer
(LAYTHK = 0.1 um of Fe's shear modulus) to show its compliance is negligible.

usage: bench/contact_shear_limit.py [--sizes 31 61] [--ratios 0.5 0.6 0.7] [--ninc 1] [--eps 1e-9] [--out DIR]
  (31 61: about 15 s on one core; 121 adds about 45 s; --ninc 10 about doubles the time)
environment:
  CONTACT_EXE    CONTACT's program (default ~/contact-peer/src/bin/contact_linux64, built with
                 ../shared/peers/contact/build.sh GIT_DIR ~/contact-peer)
  CONTACT_KIT    folder with gen_catt.py (default ../shared/peers/contact beside the repo)
  MPCONTACT_EXE  our binary (default target/release/mpcontact, built here with cargo if absent)
Both run on one thread (OMP_NUM_THREADS=1, --threads 1). Prints markdown tables; the axis profiles
q_x(x, y = 0) of both codes go to OUT/nN/profile_RATIO.csv.
"""
import argparse, json, math, os, subprocess, sys, tempfile
import numpy as np

E, NU, R, P, MU, FRATIO = 210000.0, 0.3, 18.0, 20.0, 0.3, 0.6       # N/mm^2, -, mm, N, -, -
A = (3 * P * R / (4 * E / (1 - NU ** 2))) ** (1 / 3)                   # Hertz radius, mm
P0 = 3 * P / (2 * math.pi * A * A)                                      # Hertz peak, N/mm^2
G_FE = E / (2 * (1 + NU))
HUGE = 1.0e6                                                            # N/mm^2 = 1000 GPa
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def sh(cmd, cwd, log):
    env = dict(os.environ, OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", RAYON_NUM_THREADS="1")
    with open(log, "w") as f:
        r = subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT, env=env)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}; see {log}")


# ---------------------------------------------------------------- CONTACT
def contact_input(kit, n, ninc, margin, eps, path, layer):
    """gen_catt.py's input; layer = None (M = 0) or (GG3, LAYTHK, TAU_C0, K_TAU) with M = 4."""
    subprocess.run([sys.executable, f"{kit}/gen_catt.py", str(n), str(ninc), str(margin), str(eps), path],
                   check=True)
    if layer is None:
        return
    out = []
    for line in open(path):
        if "L-D-C-M-Z-E" in line:                       # M, the 4th digit: 4 = interfacial layer
            d = line.split()[0]
            line = line.replace(d, d[:3] + "4" + d[4:], 1)
        out.append(line)
        if "POISS 1,2,  GG 1,2" in line:                # read with the influence coefficients (C >= 2)
            g3, h3, tc, kt = layer
            out.append(f"  {g3:.6f}   {h3:.6e}   {tc:.10g}   {kt:.6f}      GG3, LAYTHK, TAU_C0, K_TAU\n")
    open(path, "w").write("".join(out))


def read_contact(d, name, case, mx):
    """The last case's .mat (contact cells only) as full mx x mx arrays (rows y, columns x), plus the
    shift from the .out and from the stick cells' displacement difference."""
    cols, rows = None, []
    for line in open(f"{d}/{name}.{case:04d}.mat"):
        if line.startswith("%"):
            w = line[1:].split()
            if "IGS" in w:
                cols = w
        elif cols and line.strip():
            rows.append([float(x) for x in line.split()])
    t = np.array(rows)
    f = {c: np.zeros((mx, mx)) for c in cols[1:]}
    i = t[:, 0].astype(int) - 1
    for k, c in enumerate(cols[1:], 1):
        f[c][i // mx, i % mx] = t[:, k]
    txt = open(f"{d}/{name}.out").read().split(" Case ")[-1].split()
    k = txt.index("APPROACH")
    f["shift_out"] = abs(float(txt[k + 3]))            # FN/G, SHIFT X, SHIFT Y, APPROACH / values
    st = f["IGS"] == 1
    f["shift"] = abs(f["UX"][st].mean()) if st.any() else f["shift_out"]   # stick: slip 0 = shift + u
    f["shift_spread"] = float(np.ptp(f["UX"][st])) if st.any() else float("nan")
    return f


# ---------------------------------------------------------------- mpcontact
def ours_config(path, n, margin, h_um, tau_gpa, ninc, tol):
    s = f"""[grid]
points = {n + 2 * margin}
spacing_um = {h_um!r}
[indenter]
radius_mm = {R}
[load]
normal_n = {P}
friction = {MU}
tangential_ratio = {FRATIO}
[sweep]
materials = ["Fe"]
surfaces = ["flat"]
angles_deg = [0.0]
[solver]
coupling = false
tangential_tolerance = {tol}
"""
    if ninc > 1:
        s += f"[history]\ntangential_ratios = [0.0, {FRATIO}]\nsteps_per_segment = {ninc}\n"
    if tau_gpa is not None:
        s += f"[materials.Fe]\nshear_limit_gpa = {tau_gpa!r}\n"
    open(path, "w").write(s)


def read_ours(d):
    c = json.load(open(f"{d}/case.json"))
    f = {k: np.load(f"{d}/{k}.npy") for k in ("p", "qx", "qy", "stick", "sx", "sy")}
    f["case"] = c
    f["shift"] = abs(c["delta_t_m"]) * 1e3             # mm
    if c.get("history"):
        st = c["history"]["steps"]
        f["shift"] = abs(st[-1]["delta_t_m"][0]) * 1e3
    return f


# ---------------------------------------------------------------- classification
def classes(p, qx, qy, tau, rel=1e-5):
    """contact, stick, capped (|q| = tau_c < mu p), Coulomb slip (|q| = mu p <= tau_c) from the fields"""
    q = np.hypot(qx, qy)
    con = p > 0
    bound = np.minimum(MU * p, tau)
    at = con & (q >= (1 - rel) * bound)
    capped = at & (tau < MU * p)
    return con, con & ~at, capped, at & ~capped


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[31, 61], help="cells across 2a")
    ap.add_argument("--ratios", type=float, nargs="+", default=[0.5, 0.6, 0.7], help="tau_c / (mu p0)")
    ap.add_argument("--ninc", type=int, default=1, help="force increments (1: one step from rest)")
    ap.add_argument("--eps", type=float, default=1e-9, help="CONTACT's EPS; ours tangential_tolerance")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    out = os.path.abspath(args.out or tempfile.mkdtemp(prefix="mpcontact-shear-limit."))
    kit = os.environ.get("CONTACT_KIT", os.path.join(ROOT, "..", "shared", "peers", "contact"))
    cexe = os.path.expanduser(os.environ.get("CONTACT_EXE", "~/contact-peer/src/bin/contact_linux64"))
    oexe = os.environ.get("MPCONTACT_EXE")
    if not oexe:
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "mpcontact"], cwd=ROOT, check=True)
        oexe = os.path.join(ROOT, "target", "release", "mpcontact")
    for x, what in ((cexe, "CONTACT_EXE"), (oexe, "MPCONTACT_EXE")):
        if not os.access(x, os.X_OK):
            sys.exit(f"not an executable: {x} (set {what})")
    print(f"out: {out}; CONTACT {cexe}; mpcontact {oexe}; a = {A * 1e3:.4f} um, p0 = {P0:.3f} MPa, "
          f"F = {FRATIO * MU * P:.3f} N, NINC = {args.ninc}, EPS = {args.eps:g}", file=sys.stderr)
    last = args.ninc + 1 if args.ninc > 1 else 1            # CONTACT's case number of the final state
    runs = [("elastic", None), ("huge", HUGE)] + [(f"{r:g}", r * MU * P0) for r in args.ratios]
    checks, main_rows, prof_rows = [], [], []
    for n in args.sizes:
        m = max(4, n // 4)
        mx = n + 2 * m
        h = 2 * A / n
        d = os.path.join(out, f"n{n}")
        os.makedirs(d, exist_ok=True)
        res = {}
        for tag, tau in runs:
            # CONTACT
            cd = os.path.join(d, f"contact_{tag}")
            os.makedirs(cd, exist_ok=True)
            layer = None if tau is None else (1.0, 0.0, tau, 0.0)
            contact_input(kit, n, args.ninc, m, args.eps, f"{cd}/catt.inp", layer)
            sh(["nice", "-n", "19", cexe, "2", "catt"], cd, f"{cd}/stdout")
            cf = read_contact(cd, "catt", last, mx)
            # ours
            od = os.path.join(d, f"ours_{tag}")
            os.makedirs(od, exist_ok=True)
            ours_config(f"{od}/ours.toml", n, m, h * 1e3, None if tau is None else tau / 1e3, args.ninc,
                        args.eps)
            sh(["nice", "-n", "19", oexe, "solve", f"{od}/ours.toml", "--out", f"{od}/out", "--threads", "1",
                "--quiet"], od, f"{od}/stdout")
            of = read_ours(f"{od}/out")
            res[tag] = (cf, of, tau)
        if args.ratios:
            # a real layer, thin: 0.1 um of Fe's shear modulus, at the first ratio
            tau = args.ratios[0] * MU * P0
            cd = os.path.join(d, "contact_thinlayer")
            os.makedirs(cd, exist_ok=True)
            contact_input(kit, n, args.ninc, m, args.eps, f"{cd}/catt.inp", (G_FE, 1e-4, tau, 0.0))
            sh(["nice", "-n", "19", cexe, "2", "catt"], cd, f"{cd}/stdout")
            thin = read_contact(cd, "catt", last, mx)
        # checks: the limit that never binds changes nothing, in each code
        ce, oe = res["elastic"][0], res["elastic"][1]
        ch, oh = res["huge"][0], res["huge"][1]
        sc = MU * P0
        checks.append((n, "CONTACT M=4, TAU_C0 = 1e6 N/mm² vs M=0",
                       np.abs(ch["PX"] - ce["PX"]).max() / sc, abs(ch["shift"] / ce["shift"] - 1),
                       int((ch["IGS"] != ce["IGS"]).sum())))
        checks.append((n, "ours shear_limit_gpa = 1000 vs none",
                       np.abs(oh["qx"] - oe["qx"]).max() / 1e6 / sc, abs(oh["shift"] / oe["shift"] - 1),
                       int(((oh["stick"] > .5) != (oe["stick"] > .5)).sum())))
        if args.ratios:
            c1 = res[f"{args.ratios[0]:g}"][0]
            checks.append((n, f"CONTACT thin layer (LAYTHK 0.1 µm, GG3 = G_Fe) vs LAYTHK 0, τ_c = {args.ratios[0]:g} μp0",
                           np.abs(thin["PX"] - c1["PX"]).max() / sc, abs(thin["shift"] / c1["shift"] - 1),
                           int((thin["IGS"] != c1["IGS"]).sum())))
        for tag, (cf, of, tau) in res.items():
            if tag == "huge":
                continue
            t = HUGE if tau is None else tau
            # CONTACT's fields in N/mm^2, ours in Pa -> N/mm^2
            op, oqx, oqy = of["p"] / 1e6, of["qx"] / 1e6, of["qy"] / 1e6
            ccon, cst, ccap, cslip = classes(cf["PN"], cf["PX"], cf["PY"], t)
            ocon, ost, ocap, oslip = classes(op, oqx, oqy, t)
            igs = cf["IGS"]
            c_igs = ((igs >= 1).sum(), (igs == 1).sum(), (igs == 3).sum(), (igs == 2).sum())
            o_stick_map = int((of["stick"] > .5).sum())
            # the local tangential motion: ours the slip s (m); CONTACT the slip distance SHFT plus, in its
            # plastic cells, the plastic displacement UPLS (mm); one step from rest only (in increments
            # CONTACT's SHFT is the last increment's)
            ds = float("nan")
            if args.ninc == 1:
                c_s = cf["SHFT"] + (np.hypot(cf["UPLSX"], cf["UPLSY"]) if "UPLSX" in cf else 0)
                ds = np.abs(np.hypot(of["sx"], of["sy"]) * 1e3 - c_s)[ccon].max() / cf["shift"]
            ha = h / A
            ceq = lambda k: math.sqrt(k / math.pi) * ha          # equivalent radius / a of k cells
            # capacity sum min(mu p, tau) dA (of the solved p) vs the closed form
            cap_c = np.minimum(MU * cf["PN"], t).sum() * h * h
            cap_o = np.minimum(MU * op, t).sum() * h * h
            if tau is None:
                cf_closed = MU * P
            else:
                r1 = A * math.sqrt(max(0.0, 1 - (t / (MU * P0)) ** 2))
                cf_closed = t * math.pi * r1 ** 2 + 2 * math.pi / 3 * MU * P0 * A ** 2 * (1 - r1 ** 2 / A ** 2) ** 1.5
            main_rows.append(dict(
                n=n, tag=tag, grid=mx, h_um=h * 1e3,
                contact=(int(ocon.sum()), int(c_igs[0])), stick=(int(ost.sum()), int(c_igs[1])),
                stick_map=o_stick_map, capped=(int(ocap.sum()), int(c_igs[2])), slip=(int(oslip.sum()), int(c_igs[3])),
                c_fromq=(int(cst.sum()), int(ccap.sum()), int(cslip.sum())),
                c_eq=(ceq(ost.sum()), ceq(c_igs[1])), cap_eq=(ceq(ocap.sum() + ost.sum()), ceq(c_igs[2] + c_igs[1])),
                shift=(of["shift"] * 1e3, cf["shift"] * 1e3), shift_out=cf["shift_out"] * 1e3,
                shift_spread=cf["shift_spread"] * 1e3,
                ds=ds, dq=np.abs(oqx - cf["PX"]).max() / (MU * P0), dp=np.abs(op - cf["PN"]).max() / P0,
                qmax=(np.hypot(oqx, oqy).max(), np.hypot(cf["PX"], cf["PY"]).max()), tau=t,
                cap=(cap_o, cap_c, cf_closed),
                r1="—" if tau is None else f"{math.sqrt(max(0.0, 1 - (t / (MU * P0)) ** 2)):.4f}",
                its=(of["case"]["tangential_iterations"], of["case"]["converged"])))
            # the axis profile: the row y = 0 (NCELLS odd), else the row nearest it
            j = mx // 2
            x = (np.arange(mx) - (mx - 1) / 2) * h
            with open(os.path.join(d, f"profile_{tag}.csv"), "w") as fo:
                fo.write("x_over_a,p0_ours_MPa,p_contact_MPa,qx_ours_MPa,qx_contact_MPa,bound_MPa,igs_contact,stick_ours\n")
                for i in range(mx):
                    fo.write(f"{x[i] / A:.6f},{op[j, i]:.6f},{cf['PN'][j, i]:.6f},{oqx[j, i]:.6f},{cf['PX'][j, i]:.6f},"
                             f"{min(MU * op[j, i], t):.6f},{int(igs[j, i])},{int(of['stick'][j, i] > .5)}\n")
            if tag not in ("elastic",):
                sel = [i for i in range(mx) if op[j, i] > 0 and x[i] >= 0]
                prof_rows.append((n, tag, [(x[i] / A, oqx[j, i], cf["PX"][j, i], int(igs[j, i]),
                                            int(of["stick"][j, i] > .5)) for i in sel]))

    print("\n### Checks: a limit that never binds, and the layer's compliance\n")
    print("| cells across 2a | runs compared | max \\|Δq_x\\| / μp0 | shift rel. diff | cells whose state differs |")
    print("|---|---|---|---|---|")
    for n, what, dq, ds, k in checks:
        print(f"| {n} | {what} | {dq:.1e} | {ds:.1e} | {k} |")
    print("\n### mpcontact (ours) / CONTACT, F = 0.6 μP" + (" in one step" if args.ninc == 1 else f" in {args.ninc} increments"))
    print("\n| cells across 2a | τ_c / μp0 | contact cells | stick cells | capped cells (\\|q\\| = τ_c) | Coulomb slip cells | "
          "stick radius √(N h²/π)/a | stick+capped radius / a (r₁/a) | shift δt (µm) | shift rel. diff | max \\|Δq_x\\| / μp0 | "
          "max \\|q\\| / τ_c | capacity Σmin(μp,τ_c)ΔA (N): ours / CONTACT / closed form |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in main_rows:
        f = lambda t: f"{t[0]} / {t[1]}"
        tau_lbl = "∞ (none)" if r["tag"] == "elastic" else r["tag"]
        qm = "—" if r["tag"] == "elastic" else f"{r['qmax'][0] / r['tau']:.6f} / {r['qmax'][1] / r['tau']:.6f}"
        print(f"| {r['n']} ({r['grid']}² of {r['h_um']:.4f} µm) | {tau_lbl} | {f(r['contact'])} | {f(r['stick'])} | "
              f"{f(r['capped'])} | {f(r['slip'])} | {r['c_eq'][0]:.4f} / {r['c_eq'][1]:.4f} | "
              f"{r['cap_eq'][0]:.4f} / {r['cap_eq'][1]:.4f} ({r['r1']}) | {r['shift'][0]:.6f} / {r['shift'][1]:.6f} | "
              f"{r['shift'][0] / r['shift'][1] - 1:+.1e} | {r['dq']:.1e} | {qm} | "
              f"{r['cap'][0]:.5f} / {r['cap'][1]:.5f} / {r['cap'][2]:.5f} |")
    print("\nNotes: CONTACT's counts are its element states (IGS 1 adhesion, 3 plastic, 2 slip); from its tractions "
          "(|q| against min(μp, τ_c), rel. 1e-5) they are, stick / capped / slip:")
    for r in main_rows:
        print(f"- {r['n']}, {r['tag']}: {r['c_fromq'][0]} / {r['c_fromq'][1]} / {r['c_fromq'][2]}; ours stick.npy "
              f"{r['stick_map']} cells; CONTACT shift from its .out {r['shift_out']:.4f} µm, spread over its stick cells "
              f"{r['shift_spread']:.1e} µm; ours tangential its {r['its'][0]}, converged {r['its'][1]}; "
              f"max |Δp| / p0 {r['dp']:.1e}; max |Δ(slip + plastic displacement)| / δt {r['ds']:.1e}")
    print("\n### q_x on the load axis (y = 0, x ≥ 0; MPa): x/a, ours, CONTACT, CONTACT state, ours stick\n")
    print("(every k-th cell of the row and every cell where CONTACT's state changes; S: stick in ours; "
          "all cells in OUT/nN/profile_TAG.csv)\n")
    for n, tag, pts in prof_rows:
        k = max(1, len(pts) // 12)
        keep = [i for i in range(len(pts)) if i % k == 0 or i == len(pts) - 1 or (i and pts[i][3] != pts[i - 1][3])]
        dmax = max(abs(a - b) for _, a, b, _, _ in pts)
        print(f"- {n} cells, τ_c = {tag} μp0 (max |Δq_x| on the row {dmax:.1e} MPa): " + "; ".join(
            f"{pts[i][0]:.3f}: {pts[i][1]:.3f} / {pts[i][2]:.3f} ({pts[i][3]}{'S' if pts[i][4] else ''})" for i in keep))


if __name__ == "__main__":
    main()
