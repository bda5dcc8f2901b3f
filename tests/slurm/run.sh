#!/usr/bin/env bash
# A sharded sweep on a real one-node Slurm (issue #18): installs Debian's
# slurm-wlm and munge, starts munged, slurmctld and slurmd on loopback as
# plain background daemons, runs configs/quick.toml as a 3-task job array
# plus a dependent merge job, and compares the merged outputs with a single
# run of the same config. Then cancels one array task mid-run, shows the
# merge does not run, resubmits the array (finished shards return at once,
# the cancelled one resumes) and merges again. Stops every daemon it started.
# Needs root (CI runs as root). Fails loudly when Slurm cannot start.
#
# `tests/slurm/run.sh bench` instead times configs/paper-1c-sweep.toml as
# 1, 2 and 4 shards under the same Slurm (docs/performance.md).
set -euo pipefail
mode=${1:-test}
cd "$(dirname "$0")/../.."
root=$(pwd)

say() { printf 'slurm test: %s\n' "$*"; }
die() { say "FAILED: $*"; exit 1; }

if [ "$(id -u)" != 0 ]; then die "needs root (to install and start Slurm)"; fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  say "installing slurm-wlm and munge"
  apt-get update -qq >/dev/null
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi

cargo build --release -q -p mpcontact
bin="$root/target/release/mpcontact"
work=$(mktemp -d /tmp/mpcontact-slurm.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

# munge: its key comes with the package; the daemon runs as the munge user.
mkdir -p /run/munge /var/log/munge /var/lib/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge
[ -s /etc/munge/munge.key ] || die "no /etc/munge/munge.key after installing munge"
runuser -u munge -- /usr/sbin/munged --foreground --force >"$work/munged.log" 2>&1 &
pids+=($!)
for _ in $(seq 1 50); do munge -n >/dev/null 2>&1 && break; sleep 0.1; done
munge -n | unmunge >/dev/null || die "munged did not start"

host=$(cat /proc/sys/kernel/hostname)
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
export SLURM_CONF="$work/slurm.conf"
mkdir -p "$work/state" "$work/spool" "$work/jobs"
cat >"$SLURM_CONF" <<EOF
ClusterName=mpcontact-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MpiDefault=none
ReturnToService=2
SlurmctldPort=6817
SlurmdPort=6818
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -f "$SLURM_CONF" >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/slurmd.out" 2>&1 &
pids+=($!)
up=
for _ in $(seq 1 100); do
  if sinfo -h -o %T 2>/dev/null | grep -q idle; then up=1; break; fi
  sleep 0.2
done
if [ -z "$up" ]; then
  tail -20 "$work"/slurm*.log "$work"/*.out || true
  die "Slurm did not come up (no idle node in 20 s)"
fi
say "Slurm up: $(sinfo -h -o '%P %D %T %c')"

# Waits for the jobs given to leave the queue (deadline $1 s).
wait_jobs() {
  local deadline=$1; shift
  local t=0
  while [ "$t" -lt "$deadline" ]; do
    if [ -z "$(squeue -h -j "$(IFS=,; echo "$*")" 2>/dev/null)" ]; then return 0; fi
    sleep 1; t=$((t + 1))
  done
  squeue; die "jobs $* still queued after $deadline s"
}

submit_array() { # OUT, extra run args...
  local out=$1; shift
  MPCONTACT="$bin" sbatch --parsable --chdir="$work/jobs" --export=ALL --array=0-2 \
    configs/slurm/sweep.sbatch "$root/configs/quick.toml" "$out" "$@"
}
submit_merge() { # JOBID, OUT
  MPCONTACT="$bin" sbatch --parsable --chdir="$work/jobs" --export=ALL \
    --dependency=afterok:"$1" configs/slurm/merge.sbatch "$2"
}

# Compared with a single run: curves.csv and both plots byte for byte,
# results.csv without its seconds and worker columns (17 and 18).
compare() { # MERGED SINGLE
  for f in curves.csv mu_a_vs_angle.svg mu_a_vs_angle.png; do
    cmp -s "$1/$f" "$2/$f" || die "$f of the merged run differs from the single run"
  done
  diff <(cut -d, -f1-16 "$1/results.csv") <(cut -d, -f1-16 "$2/results.csv") >/dev/null \
    || die "results.csv of the merged run differs from the single run"
}

if [ "$mode" = bench ]; then
  paper="$root/configs/paper-1c-sweep.toml"
  for n in 1 2 4; do
    t0=$(date +%s.%N)
    array=$(MPCONTACT="$bin" sbatch --parsable --chdir="$work/jobs" --export=ALL \
      --array=0-$((n - 1)) configs/slurm/sweep.sbatch "$paper" "$work/p$n")
    merge=$(submit_merge "$array" "$work/p$n")
    wait_jobs 3600 "$array" "$merge"
    t1=$(date +%s.%N)
    cases=$(awk -F, 'NR > 1 {s += $17} END {printf "%.1f", s}' "$work/p$n/results.csv")
    say "paper sweep as $n shard(s): wall $(awk "BEGIN {printf \"%.1f\", $t1 - $t0}") s, sum of case seconds $cases s"
  done
  exit 0
fi

say "single run for reference"
"$bin" run configs/quick.toml --workers 2 --out "$work/single" --quiet

say "3-task array + merge"
t0=$(date +%s)
array=$(submit_array "$work/a")
merge=$(submit_merge "$array" "$work/a")
wait_jobs 600 "$array" "$merge"
[ -f "$work/a/curves.csv" ] || { cat "$work"/jobs/*.log; die "the merge wrote no curves.csv"; }
compare "$work/a" "$work/single"
say "merged = single run ($(($(wc -l <"$work/a/results.csv") - 1)) cases, $(($(date +%s) - t0)) s)"

say "cancel one task mid-run, then resubmit"
# Finer grid: shards take long enough to be cancelled mid-way.
slow=(--set grid.points=256 --set grid.spacing_um=30)
"$bin" run configs/quick.toml --workers 2 --out "$work/single-slow" --quiet "${slow[@]}"
array=$(submit_array "$work/b" "${slow[@]}")
merge=$(submit_merge "$array" "$work/b")
journal="$work/b/shard-1/journal.jsonl"
for _ in $(seq 1 600); do
  [ -f "$journal" ] && [ "$(wc -l <"$journal")" -ge 3 ] && break
  sleep 0.2
done
[ -f "$journal" ] || die "shard 1 never started"
scancel "${array}_1"
done_before=$(($(wc -l <"$journal") - 1))
wait_jobs 600 "$array"
sleep 2
state=$(squeue -h -j "$merge" -o %r 2>/dev/null || true)
[ ! -f "$work/b/curves.csv" ] || die "the merge ran although shard 1 was cancelled"
scancel "$merge" 2>/dev/null || true
say "shard 1 cancelled after $done_before cases; merge held ($state)"
array=$(submit_array "$work/b" "${slow[@]}")
merge=$(submit_merge "$array" "$work/b")
wait_jobs 900 "$array" "$merge"
[ -f "$work/b/curves.csv" ] || { cat "$work"/jobs/*.log; die "the merge after resubmitting wrote nothing"; }
compare "$work/b" "$work/single-slow"
say "resubmitted array resumed shard 1 and the merge equals the single run"
say "passed"
