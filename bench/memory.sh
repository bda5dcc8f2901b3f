#!/usr/bin/env bash
# Peak resident memory of a sweep worker solving one 512² case (paper Table 1a,
# coupled partial slip, no fields shipped), compared with what it must hold:
# the nine kernel half spectra of the 2N x 2N padded grid plus the nine N x N
# result fields (the reference of the performance issue), and with the spectra
# as the operator stores them (three real + three complex half spectra, by
# reciprocity). Usage: bench/memory.sh [CONFIG] (default configs/paper-1a-fe.toml)
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-configs/paper-1a-fe.toml}
cargo build --release -q -p mpcontact
out=$(mktemp -d /tmp/mpcontact-mem.XXXXXX)
target/release/mpcontact run "$config" --workers 1 --out "$out/run" --quiet &
run=$!
peak=0
while kill -0 "$run" 2>/dev/null; do
  for pid in $(pgrep -f "mpcontact worker" || true); do
    kb=$(awk '/VmHWM/ {print $2}' "/proc/$pid/status" 2>/dev/null || echo 0)
    [ -n "$kb" ] && [ "$kb" -gt "$peak" ] && peak=$kb
  done
  sleep 0.1
done
wait "$run"
n=$(python3 -c "import tomllib,sys; print(tomllib.load(open('$config','rb'))['grid']['points'])")
python3 - "$peak" "$n" <<'PY'
import sys
peak_kb, n = int(sys.argv[1]), int(sys.argv[2])
m = 2 * n
spectra = 9 * m * (m // 2 + 1) * 16
fields = 9 * n * n * 8
need = spectra + fields
stored = 3 * m * (m // 2 + 1) * (8 + 16)
print(f"| grid | worker peak RSS (MB) | nine spectra (MB) | stored spectra (MB) | fields (MB) | peak / (nine spectra + fields) | peak / (stored spectra + fields) |")
print(f"|---|---|---|---|---|---|---|")
print(f"| {n}² | {peak_kb/1024:.1f} | {spectra/2**20:.1f} | {stored/2**20:.1f} | {fields/2**20:.1f} | {peak_kb*1024/need:.2f} | {peak_kb*1024/(stored+fields):.2f} |")
PY
