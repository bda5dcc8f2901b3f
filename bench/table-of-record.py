#!/usr/bin/env python3
"""The converged table of record (docs/validation.md) from a sweep run with a
convergence ladder, e.g.

    mpcontact run configs/paper-1c-sweep.toml --refine 2 --out paper-refine2
    python3 bench/table-of-record.py paper-refine2

(that config sets the paper's hull radii; `--set solver.radii=moments` gives
the second moments' table, the default definition elsewhere.)

Prints, per material x surface, μa ± error over the force angles, whether its
variation over angle is resolved, and the paper's qualitative claims checked
against the error bars. Standard library only."""
import csv, json, sys
from collections import defaultdict

out = sys.argv[1]
summary = json.load(open(f"{out}/summary.json"))
pts = defaultdict(list)
for r in csv.DictReader(open(f"{out}/curves.csv")):
    err = float(r["mu_a_err"]) if r["mu_a_err"] else float("nan")
    pts[(r["material"], r["surface"])].append((float(r["angle_deg"]), float(r["mu_a"]), err, r))
materials = list(dict.fromkeys(m for m, _ in pts))
surfaces = ["flat", "circle-A", "circle-B", "square-A", "square-B"]

def stats(m, s):
    p = pts[(m, s)]
    mus = [v for _, v, _, _ in p]
    errs = [e for _, _, e, _ in p]
    mean = sum(mus) / len(mus)
    return mean, min(mus), max(mus), max(errs)

print(f"levels: {summary['convergence_levels']}, cases: {summary['total']}, ok: {summary['ok']}\n")
print("| material | surface | μa at 0° | mean μa over ψ | min – max over ψ | largest error bar | variation over ψ resolved |")
print("|---|---|---|---|---|---|---|")
for m in materials:
    for s in surfaces:
        if (m, s) not in pts:
            continue
        mean, lo, hi, err = stats(m, s)
        p0 = next(p for p in pts[(m, s)] if p[0] == 0.0)
        res = summary["curves"][f"{m} / {s}"]["resolved"]
        print(f"| {m} | {s} | {p0[1]:.4f} ± {p0[2]:.4f} | {mean:.4f} | {lo:.4f} – {hi:.4f} | {err:.4f} | {'yes' if res else 'no'} |")

def beyond(a, b):
    """Curve a lies above curve b at every angle by more than both error bars."""
    pa = {x: (v, e) for x, v, e, _ in pts[a]}
    pb = {x: (v, e) for x, v, e, _ in pts[b]}
    return all(pa[x][0] - pa[x][1] > pb[x][0] + pb[x][1] for x in pa if x in pb)

print("\nClaims (at every angle, beyond both error bars):\n")
print("| material | patterned > flat (all four) | A > B, circles | A > B, squares | circle ≠ square, A | circle ≠ square, B |")
print("|---|---|---|---|---|---|")
yn = lambda b: "holds" if b else "not beyond error"
for m in materials:
    pf = all(beyond((m, s), (m, "flat")) for s in surfaces[1:])
    ab_c = beyond((m, "circle-A"), (m, "circle-B"))
    ab_s = beyond((m, "square-A"), (m, "square-B"))
    def differ(x, y):
        return beyond((m, x), (m, y)) or beyond((m, y), (m, x))
    print(f"| {m} | {yn(pf)} | {yn(ab_c)} | {yn(ab_s)} | {yn(differ('circle-A', 'square-A'))} | {yn(differ('circle-B', 'square-B'))} |")

print("\nDirection dependence: range of μa over ψ (max − min) against the largest error bar, crystal vs isotropic twin:\n")
print("| surface | Cu range | Cu(111) range | Ni range | Ni(111) range |")
print("|---|---|---|---|---|")
for s in surfaces[1:]:
    cells = []
    for m in ["Cu", "Cu(111)", "Ni", "Ni(111)"]:
        if (m, s) in pts:
            mean, lo, hi, err = stats(m, s)
            cells.append(f"{hi - lo:.4f} (err ≤ {err:.4f})")
        else:
            cells.append("–")
    print(f"| {s} | " + " | ".join(cells) + " |")
