#!/usr/bin/env bash
# mpcontact beside CONTACT (E.A.H. Vollebregt; the peer kit in ../shared/peers/contact) on
# Cattaneo–Mindlin in force increments: rigid sphere R = 18 mm on Fe (E = 210 GPa, ν = 0.3),
# P = 20 N, μ = 0.3, F from 0 to 0.6 μP in NINC increments, no normal–tangential coupling.
# Both codes solve the same discrete problem on the same cells: h = 2a/NCELLS (a the Hertz
# radius, 105.37 µm), a square of NCELLS + 2·MARGIN cells centred on the apex (CONTACT's
# potential contact; mpcontact's grid, whose contact window is used only when the contact spans
# at most 80 % of the side, i.e. from MARGIN ≥ NCELLS/8).
#
# usage: bench/contact.sh CONTACT_EXE [NCELLS ...]        (default NCELLS: 128 256)
#   CONTACT_EXE     CONTACT's program, e.g. ~/contact-peer/src/bin/contact_linux64 (built with
#                   ../shared/peers/contact/build.sh)
#   NCELLS          cells across the Hertz contact diameter, one or more
# environment:
#   MPCONTACT_EXE   our binary (default: target/release/mpcontact, built here with cargo)
#   CONTACT_KIT     folder with gen_catt.py (default: ../shared/peers/contact beside the repo)
#   REPS=3          timed runs of each code per size, alternating CONTACT, ours, CONTACT, ours …
#   WARMUP=1        untimed runs of each code per size first (page cache, libraries)
#   NINC=20         force increments; EPS=1e-6 CONTACT's tolerance (ours: its defaults,
#                   tangential KKT 1e-6)
#   MARGIN          cells beyond the Hertz diameter on each side (default NCELLS/16)
#   NICE=-5         niceness of both codes (negative needs root; NICE=0 otherwise)
#   OUT             working folder (default: a new /tmp/mpcontact-contact.XXXXXX)
#   MPCONTACT_CACHE_DIR  our kernel cache (default: OUT/kernels; the isotropic Fe kernel is
#                   not cached but built in every run, ~0.02 s, inside the wall time)
# Both run on one thread (OMP_NUM_THREADS=1, --threads 1). Times: ours = case.json `seconds`
# (the solve, kernel excluded); CONTACT = the cpu time of its "Total" timer in NAME.out; and the
# wall time of each whole command. Medians over REPS; ratios = CONTACT / ours of those medians.
# Cell counts at the last increment: CONTACT's NAME.<case>.mat (IGS ≥ 1 contact, IGS = 1 stick),
# ours contact_area_m2 / h² and stick_area_m2 / h² from case.json. Prints a markdown table.
set -euo pipefail
CONTACT_EXE=${1:?usage: bench/contact.sh CONTACT_EXE [NCELLS ...]}
shift
SIZES=("$@"); [ ${#SIZES[@]} -gt 0 ] || SIZES=(128 256)
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CONTACT_EXE=$(readlink -f "$CONTACT_EXE")
[ -x "$CONTACT_EXE" ] || { echo "not an executable: $CONTACT_EXE" >&2; exit 2; }
CONTACT_KIT=${CONTACT_KIT:-$ROOT/../shared/peers/contact}
[ -f "$CONTACT_KIT/gen_catt.py" ] || { echo "no gen_catt.py in $CONTACT_KIT (set CONTACT_KIT)" >&2; exit 2; }
REPS=${REPS:-3}; WARMUP=${WARMUP:-1}; NINC=${NINC:-20}; EPS=${EPS:-1e-6}; NICE=${NICE:--5}
OUT=${OUT:-$(mktemp -d /tmp/mpcontact-contact.XXXXXX)}
mkdir -p "$OUT"; OUT=$(cd "$OUT" && pwd)
if [ -z "${MPCONTACT_EXE:-}" ]; then
  (cd "$ROOT" && cargo build --release -q -p mpcontact)
  MPCONTACT_EXE=$ROOT/target/release/mpcontact
fi
MPCONTACT_EXE=$(readlink -f "$MPCONTACT_EXE")
export MPCONTACT_CACHE_DIR=${MPCONTACT_CACHE_DIR:-$OUT/kernels}
mkdir -p "$MPCONTACT_CACHE_DIR"; chmod 700 "$MPCONTACT_CACHE_DIR"
export OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 RAYON_NUM_THREADS=1
LAST=$(printf '%04d' $((NINC + 1)))   # CONTACT's case number of the last increment
now() { date +%s.%N; }
log() { echo "$*" >&2; }

run_contact() {  # DIR TAG: one run in DIR, appends "wall cpu" to DIR/times
  local d=$1 t0 t1
  rm -f "$d"/catt.out "$d"/catt.*.mat
  t0=$(now)
  (cd "$d" && nice -n "$NICE" "$CONTACT_EXE" 2 catt >"$d/stdout.$2" 2>&1)
  t1=$(now)
  grep -q "ended succesfully" "$d/stdout.$2" || { log "CONTACT failed, see $d/stdout.$2"; exit 1; }
  local cpu; cpu=$(awk -F'|' '$2 ~ /^Total/ {gsub(/ /, "", $4); print $4}' "$d/catt.out")
  echo "$(awk "BEGIN {print $t1 - $t0}") $cpu" >>"$d/times.$2"
}
run_ours() {  # DIR TAG
  local d=$1 t0 t1
  t0=$(now)
  nice -n "$NICE" "$MPCONTACT_EXE" solve "$d/ours.toml" --out "$d/out" --threads 1 >"$d/stdout.$2" 2>&1 \
    || { log "mpcontact failed, see $d/stdout.$2"; exit 1; }
  t1=$(now)
  python3 -c 'import json, sys; c = json.load(open(sys.argv[1])); print(sys.argv[2], c["seconds"], c["tangential_iterations"], c["converged"])' \
    "$d/out/case.json" "$(awk "BEGIN {print $t1 - $t0}")" >>"$d/times.$2"
}

log "CONTACT:   $CONTACT_EXE"
log "mpcontact: $MPCONTACT_EXE ($("$MPCONTACT_EXE" --version 2>/dev/null || echo 'version ?'))"
log "out: $OUT; kernel cache: $MPCONTACT_CACHE_DIR; REPS=$REPS WARMUP=$WARMUP NINC=$NINC EPS=$EPS NICE=$NICE"
for n in "${SIZES[@]}"; do
  m=${MARGIN:-$((n / 16))}
  d=$OUT/n$n; mkdir -p "$d"; rm -f "$d"/times.* "$d"/uptime
  python3 "$CONTACT_KIT/gen_catt.py" "$n" "$NINC" "$m" "$EPS" "$d/catt.inp"
  # the same cells for us: h = 2a/n with gen_catt.py's a, n + 2m points
  h_um=$(python3 -c 'E, nu, R, P = 210000.0, 0.3, 18.0, 20.0
a = (3*P*R/(4*E/(1-nu**2)))**(1/3); print(repr(2*a/'"$n"'*1e3))')
  cat >"$d/ours.toml" <<EOF
[grid]
points = $((n + 2 * m))
spacing_um = $h_um
[indenter]
radius_mm = 18.0
[load]
normal_n = 20.0
friction = 0.3
[sweep]
materials = ["Fe"]
surfaces = ["flat"]
angles_deg = [0.0]
[solver]
coupling = false
[history]
tangential_ratios = [0.0, 0.6]
steps_per_segment = $NINC
EOF
  log "== $n cells across 2a, grid $((n + 2 * m))² of h = $h_um µm"
  uptime >>"$d/uptime"
  for ((k = 0; k < WARMUP; k++)); do run_contact "$d" warm; run_ours "$d" warm; done
  for ((k = 1; k <= REPS; k++)); do
    run_contact "$d" contact; log "  CONTACT run $k: wall, cpu s = $(tail -1 "$d/times.contact")"
    run_ours "$d" ours;       log "  mpcontact run $k: wall, seconds, tangential its, converged = $(tail -1 "$d/times.ours")"
  done
  uptime >>"$d/uptime"
done

python3 - "$OUT" "$LAST" "${SIZES[@]}" <<'PY'
import json, statistics as st, sys
out, last, sizes = sys.argv[1], sys.argv[2], sys.argv[3:]
med = lambda xs: st.median(xs)
rows, notes = [], []
for n in sizes:
    d = f"{out}/n{n}"
    c = [list(map(float, l.split())) for l in open(f"{d}/times.contact")]
    o = [l.split() for l in open(f"{d}/times.ours")]
    c_wall, c_cpu = med([x[0] for x in c]), med([x[1] for x in c])
    o_wall, o_sec = med([float(x[0]) for x in o]), med([float(x[1]) for x in o])
    its = sorted({x[2] for x in o}); conv = all(x[3] == "True" for x in o)
    # CONTACT's map at the last increment: rows "I IGS ..." of the cells in contact
    igs, body = [], False
    for l in open(f"{d}/catt.{last}.mat"):
        if l.startswith("%"):
            body = "IGS" in l.split()
        elif body and l.strip():
            igs.append(int(l.split()[1]))
    c_con, c_stick = sum(1 for g in igs if g >= 1), sum(1 for g in igs if g == 1)
    cj = json.load(open(f"{d}/out/case.json")); h2 = cj["spacing_m"] ** 2
    o_con, o_stick = round(cj["contact_area_m2"] / h2), round(cj["stick_area_m2"] / h2)
    # the last increment's shift: CONTACT prints SHIFT X per case (mm, sign: body 1 against 2)
    txt = open(f"{d}/catt.out").read().split(" Case ")[-1].split()
    c_shift = abs(float(txt[txt.index("APPROACH") + 3])) * 1e-3
    steps = cj["history"]["steps"]; o_shift = steps[-1]["delta_t_m"][0] - steps[-2]["delta_t_m"][0]
    up = [l.split("load average:")[1].strip() for l in open(f"{d}/uptime")]
    rows.append(f"| {n} | {cj['grid_points']}² of {cj['spacing_m']*1e6:.4f} µm | {o_sec:.2f} | {c_cpu:.1f} | "
                f"**{c_cpu/o_sec:.1f}×** | {o_wall:.2f} | {c_wall:.2f} | {c_wall/o_wall:.1f}× | "
                f"{o_con} / {c_con} | {o_stick} / {c_stick} | {'/'.join(its)} | {'all' if conv else 'NO'} |")
    notes.append(f"- {n}: load average before / after: {up[0]} / {up[-1]}; "
                 f"last increment's shift ours {o_shift:.5e} m, CONTACT {c_shift:.4e} m; "
                 f"counts {'equal' if (o_con, o_stick) == (c_con, c_stick) else 'DIFFER'}; "
                 f"runs (CONTACT cpu s): {', '.join(f'{x[1]:.1f}' for x in c)}; (ours s): {', '.join(x[1][:5] for x in o)}")
print("| cells across 2a | grid | ours s (solve) | CONTACT s (cpu) | CONTACT / ours | ours wall s | CONTACT wall s "
      "| wall ratio | contact cells ours / CONTACT | stick cells ours / CONTACT | our tangential its | converged |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
print("\n".join(rows)); print(); print("\n".join(notes))
PY
