"""Python against the CLI, to the bit: prints the table of docs/validation.md.

For each config, `mpcontact solve` (its case.json and .npy fields) and
`mpcontact.solve` on the same config; then `mpcontact run` and
`mpcontact.run` of one sweep (results.csv without the wall times and worker
ids). Run from the repository root with the package installed:

    python bench/python_vs_cli.py [--cli target/release/mpcontact]
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import mpcontact

REPO = Path(__file__).resolve().parents[1]
TIMES = ("seconds", "kernel_seconds")


def bits(v):
    return np.float64(v).tobytes() if isinstance(v, float) else v


def same(a, b):
    """Equal, with floats compared by their bits (nested)."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and bits(a) == bits(b)


def solve_row(cli, config, tmp, sets=()):
    out = tmp / f"cli-{config.stem}"
    set_args = [a for s in sets for a in ("--set", s)]
    t0 = time.time()
    subprocess.run([cli, "solve", config, "--out", out, *set_args], check=True, capture_output=True)
    t_cli = time.time() - t0
    case = json.loads((out / "case.json").read_text())
    cfg = mpcontact.Config.from_toml(config)
    for s in sets:
        key, value = s.split("=", 1)
        cfg.set(key, json.loads(value))
    t0 = time.time()
    res = mpcontact.solve(cfg)
    t_py = time.time() - t0
    keys = [k for k in case if k not in TIMES]
    equal_keys = sum(same(res.scalars[k], case[k]) for k in keys)
    equal_fields = sum(
        res.fields[f].tobytes() == np.load(out / f"{f}.npy").tobytes() for f in mpcontact.FIELD_NAMES
    )
    n = case["grid_points"]
    label = config.name + "".join(f" --set {s}" for s in sets)
    return (
        f"| {label} | {n}² | {equal_keys}/{len(keys)} "
        f"(+ {', '.join(TIMES)}: wall times) | {equal_fields}/9 | {t_cli:.2f} | {t_py:.2f} |"
    )


def table(path, drop=("seconds", "worker")):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    keep = [i for i, name in enumerate(rows[0]) if name not in drop]
    return [[r[i] for i in keep] for r in rows]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default=str(Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target")) / "release" / "mpcontact"))
    args = ap.parse_args()
    cli = args.cli
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        print("| config | grid | case.json keys bit-equal | fields bit-equal | CLI s | Python s |")
        print("|---|---|---|---|---|---|")
        for config, sets in [
            ("configs/paper-1a-fe.toml", ()),
            ("configs/mindlin-uncoupled.toml", ()),
            ("configs/paper-1a-fe111.toml", ()),
            ("configs/examples/heightmap.toml", ()),
            ("configs/paper-1c-patterns.toml", ('sweep.materials=["Cu(111)"]', 'sweep.surfaces=["circle-A"]')),
        ]:
            print(solve_row(cli, REPO / config, tmp, sets))
        sweep = REPO / "configs" / "quick.toml"
        t0 = time.time()
        subprocess.run([cli, "run", sweep, "--workers", "2", "--quiet", "--out", tmp / "cli-run"], check=True)
        t_cli = time.time() - t0
        t0 = time.time()
        mpcontact.run(mpcontact.Config.from_toml(sweep), workers=2, out=tmp / "py-run", progress=False)
        t_py = time.time() - t0
        for name in ("results.csv", "curves.csv"):
            a, b = table(tmp / "cli-run" / name), table(tmp / "py-run" / name)
            print(
                f"\nquick.toml sweep, 2 workers: {name} {'identical' if a == b else 'DIFFERENT'} "
                f"({len(a) - 1} rows; seconds and worker columns left out)"
            )
        print(f"wall time: CLI {t_cli:.1f} s, Python {t_py:.1f} s")


if __name__ == "__main__":
    sys.exit(main())
