#!/usr/bin/env bash
# Every test of the project, as the README gives it and CI runs it:
#   1. the Rust workspace (`cargo test --workspace --release`);
#   2. every command of README.md's sh blocks, as written (tests/readme.sh:
#      coarser grids, about 1.5 min of CPU);
#   3. the Python package: `pip install ./python` into a fresh virtualenv
#      (maturin from PyPI builds the native module with this checkout's
#      Cargo.lock), then its pytest suite, which compares Python with the
#      `mpcontact` binary built here.
# Environment: PYTHON (default python3) picks the interpreter;
# MPCONTACT_TEST_VENV keeps the virtualenv at that path instead of a
# temporary one (it is recreated either way).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

cargo test --workspace --release
# The CLI the Python tests compare against (built by the tests above already;
# this only makes sure of it). --workspace keeps the features the tests
# used, so nothing is compiled again.
cargo build --release --workspace --bin mpcontact
target=${CARGO_TARGET_DIR:-$root/target}
export MPCONTACT_CLI="$target/release/mpcontact"
bash tests/readme.sh

python=${PYTHON:-python3}
if [ -n "${MPCONTACT_TEST_VENV:-}" ]; then
  venv=$MPCONTACT_TEST_VENV
  rm -rf "$venv"
else
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  venv=$tmp/venv
fi
"$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check pytest numpy
# SurfaceTopography: the reference the .x3p reader is compared with to the
# bit, and the optional extra behind mpcontact.convert (about 20 s here).
start=$(date +%s)
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check surfacetopography
echo "pip install surfacetopography: $(( $(date +%s) - start )) s"
start=$(date +%s)
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check ./python
echo "pip install ./python: $(( $(date +%s) - start )) s"
# From outside the source tree, so that `import mpcontact` is the installed
# package and not python/mpcontact (which has no native module).
cd "$root/python/tests"
"$venv/bin/python" -m pytest -q -p no:cacheprovider "$@"
