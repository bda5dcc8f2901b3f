"""The paper's Fig. 9 from a sweep's output directory.

(a) K_E versus force angle on the flat (111) substrates (the flat-calibrated
K_E of results.csv); (b) apparent friction coefficient μa versus force angle,
one panel per material, one line per surface (curves.csv), markers at the
computed angles.

    python examples/fig9.py OUT                 # OUT: a `mpcontact run` / mpcontact.run output
    python examples/fig9.py OUT --config configs/paper-1c-sweep.toml --workers 2
                                                # runs the sweep first when OUT has no curves.csv
    python examples/fig9.py OUT --png fig9.png  # default: OUT/fig9.png

Needs matplotlib (not needed by the package or its tests).
"""

import argparse
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    """Rows of a CSV as dicts (the runner's current columns, by name)."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    return float(text) if text != "" else float("nan")


def series(rows, key, value, keep=lambda r: True):
    """{key(row): ([angles], [values])} sorted by angle."""
    out = defaultdict(list)
    for r in rows:
        if keep(r):
            out[key(r)].append((number(r["angle_deg"]), number(r[value])))
    return {k: tuple(map(list, zip(*sorted(v)))) for k, v in sorted(out.items())}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path, help="sweep output directory (curves.csv, results.csv)")
    ap.add_argument("--config", type=Path, help="run this sweep first when OUT has no curves.csv")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--png", type=Path, help="output image (default OUT/fig9.png)")
    args = ap.parse_args()

    if not (args.out / "curves.csv").is_file():
        if args.config is None:
            sys.exit(f"{args.out}/curves.csv not found (give --config to run the sweep)")
        import mpcontact

        mpcontact.run(mpcontact.Config.from_toml(args.config), workers=args.workers, out=args.out)

    results = read_csv(args.out / "results.csv")
    curves = read_csv(args.out / "curves.csv")

    k_e = series(
        results,
        key=lambda r: r["material"],
        value="k_e",
        keep=lambda r: r["surface"] == "flat" and "(111)" in r["material"] and r["status"] == "ok",
    )
    mu = defaultdict(dict)
    for (material, surface), xy in series(
        curves, key=lambda r: (r["material"], r["surface"]), value="mu_a"
    ).items():
        mu[material][surface] = xy
    materials = list(mu)
    if not materials:
        sys.exit(f"{args.out}/curves.csv has no converged case with a μa")

    fig = plt.figure(figsize=(4.2 * max(2, len(materials)), 7.6), constrained_layout=True)
    grid = fig.add_gridspec(2, max(2, len(materials)))
    ax = fig.add_subplot(grid[0, :])
    for material, (angles, values) in k_e.items():
        ax.plot(angles, [v / 1e9 for v in values], "o-", label=material)
    ax.set_xlabel("force angle ψ (°)")
    ax.set_ylabel("K_E (GPa)")
    ax.set_title("(a) K_E on the flat (111) substrates" if k_e else "(a) no flat (111) case in this sweep")
    if k_e:
        ax.legend()
    ax.set_xlim(0, 180)
    ax.set_xticks(range(0, 181, 30))

    markers = "osD^v<>ph*"
    for i, material in enumerate(materials):
        # Each material on its own scale: patterned Ni reaches μa ≈ 2, flat Cu stays at μ.
        ax = fig.add_subplot(grid[1, i])
        by_surface = sorted(mu[material].items(), key=lambda kv: (kv[0] != "flat", kv[0]))
        for j, (surface, (angles, values)) in enumerate(by_surface):
            ax.plot(angles, values, marker=markers[j % len(markers)], ms=4, label=surface)
        ax.set_title(f"(b) {material}")
        ax.set_xlabel("force angle ψ (°)")
        ax.set_xlim(0, 180)
        ax.set_xticks(range(0, 181, 45))
        if i == 0:
            ax.set_ylabel("apparent friction μa")
        ax.legend(fontsize="small")
    png = args.png or args.out / "fig9.png"
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
