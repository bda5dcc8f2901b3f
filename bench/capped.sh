#!/usr/bin/env bash
# What a hardness costs (issue #50): the paper's Table 1(c) sweep
# (configs/paper-1c-patterns.toml: Cu, five surfaces, F = 0.6 μP along x,
# coupled) on 512² of 30 µm with 2 workers, elastic and with
# `materials.Cu.hardness_gpa` = 0.9 and 0.5, ROUNDS rounds (default 4), each
# round the three sweeps in turn (with BASE set, the same three of that
# binary first: alternating runs against main). Per case the fastest round's
# solve seconds (results.csv, kernel excluded), its ratio to the same
# binary's elastic case, the iterations (normal / tangential) and the sums.
# Prints markdown tables.
#
# Usage: bench/capped.sh
#        BASE=/path/to/main/mpcontact ROUNDS=2 bench/capped.sh
#        MPCONTACT_EXE=/path/to/mpcontact bench/capped.sh
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
rounds=${ROUNDS:-4}
bins=("$exe")
[ -n "${BASE:-}" ] && bins=("$BASE" "$exe")
for r in $(seq 1 "$rounds"); do
  for b in "${!bins[@]}"; do
    for h in elastic 0.9 0.5; do
      extra=()
      [ "$h" != elastic ] && extra=(--set "materials.Cu.hardness_gpa=$h")
      "${bins[$b]}" run configs/paper-1c-patterns.toml --set grid.points=512 \
        --set grid.spacing_um=30 "${extra[@]}" --workers 2 --quiet \
        --out "$tmp/b$b-$h-$r" > /dev/null
    done
  done
done
python3 - "$tmp" "$rounds" "${#bins[@]}" <<'EOF'
import csv, sys
tmp, rounds, nbins = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
names = ["base", "this"] if nbins == 2 else ["this"]
for b, name in enumerate(names):
    runs = {}
    for h in ["elastic", "0.9", "0.5"]:
        runs[h] = [{r["surface"]: r for r in csv.DictReader(open(f"{tmp}/b{b}-{h}-{k}/results.csv"))}
                   for k in range(1, rounds + 1)]
    fast = {h: {s: min(float(x[s]["seconds"]) for x in rs) for s in rs[0]} for h, rs in runs.items()}
    print(f"\n{name}: fastest of {rounds} rounds, seconds (÷ elastic), normal / tangential iterations\n")
    print("| surface | elastic | H = 0.9 GPa | H = 0.5 GPa |")
    print("|---|---|---|---|")
    for s in fast["elastic"]:
        cells = []
        for h in ["elastic", "0.9", "0.5"]:
            r = runs[h][0][s]
            its = f"{r['normal_iterations']} / {r['tangential_iterations']}"
            ratio = "" if h == "elastic" else f" ({fast[h][s] / fast['elastic'][s]:.2f}×)"
            cells.append(f"{fast[h][s]:.2f} s{ratio}, {its}")
        print(f"| {s} | " + " | ".join(cells) + " |")
    tot = {h: sum(v.values()) for h, v in fast.items()}
    print(f"| sum | {tot['elastic']:.2f} s | {tot['0.9']:.2f} s ({tot['0.9'] / tot['elastic']:.2f}×) | "
          f"{tot['0.5']:.2f} s ({tot['0.5'] / tot['elastic']:.2f}×) |")
EOF
