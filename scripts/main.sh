#!/usr/bin/env bash
# The main job: build flexmech (release) and solve every model in
# data/benchmarks/, data/statics/ and data/dynamics/, writing one HDF5 result
# file per model into results/
# (or the directory given as the first argument).
source "$(dirname "$0")/env.sh"
OUT="${1:-results}"
cargo build --release --bin flexmech
./target/release/flexmech run data/benchmarks/*.toml data/statics/*.toml data/dynamics/*.toml --out "$OUT"
echo "results written to $OUT/"
