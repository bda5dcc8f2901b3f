#!/usr/bin/env bash
# Cost of a fretting-wear run (issue #49): configs/fretting-wear.toml —
# Table 1(a) Fe, ±0.6 μP (partial slip), Archard wear, 10⁴ physical cycles
# simulated as CYCLES (default 100: a jump of 100, 100 wear updates), 10
# increments per segment, 256² of 1.25 µm — against one monotonic solve of
# the same case (0 → 0.6 μP in one step), with coupling off (the config's)
# and on. Also the same path without wear, to show what the wear's extra
# normal solve per increment costs. Wall seconds of the whole command (the
# kernel build included) and the solve's seconds from case.json. Prints a
# markdown table.
#
# Usage: bench/wear.sh [CYCLES] [COUPLED_CYCLES]   (defaults 100 and 10)
#        MPCONTACT_EXE=/path/to/mpcontact bench/wear.sh
#        THREADS=1 bench/wear.sh   (solve's --threads; default all cores)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
cycles=${1:-100}
coupled_cycles=${2:-10}
cfg=configs/fretting-wear.toml
echo "| coupling | path | simulated cycles | wall s | solve s | per simulated cycle s | monotonic solve s | cycle / monotonic | converged |"
echo "|---|---|---|---|---|---|---|---|---|"
for coupling in false true; do
  n=$cycles
  [ "$coupling" = true ] && n=$coupled_cycles
  common=(--set solver.coupling=$coupling ${THREADS:+--threads $THREADS})
  # The monotonic solve: no history, 0.6 μP in one step.
  sed '/^\[history\]/,$d' $cfg > "$tmp/mono.toml"
  $exe solve "$tmp/mono.toml" "${common[@]}" --set load.tangential_ratio=0.6 --out "$tmp/m" > /dev/null
  ms=$(field "$tmp/m/case.json" seconds)
  for wear in with without; do
    src=$cfg
    if [ $wear = without ]; then
      grep -v '^wear = ' $cfg > "$tmp/nowear.toml"
      src="$tmp/nowear.toml"
    fi
    set_args=("${common[@]}" --set history.fretting.cycles=$n)
    [ $wear = with ] && set_args+=(--set history.wear.physical_cycles=1e4)
    start=$(date +%s.%N)
    $exe solve "$src" "${set_args[@]}" --out "$tmp/f" --quiet > /dev/null 2>&1
    end=$(date +%s.%N)
    fs=$(field "$tmp/f/case.json" seconds); fc=$(field "$tmp/f/case.json" converged)
    python3 -c "
wall=$end-$start; fs=$fs; ms=$ms; n=$n
# The first loading is half a cycle's increments: n cycles + 1/2.
per=fs/(n+0.5)
print(f'| $coupling | $wear wear | {n} | {wall:.1f} | {fs:.1f} | {per:.2f} | {ms:.2f} | {per/ms:.1f}× | $fc |')"
  done
done
