"""In-process `flexmech.run` against the command line's whole process on the
same model: paired rounds, alternating which goes first, median ratio.

    python python/benchmarks/run_vs_cli.py [MODEL] [ROUNDS] [FLEXMECH_BIN]

Defaults: data/benchmarks/four_bar_tacs.toml, 15 rounds, target/debug/flexmech
(the workspace's dev profile, the profile the package is built with). The
Python side counts loading the model file and the run (its result read back
into NumPy arrays; with out=DIR also the file kept), not the interpreter's
start or the imports; the command line's side is its whole process, as
`flexmech run MODEL --out DIR` from a shell.
"""

from __future__ import annotations

import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import flexmech

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main() -> None:
    model_path = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "data/benchmarks/four_bar_tacs.toml")
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 15
    binary = sys.argv[3] if len(sys.argv) > 3 else str(ROOT / "target/debug/flexmech")
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="flexmech-bench-"))

    def cli() -> float:
        start = time.perf_counter()
        subprocess.run([binary, "run", model_path, "--out", str(tmp / "cli")], check=True, capture_output=True)
        return time.perf_counter() - start

    def python(out) -> float:
        start = time.perf_counter()
        flexmech.run(flexmech.Model.load(model_path), out=out)
        return time.perf_counter() - start

    cli(), python(None)  # warm the file cache
    rows = []
    for i in range(rounds):
        if i % 2 == 0:
            c, p, q = cli(), python(None), python(tmp / "py")
        else:
            q, p, c = python(tmp / "py"), python(None), cli()
        rows.append((c, p, q))
        print(f"round {i + 1:2d}: cli {c:.3f} s, run() {p:.3f} s, run(out=DIR) {q:.3f} s")
    med = lambda k: statistics.median(r[k] for r in rows)
    ratio = statistics.median(r[1] / r[0] for r in rows)
    ratio_out = statistics.median(r[2] / r[0] for r in rows)
    print(f"median: cli {med(0):.3f} s, run() {med(1):.3f} s, run(out=DIR) {med(2):.3f} s")
    print(f"median of paired ratios: run()/cli {ratio:.3f}, run(out=DIR)/cli {ratio_out:.3f}")


if __name__ == "__main__":
    main()
