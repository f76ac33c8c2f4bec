"""flexmech from Python, end to end: one of the paper's examples with every
integrator, then a parameter study over it.

    python python/examples/tutorial.py [OUT]        (default OUT: tutorial-out)

1. The paper's driven screw (data/paper/screw_driven.toml: an arm lifted by a
   screw whose angle is driven through a spin-up) with the four schemes the
   README's table compares: the energy balance error of each run (the result
   file's `energy_drift`), its step reductions and Newton iterations per step
   -- Newmark drifts by about 1e-3, the momentum scheme by 7e-6, the
   energy-momentum schemes hold the balance to round-off, the paper's own at
   the cost of 16 reduced steps -- and the tip's lift over time (the paper's
   Figure 8) as a chart.
2. A study of the screw's pitch over that model, run in parallel by Rust:
   each run's result file, the summary table and its charts, as `flexmech
   study` writes them, with a figure of our own (the arm tip's final lift),
   which grows with the pitch.

The test suite runs this script (python/tests/test_tutorial.py).
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np

import flexmech

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCHEMES = ["newmark", "momentum", "energy-momentum", "energy-momentum-paper"]


def paper_example(out: pathlib.Path) -> dict:
    """The driven screw with every scheme: one result file each in OUT/paper."""
    model = flexmech.Model.load(ROOT / "data" / "paper" / "screw_driven.toml")
    dt = model.get("solver.dt")
    results = {}
    print(f"{'integrator':24} {'status':10} {'energy error':>12} {'reduced':>8} {'iterations':>10}")
    for scheme in SCHEMES:
        model.set("solver.integrator", scheme)
        result = flexmech.run(model, out=out / "paper" / scheme)
        reduced = int((result["/solver/dt"][1:] < dt * (1 - 1e-9)).sum())
        iterations = result["/solver/iterations"][1:].mean()
        print(f"{scheme:24} {result.status:10} {result.attrs['energy_drift']:12.2e} {reduced:8d} {iterations:10.2f}")
        results[scheme] = result
    figure(results, out / "paper" / "tip_lift.png")
    return results


def figure(results: dict, path: pathlib.Path) -> None:
    """The arm tip's lift over time for every scheme (when matplotlib is
    installed)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(matplotlib is not installed: no charts)")
        return
    fig, ax = plt.subplots(figsize=(8, 5))
    for scheme, result in results.items():
        result.plot("/nodes/arm.end/displacement[z]", ax=ax, labels=[scheme])
    ax.set_title("screw_driven: the arm tip's lift")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    print(f"chart: {path}")


def pitch_study(out: pathlib.Path) -> flexmech.Summary:
    """The screw's pitch swept over the paper's model: OUT/studies/pitch/."""
    base = flexmech.Model.load(ROOT / "data" / "paper" / "screw_driven.toml")
    lift = {"name": "lift", "dataset": "/nodes/arm.end/displacement", "component": "z", "reduce": "final"}
    summary = flexmech.study(
        "pitch",
        {"joint.screw.pitch": [0.01, 0.02, 0.04], "solver.integrator": ["energy-momentum"]},
        base=base,
        figures=["energy_drift", "newton_iterations", lift],
        out=out / "studies",
    )
    print(f"{'run':10} {'pitch':>6} {'status':10} {'energy error':>12} {'final lift':>10}")
    for i, run in enumerate(summary["run"]):
        print(
            f"{run:10} {summary['joint.screw.pitch'][i]:6.2f} {summary['status'][i]:10} "
            f"{summary['energy_drift'][i]:12.2e} {summary['lift'][i]:10.4f}"
        )
    print(f"summary: {summary.dir}/summary.csv, charts in {summary.dir}/charts")
    return summary


def main(out: pathlib.Path) -> None:
    results = paper_example(out)
    # The README's table: the conserving schemes hold the energy balance.
    drift = {s: r.attrs["energy_drift"] for s, r in results.items()}
    assert all(r.completed for r in results.values())
    assert 5e-4 < drift["newmark"] < 5e-3 and 1e-6 < drift["momentum"] < 1e-4
    assert drift["energy-momentum"] < 1e-12 and drift["energy-momentum-paper"] < 1e-12
    summary = pitch_study(out)
    assert all(s == "completed" for s in summary["status"])
    # The lift grows with the pitch (the screw lifts pitch x angle).
    assert np.all(np.diff(summary["lift"]) > 0)


if __name__ == "__main__":
    main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "tutorial-out"))
