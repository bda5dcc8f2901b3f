#!/usr/bin/env bash
# Issue #15's grid-convergence table: μa of configs/paper-1c-patterns.toml
# (Cu, 7.68 mm domain, coupled) at cell sizes 30 / 20 / 15 / 10 µm, with the
# sub-cell hull radii (mu_a with solver.radii=hull, set below: the table of
# issue #15) beside the paper's whole-cell radii (mu_a_cells). Prints a
# Markdown table. Usage: bench/convergence-table.sh [OUT]
# RADII=moments bench/convergence-table.sh [OUT]: the sub-cell row with the
# apparent radii from second moments (solver.radii, issue #34; the default
# since issue #47) instead of the hull.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/convergence-table}
cargo build --release -q
rm -rf "$out"
for grid in 256:30 384:20 512:15 768:10; do
  n=${grid%%:*}; h=${grid##*:}
  ./target/release/mpcontact run configs/paper-1c-patterns.toml --quiet --workers 2 \
    --set grid.points="$n" --set grid.spacing_um="$h" --set sweep.angles_deg="[0.0, 45.0]" \
    --set solver.radii="${RADII:-hull}" \
    --out "$out/$h"
done
python3 - "$out" "${RADII:-hull}" <<'PY'
import csv, sys
out, radii = sys.argv[1], sys.argv[2]
sizes = ["30", "20", "15", "10"]
rows = {}
for h in sizes:
    for r in csv.DictReader(open(f"{out}/{h}/results.csv")):
        rows[(r["surface"], r["angle_deg"], h)] = r
points = [("circle-A", "0"), ("square-A", "0"), ("circle-B", "45"), ("square-B", "45"), ("flat", "0")]
print("| surface, angle | definition | " + " | ".join(f"{h} µm" for h in sizes) + " |")
print("|---|---|" + "---|" * len(sizes))
for s, a in points:
    for col, name in [("mu_a_cells", "cells (paper)"), ("mu_a", "sub-cell" if radii == "hull" else radii)]:
        vals = [rows.get((s, a, h), {}).get(col) or "" for h in sizes]
        print(f"| {s}, {a}° | {name} | " + " | ".join(f"{float(v):.4f}" if v else "–" for v in vals) + " |")
PY
