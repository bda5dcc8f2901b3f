#!/usr/bin/env bash
# Side-by-side benchmark of mpcontact against the established contact solvers
# on PyPI (tamaas 2.9.0, contactmechanics 1.8.3, aspher 0.1.3.post1) on the
# paper's Table 1a problem: Hertz normal contact at N×N for N in $SIZES and
# partial slip, with OMP_NUM_THREADS=1 and 2; then mpcontact's FFT floor and
# the paper sweep with 1 and 2 workers. Prints markdown tables (also written to
# $OUT/report.md); every result line is kept in $OUT/compare.jsonl.
#
# Usage: bench/compare.sh [OUT_DIR]        (default: a fresh mktemp directory)
# Environment:
#   SIZES=256,512,1024   grid sizes of the Hertz runs
#   REPS=3               timed repetitions (the median is reported)
#   SKIP_SWEEP=1         skip the paper sweep (d)
#   SKIP_PEERS=1         skip the peers (and their installation)
#   OURS=...             command for mpcontact's side (default: the compare_hertz
#                        example, built here); gets --sizes --reps --threads
#   PEER_TOL_PRESET=matched|nominal   peers' tolerances (see hertz_peers.py)
#   PEER_TIMEOUT=SECONDS  per peer mode × size in the Hertz runs (default none);
#                        a mode that exceeds it is not run at the larger sizes
#   REPS_ONE_FROM=N      sizes from N on are solved once (ours and the peers)
#   HEADLINE_FROM=N      sizes from N on run only the fastest mode of each solver
#                        (ours: nested + preconditioned; aspher: nested-fft-precond)
# Round 2 of the performance work (docs/performance.md) ran
#   SIZES=256,512,1024,2048,4096 REPS_ONE_FROM=1024 HEADLINE_FROM=2048 \
#   PEER_TIMEOUT=120 SKIP_SWEEP=1 bench/compare.sh
# Peers are installed in bench/.venv (created if missing; aspher builds from
# source, about 4 minutes, and needs Debian's libeigen3-dev).
# Rough cost with the defaults: peers ~25 min (contactmechanics and tamaas take
# 1–1.5 min per solve at 1024²), plus the sweep.
set -euo pipefail
cd "$(dirname "$0")/.."

OUT=${1:-$(mktemp -d /tmp/mpcontact-compare.XXXXXX)}
mkdir -p "$OUT"
SIZES=${SIZES:-256,512,1024}
REPS=${REPS:-3}
SKIP_SWEEP=${SKIP_SWEEP:-0}
SKIP_PEERS=${SKIP_PEERS:-0}
PEER_TOL_PRESET=${PEER_TOL_PRESET:-matched}
PEER_TIMEOUT=${PEER_TIMEOUT:-}
REPS_ONE_FROM=${REPS_ONE_FROM:-}
HEADLINE_FROM=${HEADLINE_FROM:-}
SIZE_ARGS=(${REPS_ONE_FROM:+--reps-one-from "$REPS_ONE_FROM"} ${HEADLINE_FROM:+--headline-from "$HEADLINE_FROM"})
VENV=bench/.venv
PY=$VENV/bin/python
JSONL=$OUT/compare.jsonl
: > "$JSONL"

echo "commit $(git rev-parse --short HEAD), $(date '+%Y-%m-%d %H:%M %Z'), out: $OUT" >&2

# ---------------------------------------------------------------- peers' venv
ensure_eigen() {
  if dpkg-query -W -f='${Status}' libeigen3-dev 2>/dev/null | grep -q "install ok installed"; then
    return 0
  fi
  echo "installing libeigen3-dev (aspher's build needs it)" >&2
  local sudo=()
  if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null; then sudo=(sudo); else
      echo "warning: not root and no sudo: cannot install libeigen3-dev; aspher's build will try to download Eigen" >&2
      return 0
    fi
  fi
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libeigen3-dev
}

