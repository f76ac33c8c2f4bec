#!/usr/bin/env bash
# The main job: build flexmech (release), reproduce the paper's examples
# (data/paper, every integrator) with their charts, solve every other model in
# data/benchmarks/, data/statics/ and data/dynamics/, and check the published
# dynamic benchmarks in full with every integrator (the long, #[ignore]d runs
# of flexmech/tests/published_dynamics.rs).
#   results/<model>/<integrator>.h5   the paper's examples
#   results/charts/*.png, .svg, .csv, .tex   their figures (and editable copies)
#   results/summary.csv, summary.md   outcome, energy drift, step halvings
#   results/<model>/<integrator>.pvd  ParaView series of each run
#   results/animations/<model>.gif    each example moving
#   results/models/<name>.h5          the other models
#   results/benchmarks/               the benchmark set beside its references:
#                                     a chart each and table.md (reproduce --benchmarks)
# (or the directory given as the first argument instead of results/).
set -e
source "$(dirname "$0")/env.sh"
OUT="${1:-results}"
cargo build --release -p flexmech --bin flexmech
FLEXMECH="${CARGO_TARGET_DIR:-target}/release/flexmech"
"$FLEXMECH" reproduce --out "$OUT"
"$FLEXMECH" reproduce --benchmarks --out "$OUT"
"$FLEXMECH" run data/benchmarks/*.toml data/statics/*.toml data/dynamics/*.toml --out "$OUT/models"
cargo test --release -p flexmech --test main published_dynamics -- --ignored
echo "results written to $OUT/ (figures in $OUT/charts/, summary in $OUT/summary.md, ParaView series $OUT/<model>/<integrator>.pvd, animations in $OUT/animations/)"
