"""Bad input from Python is an exception naming the key or the run — never
a crash of the interpreter, never a half-read value."""

from __future__ import annotations

import math

import numpy as np
import pytest

import flexmech

PAPER = "data/paper/screw_driven.toml"


def test_a_model_file_error_keeps_its_file_line_and_key(in_root, tmp_path):
    text = open(PAPER).read().replace("pitch = 0.02", "pitch = \"steep\"")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Model.load(path)
    err = e.value
    assert err.key == "joint[0].pitch"
    assert err.file == str(path)
    assert err.line == text.splitlines().index(next(l for l in text.splitlines() if l.startswith("pitch = \"steep\""))) + 1
    assert str(err).startswith(f"{path}:{err.line}: key `joint[0].pitch`")
    assert isinstance(err, ValueError)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Model.from_toml(text)
    assert e.value.file == "<string>" and e.value.line == err.line


def test_an_unknown_joint_kind_names_the_registered_ones(in_root):
    text = open(PAPER).read().replace('type = "screw"', 'type = "scru"')
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Model.from_toml(text, "scru.toml")
    assert e.value.key == "joint[0].type"
    for kind in flexmech.joint_kinds():
        assert f'"{kind}"' in str(e.value)
    assert "screw" in flexmech.joint_kinds() and "rack_pinion" in flexmech.joint_kinds()


def test_set_refuses_an_unknown_key_naming_it(in_root):
    model = flexmech.Model.load(PAPER)
    with pytest.raises(flexmech.ModelError) as e:
        model.set("joint.scew.pitch", 0.05)
    assert e.value.key == "joint.scew.pitch" and 'entries: "screw"' in str(e.value)
    with pytest.raises(flexmech.ModelError) as e:
        model.set("solver.dtt", 0.05)
    assert "dtt" in str(e.value) and "dtt" in e.value.key
    with pytest.raises(flexmech.ModelError) as e:
        model.set("beam[7].elements", 3)
    assert e.value.key == "beam[7].elements" and "2 entries" in str(e.value)
    with pytest.raises(flexmech.ModelError, match="unclosed"):
        model.set("beam[0.elements", 3)
    # Nothing changed: the model still runs as read.
    assert model.get("joint.screw.pitch") == 0.02
    assert model.to_toml() == open(PAPER).read()


@pytest.mark.parametrize(
    "key, value, words",
    [
        ("solver.dt", "fast", "expected a number"),
        ("solver.dt", -0.01, "solver.dt"),
        ("joint.screw.pitch", [1, 2], "joint[0].pitch"),
        ("beam.arm.elements", 2.5, "beam[1].elements"),
        ("solver.integrator", "rk4", "rk4"),
    ],
)
def test_set_refuses_a_wrong_value_and_keeps_the_model(in_root, key, value, words):
    model = flexmech.Model.load(PAPER)
    with pytest.raises(flexmech.ModelError) as e:
        model.set(key, value)
    assert words in str(e.value) and key in str(e.value)
    assert model.to_toml() == open(PAPER).read()


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, np.float64("nan")])
def test_non_finite_numbers_are_refused_at_their_key(in_root, value):
    model = flexmech.Model.load(PAPER)
    with pytest.raises(flexmech.ModelError) as e:
        model.set("joint.screw.pitch", value)
    assert e.value.key == "joint.screw.pitch" and "finite" in str(e.value)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Model("m").gravity([0.0, 0.0, value])
    assert e.value.key == "gravity[2]"
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Model("m").section("rod", EA=value, GA=[1, 1], GJ=1, EI=[1, 1])
    assert e.value.key == "section[0].EA"