# pip requirement → import check (version pinned where the benchmark needs it)
importable() {
  "$PY" - "$1" <<'PY' >/dev/null 2>&1
import importlib, importlib.metadata as md, sys
req = sys.argv[1]
name, _, ver = req.partition("==")
mod = {"contactmechanics": "ContactMechanics"}.get(name, name)
importlib.import_module(mod)
if ver and md.version(name) != ver:
    raise SystemExit(1)
PY
}

setup_peers() {
  [ -x "$PY" ] || python3 -m venv "$VENV"
  local need=() req
  for req in numpy scipy tamaas==2.9.0 contactmechanics==1.8.3 aspher==0.1.3.post1; do
    importable "$req" || need+=("$req")
  done
  if [ ${#need[@]} -eq 0 ]; then
    return 0
  fi
  case " ${need[*]} " in *" aspher=="*) ensure_eigen ;; esac
  echo "pip install ${need[*]} (into $VENV)" >&2
  "$PY" -m pip install -q "${need[@]}"
}

# ------------------------------------------------------------------ our side
if [ -z "${OURS:-}" ]; then
  cargo build --release -q -p mpcontact-solver --example compare_hertz
  OURS=target/release/examples/compare_hertz
fi
read -r -a OURS_CMD <<< "$OURS"
if [ "$SKIP_SWEEP" != 1 ]; then
  cargo build --release -q -p mpcontact
fi
if [ "$SKIP_PEERS" != 1 ]; then
  setup_peers
fi

# Run a command, keep its JSON lines (adding "threads" where missing); a failing
# command leaves an "ok": false line instead of stopping the benchmark.
run_json() {
  local name=$1 threads=$2
  shift 2
  local raw="$OUT/raw-$name-t$threads.out" rc=0
  echo "== $name, $threads thread(s): $*" >&2
  "$@" > "$raw" || rc=$?
  python3 - "$raw" "$threads" "$name" "$rc" >> "$JSONL" <<'PY'
import json, sys
raw, threads, name, rc = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
for line in open(raw):
    line = line.strip()
    if not line.startswith("{"):
        continue
    try:
        obj = json.loads(line)
    except json.JSONDecodeError:
        continue
    obj.setdefault("threads", threads)
    print(json.dumps(obj))
if rc != 0:
    solver = "mpcontact" if name == "mpcontact" else name
    print(json.dumps({"solver": solver, "kind": "run", "threads": threads, "ok": False,
                      "error": f"{name} exited with code {rc} (output: {raw})"}))
PY
}

for T in 1 2; do
  (
    export OMP_NUM_THREADS=$T OPENBLAS_NUM_THREADS=$T MKL_NUM_THREADS=$T
    run_json mpcontact "$T" "${OURS_CMD[@]}" --sizes "$SIZES" --reps "$REPS" --threads "$T" "${SIZE_ARGS[@]}"
    if [ "$SKIP_PEERS" != 1 ]; then
      run_json hertz-peers "$T" "$PY" bench/peers/hertz_peers.py --peers tamaas,contactmechanics,aspher \
        --sizes "$SIZES" --reps "$REPS" --tol-preset "$PEER_TOL_PRESET" ${PEER_TIMEOUT:+--timeout "$PEER_TIMEOUT"} \
        "${SIZE_ARGS[@]}"
      run_json slip-peers "$T" "$PY" bench/peers/slip_peers.py --peers aspher,tamaas
    fi
  )
done

SWEEP_ARGS=()
if [ "$SKIP_SWEEP" != 1 ]; then
  for W in 1 2; do
    rm -rf "$OUT/sweep-$W"
    echo "== paper sweep, $W worker(s)" >&2
    target/release/mpcontact run configs/paper-1c-sweep.toml --workers "$W" --out "$OUT/sweep-$W" --quiet
  done
  SWEEP_ARGS=(--sweep-dir "$OUT")
fi

python3 bench/peers/report.py "$JSONL" "${SWEEP_ARGS[@]}" | tee "$OUT/report.md"
