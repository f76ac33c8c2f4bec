#!/usr/bin/env python3
"""Time of the 10 lowest modes against the model's size, dense and sparse.

    python3 benches/modal_size.py [ELEMENTS ...]

For each element count a cantilever of 2-node elements (6 unknowns per
node) runs `analysis = "modal"`, `modes = 10` once with `eigensolver =
"dense"` and once with `"sparse"` (the dense one only up to 1 200
elements), whole process, release binary (`cargo build --release`), and the
lowest frequencies of both are compared. Prints one row per size: unknowns,
seconds dense, seconds sparse, largest relative difference of the ten
frequencies.
"""
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parents[1]
BIN = ROOT / "target" / "release" / "flexmech"
MODEL = """name = "beam"
[[section]]
name = "s"
EA = 1e7
GA = [1e7, 1e7]
GJ = 1e3
EI = [1e3, 2e3]
rhoA = 1.0
rhoJ = [1e-3, 1e-4, 1e-4]
[[beam]]
name = "b"
section = "s"
start = [0.0, 0.0, 0.0]
end = [1.0, 0.0, 0.0]
e2 = [0.0, 1.0, 0.0]
elements = {elements}
[[support]]
node = "b.start"
fixed = "all"
[solver]
analysis = "modal"
modes = 10
eigensolver = "{solver}"
"""
DENSE_UP_TO = 1200


def run(elements, solver, out):
    model = out / f"{solver}-{elements}.toml"
    model.write_text(MODEL.format(elements=elements, solver=solver))
    start = time.perf_counter()
    subprocess.run([BIN, "run", model, "--out", out / solver], check=True, capture_output=True)
    seconds = time.perf_counter() - start
    with h5py.File(out / solver / "beam.h5") as f:
        return seconds, f["/modes/frequency"][:]


def main():
    sizes = [int(a) for a in sys.argv[1:]] or [100, 400, 1200, 5000, 20000]
    print("elements unknowns dense_s sparse_s max_rel_diff")
    with tempfile.TemporaryDirectory() as d:
        out = Path(d)
        for e in sizes:
            ts, fs = run(e, "sparse", out)
            if e <= DENSE_UP_TO:
                td, fd = run(e, "dense", out)
                diff = max(abs(a - b) / b for a, b in zip(fs, fd))
                print(f"{e} {6 * e} {td:.3f} {ts:.3f} {diff:.1e}")
            else:
                print(f"{e} {6 * e} - {ts:.3f} -")


if __name__ == "__main__":
    main()
