#!/usr/bin/env bash
# Builds a release `flexmech` with the HDF5 library compiled from bundled
# sources and linked in (`--features hdf5-static`): no libhdf5 needed at
# build or run time, and no shared libraries of the system's HDF5 (38 on
# Debian's, with its curl/TLS stack) to load at every start — on a run of a
# few tens of milliseconds that loading is about a tenth of the process.
#   scripts/build_static.sh        -> target/static/release/flexmech
# With FLEXMECH_TARGET_CPU set (a `-C target-cpu` of rustc: `x86-64-v3` for
# AVX2, `native` for this machine) the build uses that processor's
# instructions and goes to target/static-<cpu>/release/flexmech; it will not
# start on a processor without them. Rust never fuses a product and a sum
# into one rounding, so the results are bitwise those of the portable build
# (scripts/same_results.sh checks it on every model of data/paper and
# data/benchmarks).
# CMake >= 3.26 is taken from PATH or the environment's CMAKE, else installed
# from PyPI into target/cmake-venv. The first build compiles HDF5 (a few
# minutes); later ones only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake_ok() {
    local v
    v=$("$1" --version 2>/dev/null | head -1 | grep -oE '[0-9]+\.[0-9]+' | head -1) || return 1
    [ -n "$v" ] && [ "$(printf '%s\n3.26\n' "$v" | sort -V | head -1)" = "3.26" ]
}
CMAKE="${CMAKE:-$(command -v cmake || true)}"
if [ -z "$CMAKE" ] || ! cmake_ok "$CMAKE"; then
    if [ ! -x target/cmake-venv/bin/cmake ]; then
        python3 -m venv target/cmake-venv
        target/cmake-venv/bin/pip install --quiet cmake
    fi
    CMAKE="$PWD/target/cmake-venv/bin/cmake"
fi
export CMAKE PATH="$(dirname "$CMAKE"):$PATH"
dir=target/static
if [ -n "${FLEXMECH_TARGET_CPU:-}" ]; then
    dir="target/static-$FLEXMECH_TARGET_CPU"
    export RUSTFLAGS="${RUSTFLAGS:-} -C target-cpu=$FLEXMECH_TARGET_CPU"
fi
CARGO_TARGET_DIR="$dir" cargo build --release -p flexmech --features hdf5-static --bin flexmech
echo "built $dir/release/flexmech"
