"""The type stubs and docstrings cover every public call of the package."""

from __future__ import annotations

import ast
import inspect
import pathlib

import flexmech
from flexmech import _flexmech


def _stub() -> dict:
    tree = ast.parse((pathlib.Path(_flexmech.__file__).parent / "_flexmech.pyi").read_text())
    names: dict = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = {n.name for n in node.body if isinstance(n, (ast.FunctionDef, ast.AnnAssign)) and hasattr(n, "name")}
            names[node.name] |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = set()
    return names


def test_every_public_name_of_the_extension_has_a_stub_and_a_docstring():
    stub = _stub()
    for name in ["Model", "Simulation", "ModelError", "RunError", "joint_kinds", "run_model", "read_h5", "run_study_py", "run_study_file"]:
        assert name in stub, name
        assert getattr(_flexmech, name).__doc__, name
    for cls in [flexmech.Model, flexmech.Simulation]:
        public = {n for n in dir(cls) if not n.startswith("_")}
        assert public <= stub[cls.__name__], public - stub[cls.__name__]
        for n in public:
            assert getattr(cls, n).__doc__, f"{cls.__name__}.{n}"


def test_the_python_api_is_documented():
    for name in flexmech.__all__:
        obj = getattr(flexmech, name)
        assert obj.__doc__, name
    for n, member in inspect.getmembers(flexmech.Result):
        if not n.startswith("_"):
            assert member.__doc__ or isinstance(member, property), n
