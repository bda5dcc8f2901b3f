#!/usr/bin/env bash
# Sweep-runner benchmark: cases per minute of the quick sweep with 1 and 2
# workers, the speed-up, and the IPC cost per case (worker result ready →
# coordinator recorded) for cases that ship their fields at 256² and 512².
# Prints a markdown table. Usage: bench/sweep.sh [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-$(mktemp -d /tmp/mpcontact-bench.XXXXXX)}
cargo build --release -q -p mpcontact
bin=target/release/mpcontact

for w in 1 2; do
  rm -rf "$out/quick-$w"
  "$bin" run configs/quick.toml --workers "$w" --out "$out/quick-$w" --quiet
done
# Fields travel in shared memory only when saved: a small normal-contact sweep per grid.
for n in 256 512; do
  rm -rf "$out/ipc-$n"
  "$bin" run configs/quick.toml --workers 2 --out "$out/ipc-$n" --quiet --save-fields \
    --set grid.points="$n" --set grid.spacing_um=$(python3 -c "print(60.0*128/$n)") \
    --set 'sweep.materials=["Cu"]' --set 'sweep.surfaces=["flat"]' \
    --set 'sweep.angles_deg=[0.0, 90.0]' --set load.tangential_ratio=0
done

python3 - "$out" <<'PY'
import json, sys, subprocess
out = sys.argv[1]
s1 = json.load(open(f"{out}/quick-1/summary.json"))
s2 = json.load(open(f"{out}/quick-2/summary.json"))
rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
print(f"commit {rev}; quick sweep = {s1['total']} cases (configs/quick.toml)\n")
print("| workers | wall (s) | cases/min | speed-up |")
print("|---|---|---|---|")
for s in (s1, s2):
    print(f"| {s['workers']} | {s['wall_seconds']:.1f} | {s['cases_per_minute']:.1f} | {s1['wall_seconds']/s['wall_seconds']:.2f} |")
print("\n| grid | payload | cases | IPC median (ms) | IPC max (ms) | transfer median (ms) |")
print("|---|---|---|---|---|---|")
for n in (256, 512):
    s = json.load(open(f"{out}/ipc-{n}/summary.json"))
    for r in s["ipc"]:
        print(f"| {r['grid_n']}² | {r['payload_bytes']/1e6:.1f} MB | {r['count']} | {r['median_ms']:.1f} | {r['max_ms']:.1f} | {r['median_transfer_ms']:.2f} |")
PY
