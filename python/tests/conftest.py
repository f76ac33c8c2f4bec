"""Fixtures of the Python package's tests: the repository, the workspace's
`flexmech` binary (the command line the results are compared with) and a
comparison of two HDF5 files, dataset by dataset, bit for bit."""

from __future__ import annotations

import os
import pathlib
import subprocess
from typing import Dict, List, Optional

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

# Attributes that describe the process and the build that wrote a file, not
# the run: left out of the comparisons.
METADATA = {"created", "command_line", "wall_time_s", "git_revision"}


def flexmech_binary() -> pathlib.Path:
    """The workspace's `flexmech` binary, built in the dev profile (the
    test suite builds it with `cargo test`; built here if missing)."""
    env = os.environ.get("FLEXMECH_BIN")
    if env:
        return pathlib.Path(env)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    binary = target / "debug" / "flexmech"
    if not binary.exists():
        subprocess.run(
            ["cargo", "build", "-p", "flexmech", "--bin", "flexmech"],
            cwd=ROOT,
            check=True,
        )
    return binary


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    return flexmech_binary()


@pytest.fixture
def in_root(monkeypatch: pytest.MonkeyPatch) -> pathlib.Path:
    """Runs the test in the repository root (the model paths of the CLI and
    of Python are then the same strings, as their messages show them)."""
    monkeypatch.chdir(ROOT)
    return ROOT


def run_cli(cli: pathlib.Path, *args: str, check: bool = True) -> subprocess.CompletedProcess:
    """Runs `flexmech ARGS...` in the repository root."""
    proc = subprocess.run([str(cli), *args], cwd=ROOT, capture_output=True, text=True)
    if check and proc.returncode != 0:
        raise AssertionError(f"flexmech {' '.join(args)} failed:\n{proc.stdout}\n{proc.stderr}")
    return proc


def _value(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.ndarray) and v.dtype == object:
        return [x.decode() if isinstance(x, bytes) else x for x in v.tolist()]
    return v


def _same(a, b) -> bool:
    """Equal bit for bit (NaN equal to NaN of the same bits, -0.0 not 0.0)."""
    a, b = _value(a), _value(b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.dtype != b.dtype or a.shape != b.shape:
            return False
        if a.dtype.kind == "f":
            return a.tobytes() == b.tobytes()
        return bool(np.array_equal(a, b))
    if isinstance(a, float) and isinstance(b, float):
        return np.float64(a).tobytes() == np.float64(b).tobytes()
    return a == b


def h5_contents(path) -> Dict[str, Dict]:
    """Every dataset (path -> array) and every attribute (path -> dict)."""
    import h5py

    datasets: Dict[str, np.ndarray] = {}
    attrs: Dict[str, Dict] = {}
    with h5py.File(path, "r") as f:
        attrs["/"] = dict(f.attrs)

        def visit(name, obj):
            attrs["/" + name] = dict(obj.attrs)
            if isinstance(obj, h5py.Dataset):
                datasets["/" + name] = obj[()]

        f.visititems(visit)
    return {"datasets": datasets, "attrs": attrs}


def differences(a, b, ignore: Optional[set] = None) -> List[str]:
    """What differs between the HDF5 files `a` and `b`: datasets (names,
    types, shapes, values bit for bit) and attributes (all but `ignore`,
    the run metadata by default)."""
    ignore = METADATA if ignore is None else ignore
    ca, cb = h5_contents(a), h5_contents(b)
    out: List[str] = []
    da, db = ca["datasets"], cb["datasets"]
    if set(da) != set(db):
        out.append(f"datasets only in one file: {sorted(set(da) ^ set(db))}")
    for name in sorted(set(da) & set(db)):
        if not _same(da[name], db[name]):
            out.append(f"dataset {name} differs")
    aa, ab = ca["attrs"], cb["attrs"]
    if set(aa) != set(ab):
        out.append(f"objects only in one file: {sorted(set(aa) ^ set(ab))}")
    for obj in sorted(set(aa) & set(ab)):
        keys = (set(aa[obj]) | set(ab[obj])) - (ignore if obj == "/" else set())
        for k in sorted(keys):
            if k not in aa[obj] or k not in ab[obj]:
                out.append(f"attribute {obj}@{k} only in one file")
            elif not _same(aa[obj][k], ab[obj][k]):
                out.append(f"attribute {obj}@{k} differs: {aa[obj][k]!r} vs {ab[obj][k]!r}")
    return out
