#!/usr/bin/env python3
"""The cost of exact sensitivities: the four-bar benchmark (12 s, 1 201
steps, generalized-alpha, full Newton) run plain, with one
`[output] sensitivity` key and with three, alternating the runs so that the
machine's drift cancels; prints each variant's median whole-process wall
time over the plain run's (the result file included).

    python3 benches/sensitivity_cost.py [ROUNDS] [FLEXMECH_BINARY]

ROUNDS defaults to 7, the binary to target/release/flexmech (build it with
`cargo build --release -p flexmech`) or $FLEXMECH_BIN."""

import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
TRACK = 'track = ["bar2.end", "bar3.start"]'
VARIANTS = {
    "plain": [],
    "1 key": ["section.bar8.EI[0]"],
    "3 keys": ["section.bar8.EI[0]", "section.bar16.GJ", "section.bar8.EA"],
}


def main() -> None:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    default = os.environ.get("FLEXMECH_BIN", str(ROOT / "target/release/flexmech"))
    binary = sys.argv[2] if len(sys.argv) > 2 else default
    text = (ROOT / "data/benchmarks/four_bar_tacs.toml").read_text()
    text = text.replace("resultants = true", "resultants = false")
    with tempfile.TemporaryDirectory() as tmp:
        files = {}
        for name, keys in VARIANTS.items():
            listed = ", ".join(f'"{k}"' for k in keys)
            body = text.replace(TRACK, f"{TRACK}\nsensitivity = [{listed}]") if keys else text
            files[name] = pathlib.Path(tmp) / f"{name.replace(' ', '_')}.toml"
            files[name].write_text(body)
        ratios = {name: [] for name in VARIANTS if name != "plain"}
        for _ in range(rounds):
            times = {}
            for name, file in files.items():
                start = time.perf_counter()
                subprocess.run([binary, "run", str(file), "--out", tmp], check=True,
                               stdout=subprocess.DEVNULL)
                times[name] = time.perf_counter() - start
            for name in ratios:
                ratios[name].append(times[name] / times["plain"])
        for name, values in ratios.items():
            print(f"{name}: {statistics.median(values):.2f} x the plain run "
                  f"(min {min(values):.2f}, max {max(values):.2f}, {rounds} rounds)")


if __name__ == "__main__":
    main()
