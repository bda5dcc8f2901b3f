# Sourced by the bench scripts that time `mpcontact solve` (fretting.sh,
# iterations.sh), from the repository root: sets `exe` (MPCONTACT_EXE, e.g.
# main's binary for alternating runs, else this tree's release build), a
# scratch folder `tmp` removed on exit, and `field FILE KEY` (a top-level
# value of a case.json).
exe=${MPCONTACT_EXE:-}
if [ -z "$exe" ]; then
  cargo build --release -q --bin mpcontact
  exe=target/release/mpcontact
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }
