"""flexmech.Simulation: stepping to t equals running to t, bit for bit;
its saved file is the run's file; a restart continues it exactly."""

from __future__ import annotations

import numpy as np
import pytest

import flexmech
from conftest import differences, h5_contents, run_cli

PAPER = "data/paper/screw_driven.toml"  # energy-momentum, driven screw, dt = 0.01
FOUR_BAR = "data/benchmarks/four_bar_tacs.toml"  # generalized-alpha, dt = 0.01


def _last_row(result, name):
    return result[f"/configuration/{name}"][-1]


@pytest.mark.parametrize("path, t", [(PAPER, 0.5), (FOUR_BAR, 1.5)])
def test_stepping_to_t_equals_running_to_t(in_root, path, t):
    sim = flexmech.Simulation(flexmech.Model.load(path))
    steps = sim.run_until(t)
    assert sim.time == pytest.approx(t, abs=1e-12) and steps == round(t / 0.01)
    assert sim.status == "running"
    reference = flexmech.run(flexmech.Model.load(path).set("solver.t_end", t))
    assert reference.time[-1] == sim.time
    for name, value in [
        ("position", sim.positions),
        ("quaternion", sim.quaternions),
        ("velocity", sim.velocities),
        ("angular_velocity", sim.angular_velocities),
    ]:
        expected = _last_row(reference, name)
        assert value.shape == expected.shape
        assert value.tobytes() == expected.tobytes(), name
    assert sim.node_labels == reference.node_labels
    assert sim.energy["total"] == reference["/energy/total"][-1]


def test_step_by_step_and_the_saved_file_equal_the_cli_run(cli, in_root, tmp_path):
    model = flexmech.Model.load(PAPER)
    sim = flexmech.Simulation(model)
    assert sim.time == 0.0 and sim.positions.shape == (len(sim.node_labels), 3)
    assert np.array_equal(sim.quaternions[:, 0], np.ones(len(sim.node_labels)))
    n = 0
    while sim.step():
        n += 1
    assert n == 300 and sim.status == "completed" and sim.time == 3.0
    assert sim.step() is False
    saved = sim.save(tmp_path / "sim.h5")
    run_cli(cli, "run", PAPER, "--out", str(tmp_path / "cli"))
    assert differences(tmp_path / "cli" / "screw_driven.h5", saved) == []


def test_output_every_keeps_the_runs_steps(cli, in_root, tmp_path):
    text = open(FOUR_BAR).read().replace("[output]", "[output]\nevery = 7")
    path = tmp_path / "four_bar_every.toml"
    path.write_text(text)
    model = flexmech.Model.load(path)
    sim = flexmech.Simulation(model)
    sim.run()
    sim.save(tmp_path / "sim.h5")
    run_cli(cli, "run", str(path), "--out", str(tmp_path / "cli"))
    assert differences(tmp_path / "cli" / "four-bar.h5", tmp_path / "sim.h5") == []


def test_a_restart_continues_to_the_last_bit(in_root, tmp_path):
    model = flexmech.Model.load(PAPER)
    first = flexmech.Simulation(model)
    first.run_until(1.2)
    first.save(tmp_path / "half.h5")
    assert flexmech.Result.load(tmp_path / "half.h5").status == "running"
    second = flexmech.Simulation.restart(model, tmp_path / "half.h5")
    assert second.time == pytest.approx(1.2, abs=1e-12)
    second.run()
    whole = flexmech.Simulation(model)
    whole.run()
    assert second.time == whole.time == 3.0
    assert second.positions.tobytes() == whole.positions.tobytes()
    assert second.velocities.tobytes() == whole.velocities.tobytes()
    # The continued file, as `flexmech run --restart` writes it.
    second.save(tmp_path / "rest.h5")
    contents = h5_contents(tmp_path / "rest.h5")
    assert contents["attrs"]["/"]["restart_time"] == pytest.approx(1.2, abs=1e-12)
    assert contents["datasets"]["/time"][0] == pytest.approx(1.2, abs=1e-12)


def test_restart_with_the_cli_file(cli, in_root, tmp_path):
    """A CLI run's /restart continues in Python as it does in the CLI."""
    short = flexmech.Model.load(PAPER).set("solver.t_end", 1.0)
    flexmech.run(short, out=tmp_path / "a")
    model = flexmech.Model.load(PAPER)
    sim = flexmech.Simulation.restart(model, tmp_path / "a" / "screw_driven.h5")
    sim.run()
    sim.save(tmp_path / "py.h5")
    run_cli(cli, "run", PAPER, "--restart", str(tmp_path / "a" / "screw_driven.h5"), "--out", str(tmp_path / "cli"))
    assert differences(tmp_path / "cli" / "screw_driven.h5", tmp_path / "py.h5") == []


def test_a_failing_step_raises_and_keeps_the_steps(in_root, tmp_path):
    sim = flexmech.Simulation(flexmech.Model.load("python/tests/models/whip.toml"))
    with pytest.raises(flexmech.RunError, match="turns by"):
        sim.run()
    assert sim.status.startswith("failed: ") and sim.time == 0.01
    with pytest.raises(flexmech.RunError):
        sim.step()
    sim.save(tmp_path / "whip.h5")
    saved = flexmech.Result.load(tmp_path / "whip.h5")
    assert saved.failed and saved.time.tolist() == [0.0, 0.005, 0.01]


def test_a_static_model_is_not_stepped(in_root):
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Simulation(flexmech.Model.load("data/statics/screw_driven.toml"))
    assert e.value.key == "solver.analysis"


def test_a_restart_of_another_mechanism_is_refused(in_root, tmp_path):
    flexmech.run(flexmech.Model.load(PAPER).set("solver.t_end", 0.1), out=tmp_path)
    other = flexmech.Model.load(PAPER).set("beam.arm.elements", 5)
    with pytest.raises(flexmech.RunError, match="nodes"):
        flexmech.Simulation.restart(other, tmp_path / "screw_driven.h5")


def test_a_saved_file_carries_the_runs_warnings(cli, in_root, tmp_path):
    # Newmark on the free screw to 5 s blows its energy up (the run's
    # energy-balance check warns); the stepped and saved simulation's file
    # carries the same `warnings` as the command line's.
    text = (
        open("data/paper/screw_free.toml")
        .read()
        .replace('integrator = "energy-momentum"', 'integrator = "newmark"')
        .replace("t_end = 6.0", "t_end = 5.0")
    )
    path = tmp_path / "screw_newmark.toml"
    path.write_text(text)
    sim = flexmech.Simulation(flexmech.Model.load(path))
    sim.run_until(5.0)
    assert sim.status == "completed"
    saved = sim.save(tmp_path / "sim.h5")
    run_cli(cli, "run", str(path), "--out", str(tmp_path / "cli"))
    expected = tmp_path / "cli" / "screw_free.h5"
    assert differences(expected, saved) == []
    warnings = flexmech.Result.load(saved).attrs["warnings"]
    assert "energy balance" in str(warnings)
