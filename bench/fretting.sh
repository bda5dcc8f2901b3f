#!/usr/bin/env bash
# Cost of a load history against one monotonic solve (issue #16): Table 1(a)
# Fe (configs/fretting-fe.toml), first loading 0 → 0.6 μP then one full cycle
# (+0.6 → −0.6 → +0.6 μP), 20 increments per segment (60 in all, the cycle
# 40), against `mpcontact solve configs/paper-1a-fe.toml` (one monotonic step
# to 0.6 μP) on the same grid, coupled and uncoupled. Solve seconds from
# case.json (kernel excluded); whether every increment converged and the
# energy dissipated per cycle. Prints a markdown table.
#
# Usage: bench/fretting.sh [SIZES]   (default "256:1 512:0.5", points:spacing_um)
#        MPCONTACT_EXE=/path/to/mpcontact bench/fretting.sh [SIZES]
#        METHOD=active-set bench/fretting.sh [SIZES]   (solver.tangential_method; default cg)
#        THREADS=1 bench/fretting.sh [SIZES]   (solve's --threads; default all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
sizes=${1:-"256:1 512:0.5"}
echo "| grid | coupling | monotonic solve s | its (t) | history: 60 increments s | its (t) | per increment s | one cycle (40) s | cycle / monotonic | converged | energy per cycle J |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for s in $sizes; do
  n=${s%%:*}; h=${s##*:}
  for coupling in true false; do
    set_args=(--set grid.points=$n --set grid.spacing_um=$h --set solver.coupling=$coupling ${THREADS:+--threads $THREADS} ${METHOD:+--set solver.tangential_method=\"$METHOD\"})
    $exe solve configs/paper-1a-fe.toml "${set_args[@]}" --out "$tmp/m" > /dev/null
    $exe solve configs/fretting-fe.toml "${set_args[@]}" --set history.fretting.cycles=1 --out "$tmp/f" > /dev/null
    ms=$(field "$tmp/m/case.json" seconds); mi=$(field "$tmp/m/case.json" tangential_iterations)
    fs=$(field "$tmp/f/case.json" seconds); fi_=$(field "$tmp/f/case.json" tangential_iterations)
    fc=$(field "$tmp/f/case.json" converged)
    fw=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['history']['dissipated_energy_per_cycle_j'])" "$tmp/f/case.json")
    python3 -c "
ms,fs=$ms,$fs
inc=fs/60
print(f'| {$n}² | $coupling | {ms:.2f} | $mi | {fs:.1f} | $fi_ | {inc:.2f} | {40*inc:.1f} | {40*inc/ms:.1f}× | $fc | {$fw:.6e} |')"
  done
done
