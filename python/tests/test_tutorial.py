"""The tutorial script (python/examples/tutorial.py) runs end to end: the
paper's driven screw with every scheme and a study of its pitch."""

from __future__ import annotations

import subprocess
import sys

from conftest import ROOT


def test_the_tutorial_runs(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(ROOT / "python" / "examples" / "tutorial.py"), str(tmp_path)],
        capture_output=True,
        text=True,
        env={"MPLBACKEND": "Agg", **__import__("os").environ},
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    out = proc.stdout
    assert "energy-momentum-paper    completed" in out
    for scheme in ["newmark", "momentum", "energy-momentum", "energy-momentum-paper"]:
        assert (tmp_path / "paper" / scheme / "screw_driven.h5").exists()
    study = tmp_path / "studies" / "pitch"
    assert (study / "summary.csv").read_text().startswith("run,joint.screw.pitch,solver.integrator,status")
    assert sorted(p.name for p in (study / "runs").iterdir()) == ["run-0000.h5", "run-0001.h5", "run-0002.h5"]
    assert (study / "charts" / "lift.png").exists()
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    assert (tmp_path / "paper" / "tip_lift.png").stat().st_size > 1000
