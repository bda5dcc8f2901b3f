#!/usr/bin/env bash
# Config loading under many mutated configs (the property test of
# coordinator/tests/config_fuzz.rs, with more cases and seeds).
# Usage: bench/fuzz-config.sh [CASES_PER_SEED] [SEEDS]
set -euo pipefail
cd "$(dirname "$0")/.."
cases=${1:-100000}
seeds=${2:-8}
for seed in $(seq 1 "$seeds"); do
  MPCONTACT_FUZZ_CASES=$cases MPCONTACT_FUZZ_SEED=$((seed * 7919)) \
    cargo test --release -q -p mpcontact --test config_fuzz -- --nocapture 2>&1 \
    | grep -E "mutated configs|panicked|error names" || true
done
