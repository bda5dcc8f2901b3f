#!/usr/bin/env python3
"""Markdown tables from the JSON lines of bench/compare.sh (standard library only).

    report.py OUT/compare.jsonl [--sweep-dir OUT]

(a) Hertz normal: solver/mode × threads, per N "seconds (iterations)" (with
    "+ k coarse" when a line reports coarse-level iterations), then the
    p_max and contact-radius errors (one value per N, in column order), and for
    each mpcontact mode and thread count a row "mpcontact time ÷ fastest peer
    time" at each N (< 1: mpcontact is faster; the peer is named).
(b) partial slip, (c) mpcontact's FFT floor (time per iteration vs one FFT),
(d) the paper sweep from SWEEP_DIR/sweep-W/summary.json (W = 1, 2).
Lines with "ok": false are listed under "Failures".
"""

import argparse
import datetime
import json
import math
import os
import subprocess
import sys


def load(path):
    rows = []
    with open(path) as f:
        for i, line in enumerate(f, 1):
            line = line.strip()
            if not line.startswith("{"):
                continue
            try:
                rows.append(json.loads(line))
            except json.JSONDecodeError as e:
                sys.stderr.write(f"{path}:{i}: skipped, not JSON ({e})\n")
    return rows


def kind(r):
    return r.get("kind") or "hertz"


def num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def fs(v):
    """Seconds."""
    if not num(v):
        return "—"
    if v >= 100:
        return f"{v:.0f}"
    if v >= 10:
        return f"{v:.1f}"
    if v >= 1:
        return f"{v:.2f}"
    return f"{v:.3g}"


def fe(v):
    """Signed relative error."""
    return f"{v:+.2e}" if num(v) else "—"


def fr(v, nd=4):
    return f"{v:.{nd}f}" if num(v) else "—"


def label(r):
    m = r.get("mode")
    return f"{r.get('solver', '?')} / {m}" if m else str(r.get("solver", "?"))


def is_ours(r):
    return r.get("solver") == "mpcontact"


def order_key(r):
    return (0 if is_ours(r) else 1, str(r.get("solver")), str(r.get("mode")), str(r.get("threads")))


def latest(rows, key):
    """Last row per key (a re-run overrides an earlier line)."""
    out = {}
    for r in rows:
        out[key(r)] = r
    return out


def table(header, body):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in body]
    return "\n".join(lines)


def hertz_table(rows):
    ok = [r for r in rows if kind(r) == "hertz" and r.get("ok", True) and "n" in r]
    if not ok:
        return "(no Hertz results)"
    sizes = sorted({int(r["n"]) for r in ok})
    cells = latest(ok, lambda r: (r.get("solver"), r.get("mode"), r.get("threads"), int(r["n"])))
    series = sorted({(k[0], k[1], k[2]) for k in cells}, key=lambda k: (k[0] != "mpcontact", str(k[0]), str(k[1]), str(k[2])))
    header = ["solver / mode", "threads"] + [f"{n}² s (it)" for n in sizes]
    header += ["p_max err (" + " / ".join(f"{n}²" for n in sizes) + ")", "radius err (" + " / ".join(f"{n}²" for n in sizes) + ")"]
    body = []
    for s, m, t in series:
        got = [cells.get((s, m, t, n)) for n in sizes]
        row = [label({"solver": s, "mode": m}), t if t is not None else "—"]
        for r in got:
            if r is None:
                row.append("—")
            else:
                it, c = r.get("iterations"), r.get("coarse_iterations")
                if it is not None and num(c) and c > 0:
                    it = f"{it} + {c} coarse"
                row.append(f"{fs(r.get('seconds'))} ({it})" if it is not None else fs(r.get("seconds")))
        row.append(" / ".join(fe(r.get("pmax_err")) if r else "—" for r in got))
        row.append(" / ".join(fe(r.get("radius_err")) if r else "—" for r in got))
        body.append(row)
    # mpcontact ÷ fastest peer, per mpcontact mode and thread count.
    for s, m, t in series:
        if s != "mpcontact":
            continue
        row = [f"**{label({'solver': s, 'mode': m})} ÷ fastest peer**", t if t is not None else "—"]
        for n in sizes:
            ours = cells.get((s, m, t, n))
            peers = [r for (ps, pm, pt, pn), r in cells.items() if ps != "mpcontact" and pt == t and pn == n and num(r.get("seconds"))]
            if not ours or not num(ours.get("seconds")) or not peers:
                row.append("—")
                continue
            best = min(peers, key=lambda r: r["seconds"])
            row.append(f"{ours['seconds'] / best['seconds']:.2f} (vs {label(best)})")
        row += ["", ""]
        body.append(row)
    return table(header, body)


