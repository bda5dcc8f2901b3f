#!/usr/bin/env bash
# Cost of a fretting cycle against one monotonic solve (issues #16, #60):
# Table 1(a) Fe (configs/fretting-fe.toml, ±0.6 μP at P = 20 N) against
# `mpcontact solve configs/paper-1a-fe.toml` (one monotonic step to 0.6 μP)
# on the same grid, coupled and uncoupled. The cycle's cost is the marginal
# one: the solve of 1 + MORE cycles minus that of 1 cycle, over MORE
# (MORE=2 by default) — the first
# loading, the kernel and the last cycle (sampled for its loop at
# `history.loop_increments`) cancel, so it is what every further cycle of
# a long history costs. Solve seconds from case.json (kernel excluded), the
# increments of the two marginal cycles, and the energy per cycle. Prints
# a markdown table.
#
# Usage: bench/fretting.sh [SIZES]   (default "256:1 512:0.5", points:spacing_um)
#        MPCONTACT_EXE=/path/to/mpcontact bench/fretting.sh [SIZES]
#        STEPS=20 bench/fretting.sh     (history.steps_per_segment; default
#                                        the config's, "auto" since #60; main
#                                        before #60 needs STEPS=20)
#        COUPLING="true" bench/fretting.sh   (the couplings to run; default "true false")
#        MORE=1 bench/fretting.sh       (the further cycles timed; default 2)
#        METHOD=active-set bench/fretting.sh [SIZES]   (solver.tangential_method; default cg)
#        THREADS=1 bench/fretting.sh [SIZES]   (solve's --threads; default all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
sizes=${1:-"256:1 512:0.5"}
couplings=${COUPLING:-"true false"}
more=${MORE:-2}
last=$((1 + more))
increments() {
  python3 -c "
import json, sys
h = json.load(open(sys.argv[1]))['history']
print(h.get('increments_per_segment') and sum(h['increments_per_segment']) or len(h['steps']))" "$1"
}
echo "| grid | coupling | monotonic solve s | 1 cycle s | $last cycles s | a further cycle s | its increments | cycle / monotonic | energy per cycle J |"
echo "|---|---|---|---|---|---|---|---|---|"
for s in $sizes; do
  n=${s%%:*}; h=${s##*:}
  for coupling in $couplings; do
    set_args=(--set grid.points=$n --set grid.spacing_um=$h --set solver.coupling=$coupling ${THREADS:+--threads $THREADS} ${METHOD:+--set solver.tangential_method=\"$METHOD\"})
    steps=()
    [ -n "${STEPS:-}" ] && steps=(--set history.steps_per_segment=$STEPS)
    $exe solve configs/paper-1a-fe.toml "${set_args[@]}" --out "$tmp/m" > /dev/null
    $exe solve configs/fretting-fe.toml "${set_args[@]}" "${steps[@]}" --set history.fretting.cycles=1 --out "$tmp/f1" > /dev/null
    $exe solve configs/fretting-fe.toml "${set_args[@]}" "${steps[@]}" --set history.fretting.cycles=$last --out "$tmp/f3" > /dev/null
    ms=$(field "$tmp/m/case.json" seconds)
    f1=$(field "$tmp/f1/case.json" seconds); f3=$(field "$tmp/f3/case.json" seconds)
    i1=$(increments "$tmp/f1/case.json"); i3=$(increments "$tmp/f3/case.json")
    fw=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['history']['dissipated_energy_per_cycle_j'])" "$tmp/f3/case.json")
    python3 -c "
ms, f1, f3 = $ms, $f1, $f3
cycle = (f3 - f1) / $more
print(f'| {$n}² | $coupling | {ms:.2f} | {f1:.1f} | {f3:.1f} | {cycle:.2f} | {($i3 - $i1) / $more:g} | {cycle / ms:.1f}× | {$fw:.6e} |')"
  done
done
