#!/usr/bin/env bash
# The whole test suite: unit, property and integration tests of every crate
# (benchmarks against analytic and published solutions included), then the
# formatting and lint checks the project keeps clean.
source "$(dirname "$0")/env.sh"
cargo test --workspace --all-targets
cargo test --workspace --doc
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