def test_values_without_a_model_file_form_are_refused(in_root):
    model = flexmech.Model.load(PAPER)
    with pytest.raises(flexmech.ModelError, match="no model-file form") as e:
        model.set("solver.dt", object())
    assert e.value.key == "solver.dt"
    with pytest.raises(flexmech.ModelError, match="None"):
        model.set("solver.dt", None)
    with pytest.raises(flexmech.ModelError, match="64 bits"):
        model.set("beam.arm.elements", 2**70)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.Model("m").joint("j", "screw", "a.end", "b.start", params="axis = [0, 0")
    assert e.value.key == "joint[0]"
    # NumPy values are numbers.
    model.set("joint.screw.pitch", np.float32(0.25)).set("beam.arm.elements", np.int64(6))
    assert model.get("beam.arm.elements") == 6 and model.get("joint.screw.pitch") == 0.25


def test_an_incomplete_builder_model_is_refused_when_used(tmp_path):
    model = flexmech.Model("arm").section("rod", EA=1e7, GA=[1e6, 1e6], GJ=1e3, EI=[1e3, 1e3])
    model.beam("arm", "rod", start=[0, 0, 0], end=[1, 0, 0], elements=4, e2=[0, 1, 0])
    model.support("arm.start").nodal_load("arm.tip", [0, 0, -1]).statics(1)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.run(model)
    assert e.value.key == "load[0].node" and "arm.tip" in str(e.value)
    assert e.value.file is None and e.value.line is None
    with pytest.raises(TypeError):
        flexmech.run("data/paper/screw_driven.toml")


def test_a_callable_that_raises_names_the_run(tmp_path):
    def build(params):
        if params["x"] == 2:
            raise ZeroDivisionError("no model for x = 2")
        return flexmech.Model.load(f"{flexmech_root()}/data/paper/screw_driven.toml")

    with pytest.raises(flexmech.RunError) as e:
        flexmech.study("bad", {"x": [1, 2, 3]}, build=build, out=tmp_path)
    assert "run-0001" in str(e.value) and "x = 2" in str(e.value)
    assert isinstance(e.value.__cause__, ZeroDivisionError)
    assert not (tmp_path / "bad" / "runs").exists()


def test_a_callable_returning_no_model_or_a_bad_one_names_the_run(tmp_path):
    with pytest.raises(flexmech.RunError, match="run-0000.*not a flexmech.Model"):
        flexmech.study("bad", {"x": [1]}, build=lambda p: 42, out=tmp_path)
    bad = flexmech.Model("m").section("rod", EA=-1.0, GA=[1, 1], GJ=1, EI=[1, 1])
    with pytest.raises(flexmech.ModelError, match="run-0000") as e:
        flexmech.study("bad", {"x": [1]}, build=lambda p: bad, out=tmp_path)
    assert isinstance(e.value.__cause__, flexmech.ModelError)


def test_study_input_errors_name_the_key(in_root, tmp_path):
    base = flexmech.Model.load(PAPER)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.study("s", {"joint.scew.pitch": [0.1]}, base=base, out=tmp_path)
    assert e.value.key == "joint.scew.pitch"
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.study("s", {"joint.screw.pitch": 0.1}, base=base, out=tmp_path)
    assert "list" in str(e.value)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.study("s", {"joint.screw.pitch": [0.1, math.nan]}, base=base, out=tmp_path)
    assert "finite" in str(e.value)
    with pytest.raises(flexmech.ModelError) as e:
        flexmech.study("s", {"joint.screw.pitch": [0.1, "steep"]}, base=base, out=tmp_path)
    assert "run-0001" in str(e.value) and "steep" in str(e.value) and e.value.key == "joint[0].pitch"
    with pytest.raises(flexmech.ModelError, match="unknown figure"):
        flexmech.study("s", {"joint.screw.pitch": [0.1]}, base=base, figures=["speed"], out=tmp_path)
    with pytest.raises(flexmech.ModelError, match="either build"):
        flexmech.study("s", {"joint.screw.pitch": [0.1]}, out=tmp_path)
    with pytest.raises(flexmech.ModelError, match="directory name"):
        flexmech.study("a/b", {"joint.screw.pitch": [0.1]}, base=base, out=tmp_path)


def flexmech_root():
    from conftest import ROOT

    return ROOT
