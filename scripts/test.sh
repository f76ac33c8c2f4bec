#!/usr/bin/env bash
# The whole test suite: unit, property and integration tests of every crate
# (benchmarks against analytic and published solutions included), then the
# formatting and lint checks the project keeps clean.
source "$(dirname "$0")/env.sh"
# The VTK library reads the ParaView series back in the tests
# (scripts/check_vtk.py); with its Python modules installed the check is
# required, otherwise it is skipped with a message.
if python3 -c "import vtk, h5py, numpy" 2>/dev/null ||
   python3 -m pip install --quiet --disable-pip-version-check vtk h5py numpy >/dev/null 2>&1; then
  export FLEXMECH_REQUIRE_VTK=1
else
  echo "flexmech tests: Python's vtk/h5py could not be installed: the VTK read-back checks are skipped" >&2
fi
# pdflatex compiles the charts' PGFPlots copies in the tests (TeX Live from
# the distribution's packages; skipped with a message where it cannot be had).
if ! command -v pdflatex >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" -eq 0 ]; then
  echo "flexmech tests: installing pdflatex and pgfplots (apt-get: texlive-latex-base texlive-pictures texlive-latex-recommended)..." >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    texlive-latex-base texlive-pictures texlive-latex-recommended >/dev/null 2>&1 || true
fi
if command -v pdflatex >/dev/null 2>&1 && kpsewhich pgfplots.sty >/dev/null 2>&1; then
  export FLEXMECH_REQUIRE_PDFLATEX=1
else
  echo "flexmech tests: pdflatex with pgfplots is not available: the PGFPlots compile checks are skipped" >&2
fi
# A one-shot build (CI, a fresh clone) is faster without incremental
# compilation's caches; a developer's repeated runs keep them.
if [ -n "${CI:-}" ]; then export CARGO_INCREMENTAL=0; fi
# Every test target but the criterion benchmarks (bench/, a crate of
# benchmarks only; clippy below still checks that they compile): unit,
# integration, the examples' (`test = true`) and doc tests. The Python extension (python/) has no Rust tests (`test = false`,
# `doctest = false`; its pytest suite runs below), but as a member it takes
# part in the feature resolution, so the extension maturin builds below
# reuses this build's dependencies instead of building them again.
cargo test --workspace
echo "flexmech tests: unit, integration, example and doc tests done at ${SECONDS} s" >&2
# The Python package: a virtual environment in target/pyenv, `pip install
# ./python` (maturin from the registry builds the extension in the
# workspace's dev profile and target directory, so it reuses the build
# above), then its pytest suite, which compares its results with those of
# the workspace's `flexmech` binary built above.
PYENV="$ROOT/target/pyenv"
[ -x "$PYENV/bin/python" ] || python3 -m venv "$PYENV"
"$PYENV/bin/python" -m pip install --quiet --disable-pip-version-check pytest h5py matplotlib
CARGO_TARGET_DIR="$ROOT/target" "$PYENV/bin/python" -m pip install --quiet --disable-pip-version-check ./python
echo "flexmech tests: Python package installed at ${SECONDS} s" >&2
FLEXMECH_BIN="$ROOT/target/debug/flexmech" MPLBACKEND=Agg "$PYENV/bin/python" -m pytest -q python/tests
echo "flexmech tests: Python tests done at ${SECONDS} s" >&2
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
