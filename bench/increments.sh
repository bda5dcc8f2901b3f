#!/usr/bin/env bash
# Energy per cycle against the increments (issue #60): Table 1(a) Fe
# (configs/fretting-fe.toml, ±0.6 μP, 2 cycles) at fixed increments per
# segment and at "auto", uncoupled and coupled, no sampled loop; each
# against the 80-increment value and (uncoupled) against Mindlin–
# Deresiewicz's closed form 6.6945e-8 J; the solve's seconds and the
# increments each segment took. Prints a markdown table.
#
# Usage: bench/increments.sh [POINTS:SPACING_UM] [STEPS]   (defaults 256:1 and "1 2 5 20 80 auto")
#        MPCONTACT_EXE=/path/to/mpcontact bench/increments.sh
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
grid=${1:-256:1}
steps=${2:-"1 2 5 20 80 auto"}
n=${grid%%:*}; h=${grid##*:}

# run COUPLING STEPS: "energy|seconds|increments" of the case.
run() {
  local value=$2
  [ "$2" = auto ] && value='"auto"'
  $exe solve configs/fretting-fe.toml --set grid.points="$n" --set grid.spacing_um="$h" \
    --set solver.coupling="$1" --set history.steps_per_segment="$value" \
    --set history.loop_increments=0 --out "$tmp/c" > /dev/null
  python3 -c '
import json, sys
d = json.load(open(sys.argv[1])); h = d["history"]
inc = h["increments_per_segment"]; rej = h.get("auto_rejected")
text = f"{sum(inc)} ({chr(44).join(map(str, inc))}" + (f"; {rej} turned down)" if rej is not None else ")")
e, sec = h["dissipated_energy_per_cycle_j"], d["seconds"]
print(f"{e:.6e}|{sec:.2f}|{text}")
' "$tmp/c/case.json"
}

echo "| coupling | increments per segment | energy per cycle J | vs 80 | vs Mindlin–Deresiewicz | solve s | increments (per segment) |"
echo "|---|---|---|---|---|---|---|"
for coupling in false true; do
  ref=$(run "$coupling" 80)
  e80=${ref%%|*}
  for s in $steps; do
    if [ "$s" = 80 ]; then line=$ref; else line=$(run "$coupling" "$s"); fi
    IFS='|' read -r e sec inc <<< "$line"
    python3 -c "
e, e80, c = $e, $e80, '$coupling'
md = f'{e / 6.6945e-8 - 1:+.2%}' if c == 'false' else '—'
print(f'| {c} | $s | {e:.5e} | {e / e80 - 1:+.1e} | {md} | $sec | $inc |')"
  done
done
