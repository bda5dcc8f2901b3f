#!/usr/bin/env bash
# Tangential iterations per monotonic solve and per history increment on
# Table 1(a) Fe (configs/paper-1a-fe.toml, F = 0.6 μP) at several grids of the
# same cell-per-contact scaling (issue #36). The history is the first loading
# 0 → 0.6 μP in STEPS increments (default 5), so an increment there is
# 0.12 μP; fine iterations after the coarse-to-fine start for the monotonic
# solve, all of an increment's coupling passes for the history. Iteration
# counts do not depend on the thread count (results are identical to the
# bit on any), so THREADS only sets the time. Prints a markdown table.
#
# Usage: bench/iterations.sh [SIZES]   (default "512:0.5 1024:0.25 2048:0.125")
#        METHOD=active-set (solver.tangential_method; default cg)
#        STEPS=5 THREADS=2 MPCONTACT_EXE=/path/to/mpcontact bench/iterations.sh
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
sizes=${1:-"512:0.5 1024:0.25 2048:0.125"}
steps=${STEPS:-5}
echo "| grid | coupling | monotonic s | its (t) per monotonic solve | coupling passes | history s ($steps increments) | its (t) per increment | passes per increment | converged |"
echo "|---|---|---|---|---|---|---|---|---|"
for s in $sizes; do
  n=${s%%:*}; h=${s##*:}
  for coupling in true false; do
    args=(--set grid.points=$n --set grid.spacing_um=$h --set solver.coupling=$coupling ${THREADS:+--threads $THREADS} ${METHOD:+--set solver.tangential_method=\"$METHOD\"})
    $exe solve configs/paper-1a-fe.toml "${args[@]}" --out "$tmp/m" > /dev/null
    $exe solve configs/paper-1a-fe.toml "${args[@]}" --set 'history.tangential_ratios=[0.0, 0.6]' \
      --set history.steps_per_segment=$steps --out "$tmp/h" > /dev/null
    ms=$(field "$tmp/m/case.json" seconds); mi=$(field "$tmp/m/case.json" tangential_iterations)
    mc=$(field "$tmp/m/case.json" coupling_iterations)
    hs=$(field "$tmp/h/case.json" seconds); hi=$(field "$tmp/h/case.json" tangential_iterations)
    hc=$(field "$tmp/h/case.json" coupling_iterations); ok=$(field "$tmp/h/case.json" converged)
    python3 -c "print(f'| {$n}² | $coupling | {$ms:.1f} | $mi | $mc | {$hs:.1f} | {$hi/$steps:.1f} | {$hc/$steps:.1f} | $ok |')"
  done
done
