#!/usr/bin/env bash
# A fuzzing campaign over the model files in data/: mutants (numeric,
# structural and byte-level) through `flexmech check` and a shortened
# `flexmech run`, each in its own process; prints the counts per outcome and
# keeps every defect's mutant under the output directory.
#
#   scripts/fuzz.sh [MUTANTS] [SEED] [OUT]      (defaults: 5000 1 fuzz)
#
# Exits non-zero when a defect (panic, abort, hang, unlocated error,
# non-finite completed result) was found.
set -euo pipefail
cd "$(dirname "$0")/.."
mutants="${1:-5000}"
seed="${2:-1}"
out="${3:-fuzz}"
cargo build --release --bin flexmech --bin flexmech-fuzz
"${CARGO_TARGET_DIR:-target}/release/flexmech-fuzz" \
    --mutants "$mutants" --seed "$seed" --out "$out" --data data