def slip_table(rows):
    ok = [r for r in rows if kind(r) == "slip" and r.get("ok", True)]
    if not ok:
        return "(no partial-slip results)"
    cells = latest(ok, lambda r: (r.get("solver"), r.get("mode"), r.get("n"), r.get("threads")))
    header = ["solver / mode", "N", "threads", "seconds", "iterations", "c/a", "c/a err", "p_max err", "radius err", "notes"]
    body = []
    for r in sorted(cells.values(), key=lambda r: order_key(r) + (r.get("n") or 0,)):
        notes = []
        if "periodic" in r:
            notes.append("periodic" if r["periodic"] else "non-periodic")
        if "coupled" in r:
            notes.append("coupled" if r["coupled"] else "uncoupled")
        if num(r.get("nu")):
            notes.append(f"ν = {r['nu']}")
        if r.get("iteration_budget"):
            notes.append(f"fixed budget {r['iteration_budget']} it")
        if r.get("note"):
            notes.append(str(r["note"]))
        n = r.get("n")
        body.append([
            label(r), f"{n}²" if n else "—", r.get("threads", "—"), fs(r.get("seconds")), r.get("iterations", "—"),
            fr(r.get("c_over_a")), fe(r.get("c_over_a_err")), fe(r.get("pmax_err")), fe(r.get("radius_err")),
            ", ".join(notes),
        ])
    return table(header, body) + "\n\nc/a err is relative to Cattaneo–Mindlin (1 − F/μP)^(1/3) = 0.7368."


def fft_table(rows):
    ok = [r for r in rows if kind(r) == "fft_floor" and r.get("ok", True)]
    if not ok:
        return "(no FFT-floor results)"
    cells = latest(ok, lambda r: (r.get("what", ""), r.get("n"), r.get("threads")))
    # "÷ FFT (hot loop)": the transforms timed alone, best of many, hot in
    # cache; "÷ own FFTs (in place)": a solve's time over the time of the
    # transforms it ran itself (fft2::timing), with the iteration's cache state.
    # "÷ floor (in place)": over its own transforms plus its spectral
    # products (one read of the kernel spectra per application), the floor of
    # issue #19.
    header = ["iteration", "N", "threads", "s / iteration", "s / FFT (hot loop)", "iteration ÷ FFT (hot loop)", "solve ÷ own FFTs (in place)",
              "solve ÷ own FFTs + products (in place)"]
    body = []
    for r in sorted(cells.values(), key=lambda r: (r.get("what", ""), r.get("n") or 0, str(r.get("threads")))):
        ratio = r.get("ratio")
        if not num(ratio) and num(r.get("iter_seconds")) and num(r.get("fft_seconds")) and r["fft_seconds"] > 0:
            ratio = r["iter_seconds"] / r["fft_seconds"]
        # Tangential iterations run on the contact window (its transforms are the floor).
        n = f"{r.get('n')}²" + (f" (window {r['window']}²)" if r.get("window") else "")
        # The in-place timing sees only the calling thread's transforms: with
        # more threads its ratio means nothing (older lines printed one).
        one = r.get("threads") in (1, None)
        in_place = [fr(r.get(k), 2) if one else "—" for k in ("in_situ_ratio", "floor_ratio")]
        body.append([r.get("what", "—"), n, r.get("threads", "—"), fs(r.get("iter_seconds")), fs(r.get("fft_seconds")),
                     fr(ratio, 2)] + in_place)
    return table(header, body)


def sweep_table(sweep_dir):
    if not sweep_dir:
        return "(sweep skipped)"
    runs = []
    for w in (1, 2):
        p = os.path.join(sweep_dir, f"sweep-{w}", "summary.json")
        if os.path.exists(p):
            with open(p) as f:
                runs.append((w, json.load(f)))
    if not runs:
        return "(sweep skipped or no summary.json)"
    base = dict(runs).get(1, {}).get("wall_seconds")
    header = ["workers", "cases", "wall (s)", "speed-up vs 1 worker"]
    body = []
    for w, s in runs:
        wall = s.get("wall_seconds")
        sp = base / wall if num(base) and num(wall) and wall > 0 else None
        body.append([s.get("workers", w), s.get("total", "—"), fs(wall), fr(sp, 2)])
    return table(header, body)


def failures(rows):
    bad = [r for r in rows if r.get("ok") is False]
    if not bad:
        return ""
    out = ["### Failures", ""]
    for r in bad:
        n = r.get("n")
        where = f"{label(r)}, {kind(r)}" + (f", {n}²" if n else "") + f", threads {r.get('threads', '—')}"
        out.append(f"- {where}: {r.get('error', 'no message')}")
    return "\n".join(out)


def git_commit():
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("jsonl")
    ap.add_argument("--sweep-dir", default=None, help="directory holding sweep-1/ and sweep-2/")
    ap.add_argument("--no-header", action="store_true")
    args = ap.parse_args()
    rows = load(args.jsonl)
    parts = []
    if not args.no_header:
        parts.append(f"commit {git_commit()}, {datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}, "
                     f"{os.cpu_count()} cores; results: {args.jsonl}")
    parts += ["### (a) Hertz normal contact (Table 1a; solve only, median)", hertz_table(rows),
              "### (b) Partial slip (μ = 0.28571, F = 0.6 μP)", slip_table(rows),
              "### (c) mpcontact FFT floor", fft_table(rows),
              "### (d) Paper sweep (configs/paper-1c-sweep.toml)", sweep_table(args.sweep_dir)]
    f = failures(rows)
    if f:
        parts.append(f)
    print("\n\n".join(parts))


if __name__ == "__main__":
    main()
