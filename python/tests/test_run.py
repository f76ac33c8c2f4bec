"""flexmech.run against the command line: the same result file, bit for bit
(every dataset, every attribute but the run metadata), and the same values
in memory."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import flexmech
from conftest import _same, differences, h5_contents, run_cli

MODELS = [
    "data/benchmarks/four_bar_tacs.toml",  # generalized-alpha, revolutes, a drive
    "data/paper/screw_driven.toml",  # the paper's driven screw, energy-momentum
    "data/statics/follower_tip_force.toml",  # statics, follower load
    "data/dynamics/body_pendulum.toml",  # a rigid body on an offset
    "data/examples/expression_cam.toml",  # an expression joint: f(psi) in the file
    "data/statics/sensitivity_frame.toml",  # statics with /sensitivity
]

WHIP = "python/tests/models/whip.toml"  # fails part-way


def cli_file(cli, model: str, out: pathlib.Path) -> pathlib.Path:
    proc = run_cli(cli, "run", model, "--out", str(out), check=False)
    name = flexmech.Model.load(model).name
    file = out / f"{name}.h5"
    assert file.exists(), proc.stderr
    return file


@pytest.mark.parametrize("model", MODELS + [WHIP])
def test_the_file_equals_the_cli_file(cli, in_root, tmp_path, model):
    expected = cli_file(cli, model, tmp_path / "cli")
    with pytest.warns(RuntimeWarning) if model == WHIP else _no_warning():
        result = flexmech.run(flexmech.Model.load(model), out=tmp_path / "py")
    assert result.file == str(tmp_path / "py" / expected.name)
    assert differences(expected, result.file) == []


class _no_warning:
    def __enter__(self):
        import warnings

        self._w = warnings.catch_warnings()
        self._w.__enter__()
        warnings.simplefilter("error", RuntimeWarning)

    def __exit__(self, *exc):
        return self._w.__exit__(*exc)


@pytest.mark.parametrize("model", MODELS + [WHIP])
def test_the_result_in_memory_holds_the_cli_file(cli, in_root, tmp_path, model):
    expected = h5_contents(cli_file(cli, model, tmp_path / "cli"))
    with pytest.warns(RuntimeWarning) if model == WHIP else _no_warning():
        result = flexmech.run(flexmech.Model.load(model))
    assert result.file is None
    assert sorted(result) == sorted(expected["datasets"])
    for name, value in expected["datasets"].items():
        assert _same(value, result[name]), name
    root = expected["attrs"]["/"]
    for key in ["model", "status", "energy_drift", "max_displacement", "newton_iterations", "steps", "integrator"]:
        assert _same(root[key], result.attrs[key]), key
    for obj, attrs in expected["attrs"].items():
        if obj != "/":
            for key, value in attrs.items():
                assert _same(value, result.attributes(obj)[key]), (obj, key)


def test_a_run_that_fails_part_way_returns_its_steps(in_root):
    with pytest.warns(RuntimeWarning, match="turns by"):
        result = flexmech.run(flexmech.Model.load(WHIP))
    assert result.failed and not result.completed
    assert result.status.startswith("failed: element 1")
    assert "whip" in result.error and "/tmp" not in result.error
    assert result.time.tolist() == [0.0, 0.005, 0.01]
    assert result["/nodes/arm.end/position"].shape == (3, 3)
    assert np.isfinite(result["/configuration/position"]).all()


def test_names_shapes_and_columns(in_root, tmp_path):
    result = flexmech.run(flexmech.Model.load("data/paper/screw_driven.toml"))
    t = result.time
    assert t.dtype == np.float64 and t[0] == 0.0 and t[-1] == 3.0
    assert result["/nodes/arm.end/position"].shape == (t.size, 3)
    assert result["nodes/arm.end/position"] is result["/nodes/arm.end/position"]
    assert np.array_equal(result["/nodes/arm.end/position[z]"], result["/nodes/arm.end/position"][:, 2])
    n = len(result.node_labels)
    assert result["/configuration/quaternion"].shape == (t.size, n, 4)
    assert np.array_equal(result["/configuration/quaternion[w]"], result["/configuration/quaternion"][..., 0])
    assert result["/solver/iterations"].dtype == np.uint64
    assert result["/mesh/node_labels"].dtype == object
    assert result.nodes == ["arm.end", "arm.start", "post.end"]
    assert result.joints == ["screw"]
    assert result.attributes("/nodes/arm.end")["node_index"] == result.node_labels.index("arm.end")
    assert "position" in result.description("/nodes/arm.end/position")
    assert result.attrs["energy_drift"] < 1e-12
    with pytest.raises(KeyError, match="did you mean /nodes/arm.end/position"):
        result["/nodes/arm.end/positon"]
    again = flexmech.Result.load(flexmech.run(flexmech.Model.load("data/paper/screw_driven.toml"), out=tmp_path).file)
    assert _same(again["/nodes/arm.end/position"], result["/nodes/arm.end/position"])


def test_a_model_built_in_python_runs_as_its_text_through_the_cli(cli, tmp_path):
    """The builder's model, written with to_toml, gives the CLI the same run."""
    model = (
        flexmech.Model("cantilever")
        .section("rod", EA=1e7, GA=[1e6, 1e6], GJ=1e3, EI=[1e3, 1e3], rhoA=1.0, rhoJ=[1e-3, 1e-3, 1e-3])
        .beam("arm", "rod", start=[0, 0, 0], end=[1, 0, 0], e2=[0, 1, 0], elements=10)
        .support("arm.start", "all")
        .nodal_load("arm.end", [0.0, 0.0, -0.1])
        .statics(1)
        .track("arm.end")
    )
    result = flexmech.run(model, out=tmp_path / "py")
    # Timoshenko's F L^3/(3EI) + F L/GA, less the 2-node elements'
    # trapezoidal-rule error F L^3/(12 EI n^2), as the Rust crate docs check.
    expected = 0.1 / 3e3 + 0.1 / 1e6 - 0.1 / (12.0 * 1e3 * 100.0)
    assert abs(result["/nodes/arm.end/position[z]"][-1] + expected) < 1e-3 * expected
    text = tmp_path / "cantilever.toml"
    text.write_text(model.to_toml())
    run_cli(cli, "run", str(text), "--out", str(tmp_path / "cli"))
    assert differences(tmp_path / "cli" / "cantilever.h5", result.file) == []


def test_an_expression_joints_parameter_by_its_key(in_root):
    # The cam's rim reaches -b at psi = pi/2 (t = 0.5 s) whatever b is.
    model = flexmech.Model.load("data/examples/expression_cam.toml")
    model.set("joint.cam.parameters.b", 0.03)
    model.set("solver.t_end", 0.5)
    result = flexmech.run(model)
    assert result.attrs["status"] == "completed"
    follower = result["/joints/cam/released_translation"][:, 0]
    assert abs(follower.min() + 0.03) <= 1e-12
    with pytest.raises(flexmech.ModelError) as e:
        model.set("joint.cam.parameters.pi", 3.0)
    assert "parameters.pi" in str(e.value)
