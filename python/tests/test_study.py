"""flexmech.study: over a base model it writes what `flexmech study` writes
for the same study file; with a Python callable it builds each run's model."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import flexmech
from conftest import _same, differences, h5_contents, run_cli

STUDY = "data/studies/pitch_dt.toml"  # 8 runs of the free chain, 0.2 s each
GRID = {
    "solver.dt": [0.02, 0.01],
    "joint.screw.pitch": [0.02, 0.05],
    "solver.integrator": ["momentum", "energy-momentum"],
    "solver.t_end": [0.2],
}


def _rows(path):
    with open(path) as f:
        return list(csv.reader(f))


def test_a_study_over_a_base_model_equals_the_study_file(cli, in_root, tmp_path):
    run_cli(cli, "study", STUDY, "--out", str(tmp_path / "cli"))
    # The study file's model path, as the CLI resolves it.
    base = flexmech.Model.load("data/studies/../dynamics/free_chain.toml")
    summary = flexmech.study("pitch-dt", GRID, base=base, out=tmp_path / "py", threads=2)
    cli_dir, py_dir = tmp_path / "cli" / "pitch-dt", tmp_path / "py" / "pitch-dt"
    assert summary.dir == str(py_dir)
    for i in range(8):
        name = f"runs/run-000{i}.h5"
        assert differences(cli_dir / name, py_dir / name) == [], name
    # The summaries: every column but the wall time; the `study` attribute
    # is the study file's text there and the study's description here.
    a, b = h5_contents(cli_dir / "summary.h5"), h5_contents(py_dir / "summary.h5")
    assert list(a["attrs"]["/"]["columns"]) == list(b["attrs"]["/"]["columns"])
    for name in a["datasets"]:
        if name != "/wall_time":
            assert _same(a["datasets"][name], b["datasets"][name]), name
    ca, cb = _rows(cli_dir / "summary.csv"), _rows(py_dir / "summary.csv")
    wall = ca[0].index("wall_time")
    assert [r[:wall] + r[wall + 1 :] for r in ca] == [r[:wall] + r[wall + 1 :] for r in cb]
    assert sorted(p.name for p in (cli_dir / "charts").iterdir()) == sorted(p.name for p in (py_dir / "charts").iterdir())
    # The returned summary: the columns of summary.h5, in order.
    assert list(summary) == ["run"] + list(GRID) + ["status", "energy_drift", "max_displacement", "failure_time", "wall_time", "newton_iterations"]
    assert list(summary["run"]) == [f"run-000{i}" for i in range(8)]
    assert summary["solver.dt"].tolist() == [0.02] * 4 + [0.01] * 4
    assert list(summary["solver.integrator"]) == ["momentum", "energy-momentum"] * 4
    assert all(s == "completed" for s in summary["status"])
    assert summary.result(3)["/time"][-1] == pytest.approx(0.2)
    # The study file through Python: the same again.
    again = flexmech.study_file(STUDY, out=tmp_path / "file")
    assert h5_contents(again.file)["attrs"]["/"]["study"] == a["attrs"]["/"]["study"]
    assert differences(cli_dir / "runs/run-0005.h5", tmp_path / "file/pitch-dt/runs/run-0005.h5") == []


def test_a_study_of_models_built_by_a_python_function(in_root, tmp_path):
    calls = []

    def build(params):
        calls.append(dict(params))
        ei = params["EI"]
        return (
            flexmech.Model("cantilever")
            .section("rod", EA=1e7, GA=[1e6, 1e6], GJ=1e3, EI=[ei, ei])
            .beam("arm", "rod", start=[0, 0, 0], end=[1, 0, 0], e2=[0, 1, 0], elements=params["n"])
            .support("arm.start")
            .nodal_load("arm.end", [0.0, 0.0, -0.1])
            .statics(2)
            .track("arm.end")
        )

    figures = ["max_displacement", {"name": "tip", "dataset": "/nodes/arm.end/displacement", "component": "z", "reduce": "final"}]
    summary = flexmech.study("stiffness", {"EI": [500.0, 1000.0], "n": [4, 8]}, build=build, figures=figures, out=tmp_path)
    assert calls == [{"EI": 500.0, "n": 4}, {"EI": 500.0, "n": 8}, {"EI": 1000.0, "n": 4}, {"EI": 1000.0, "n": 8}]
    assert list(summary) == ["run", "EI", "n", "status", "max_displacement", "tip"]
    tip = summary["tip"]
    assert tip.shape == (4,) and (tip < 0).all()
    # Twice as stiff, half the deflection (to the shear term's share).
    assert tip[2] / tip[0] == pytest.approx(0.5, rel=2e-3)
    assert (tmp_path / "stiffness" / "summary.csv").exists()
    assert (tmp_path / "stiffness" / "charts" / "tip.png").exists()
