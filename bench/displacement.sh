#!/usr/bin/env bash
# Displacement control against force control (issue #60): Table 1(a) Fe
# (configs/fretting-fe.toml), 2 fretting cycles under an imposed shift
# amplitude Δ (`history.fretting.displacement_um`), beside the force-
# controlled path with the same loop: amplitude ratio F*/μP of the
# displacement-controlled run (capped at 0.98 in gross slip, where force
# control refuses μP). Solve seconds from case.json (kernel excluded), CPU
# seconds of the process (or, CALLGRIND=1, its instructions), tangential
# iterations, energy per cycle. Prints a
# markdown table.
#
# Usage: bench/displacement.sh [SIZES] [AMPLITUDES_UM] [STEPS]
#          (defaults "128:2 256:1", "0.02 0.05 0.2 0.4", "10 1": points:spacing_um,
#           Δ in µm, increments per segment)
#        COUPLING="false true" (default both)
#        THREADS=1 MPCONTACT_EXE=/path/to/mpcontact bench/displacement.sh
#        CALLGRIND=1 (valgrind's instruction count of the process instead of
#          its CPU seconds)
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/solve-common.sh
sizes=${1:-"128:2 256:1"}
amplitudes=${2:-"0.02 0.05 0.2 0.4"}
steps_list=${3:-"10 1"}
couplings=${COUPLING:-"false true"}
# Solves CONFIG ARGS... into $tmp/$1 and prints "solve_s cpu_s"; with
# CALLGRIND=1 under callgrind, and "cpu_s" is then the process's
# instructions, in 1e9.
run() {
  local out=$1; shift
  local cpu
  if [ -n "${CALLGRIND:-}" ]; then
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$exe" solve configs/fretting-fe.toml "$@" --out "$tmp/$out" > /dev/null 2>&1
    # The whole process: callgrind's per-function lines split a function
    # over the files its inlined code comes from (and the force path's first
    # solve goes through `solve_nested_taking`), so their sums are not the
    # solves' cost; the kernel build and outputs are the same for both runs.
    cpu=$(callgrind_annotate "$tmp/cg.out" 2>/dev/null \
      | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); printf "%.3f", $1 / 1e9}')
  else
    cpu=$( { TIMEFORMAT=%U; time "$exe" solve configs/fretting-fe.toml "$@" --out "$tmp/$out" > /dev/null; } 2>&1 )
  fi
  echo "$(field "$tmp/$out/case.json" seconds) $cpu"
}
hist() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['history'][sys.argv[2]])" "$1" "$2"; }
cost=${CALLGRIND:+process Gi}
cost=${cost:-CPU s}
echo "| grid | coupling | steps | Δ µm | regime | F*/μP | displacement: its (t) | solve s | $cost | force: its (t) | solve s | $cost | its ratio | $cost ratio | energy per cycle J |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for s in $sizes; do
  n=${s%%:*}; h=${s##*:}
  for coupling in $couplings; do
    for steps in $steps_list; do
      for amp in $amplitudes; do
        args=(--set grid.points=$n --set grid.spacing_um=$h --set solver.coupling=$coupling
          --set history.steps_per_segment=$steps ${THREADS:+--threads $THREADS})
        read -r ds dc < <(run d "${args[@]}" --set "history.fretting={ displacement_um = $amp, cycles = 2 }")
        fstar=$(hist "$tmp/d/case.json" force_amplitude_n)
        ratio=$(python3 -c "print(min($fstar / (0.28571 * 20.0), 0.98))")
        read -r fs fc < <(run f "${args[@]}" --set "history.fretting={ amplitude_ratio = $ratio, cycles = 2 }")
        di=$(field "$tmp/d/case.json" tangential_iterations); fi_=$(field "$tmp/f/case.json" tangential_iterations)
        dok=$(field "$tmp/d/case.json" converged)
        regime=$(hist "$tmp/d/case.json" regime); w=$(hist "$tmp/d/case.json" dissipated_energy_per_cycle_j)
        python3 -c "
print(f'| {$n}² | $coupling | $steps | $amp | $regime{\"\" if \"$dok\" == \"True\" else \" (not converged)\"} | {$ratio:.4f} | $di | {$ds:.2f} | {$dc:.2f} | $fi_ | {$fs:.2f} | {$fc:.2f} | {$di/$fi_:.2f} | {$dc/$fc:.2f} | {$w:.6e} |')"
      done
    done
  done
done
