"""flexmech from Python: dynamics of flexible mechanisms — geometrically
exact beams joined by joints — with the Rust solvers of the flexmech
workspace.

>>> import flexmech
>>> model = flexmech.Model.load("data/benchmarks/four_bar_tacs.toml")
>>> result = flexmech.run(model)                 # in memory
>>> result["/nodes/C/position"].shape            # T×3, the result file's names
>>> flexmech.run(model, out="results")           # results/<name>.h5, as `flexmech run`

Models (``Model``) come from model files, text, or builder calls that
mirror the Rust ``ModelBuilder``; ``run`` returns a ``Result`` of NumPy
arrays; ``Simulation`` steps a dynamic model; ``study`` runs a parameter
study as ``flexmech study`` does. The model and result names are the
contract of ``docs/MODEL_FORMAT.md``; the chapter is
``docs/book/python.md``.
"""

from __future__ import annotations

import os
import warnings
from typing import Any, Callable, Dict, Iterable, Mapping, Optional, Sequence, Union

import numpy as np

from . import _flexmech
from ._flexmech import Model, ModelError, RunError, Simulation, joint_kinds
from ._result import Result

__all__ = [
    "Model",
    "ModelError",
    "Result",
    "RunError",
    "Simulation",
    "Summary",
    "joint_kinds",
    "run",
    "study",
    "study_file",
]

__version__: str = _flexmech.__version__

PathLike = Union[str, "os.PathLike[str]"]


def run(model: Model, out: Optional[PathLike] = None) -> Result:
    """Runs ``model`` and returns its ``Result``.

    With ``out`` the result file is ``<out>/<name>.h5``, the file ``flexmech
    run MODEL --out OUT`` writes (with the ParaView series of ``[output] vtk =
    true``); without, the file is made in a temporary directory, read and
    removed. The interpreter is released while the model runs; Ctrl-C stops
    it (``KeyboardInterrupt``; with ``out`` the file keeps the steps before,
    ``status = "failed: interrupted ..."``).

    A run the solver stops part-way is not an exception: its result holds
    every step computed before, ``result.status == "failed: ..."`` (and a
    ``RuntimeWarning`` says so). Raises ``ModelError`` for a model that is
    refused and ``RunError`` when the file cannot be written.
    """
    if not isinstance(model, Model):
        raise TypeError(f"run() takes a flexmech.Model, not {type(model).__name__}")
    path = None if out is None else os.fspath(out)
    file, datasets, attributes, error = _flexmech.run_model(model, path)
    result = Result(datasets, attributes, file=file, error=error)
    if error is not None:
        warnings.warn(f"the run stopped part-way: {error}", RuntimeWarning, stacklevel=2)
    return result


class Summary(Dict[str, np.ndarray]):
    """A study's summary: one array per column (``run``, each grid key,
    ``status``, each figure), one entry per run in run order — the columns
    of ``summary.csv`` and ``summary.h5``. ``dir`` is the study's directory
    and ``result(i)`` reads run ``i``'s result file."""

    dir: str
    file: str

    def __init__(self, columns: Mapping[str, np.ndarray], dir: str, file: str) -> None:
        super().__init__(columns)
        self.dir = dir
        self.file = file

    def result(self, run: Union[int, str]) -> Result:
        """The result of run ``run`` (its index, or its id ``"run-0003"``)."""
        ids = list(self["run"])
        run_id = ids[run] if isinstance(run, int) else run
        return Result.load(os.path.join(self.dir, "runs", f"{run_id}.h5"))


def _summary(directory: str, h5: str) -> Summary:
    datasets, attributes = _flexmech.read_h5(h5)
    order = list(attributes.get("/", {}).get("columns", [])) or [k.lstrip("/") for k in datasets]
    columns: Dict[str, np.ndarray] = {}
    by_name = {k.lstrip("/"): v for k, v in datasets.items()}
    for name in order:
        # A '/' in a key is '_' in the file's dataset name.
        value = by_name.get(name, by_name.get(name.replace("/", "_")))
        if value is None:
            continue
        if isinstance(value, list):
            array = np.empty(len(value), dtype=object)
            array[:] = value
            value = array
        columns[name] = value
    return Summary(columns, directory, h5)


def study(
    name: str,
    grid: Mapping[str, Sequence[Any]],
    build: Optional[Callable[[Dict[str, Any]], Model]] = None,
    figures: Optional[Iterable[Union[str, Mapping[str, Any]]]] = None,
    out: PathLike = "studies",
    threads: Optional[int] = None,
    base: Optional[Model] = None,
) -> Summary:
    """Runs a parameter study and returns its summary (see ``Summary``).

    ``grid`` maps names to lists of values; the runs are their cartesian
    product, the last key varying fastest (``run-0000``, ``run-0001``, ...).
    Either ``build(params)`` returns each run's ``Model`` from a dict of the
    run's values (called once per run, before the first run starts), or
    ``base`` is a ``Model`` and the grid keys are its key paths, as in study
    files (``"joint.screw.pitch"``, ``"solver.dt"``). ``figures`` are the
    summary's figures: names (``"energy_drift"``, ``"max_displacement"``,
    ``"failure_time"``, ``"wall_time"``, ``"newton_iterations"``; all five by
    default) or dataset figures as in study files (``{"name": "lift",
    "dataset": "/nodes/arm.end/displacement", "component": "z", "reduce":
    "max-abs"}``).

    The runs run in parallel in Rust on ``threads`` threads (default: every
    core, or ``RAYON_NUM_THREADS``), without the interpreter lock; the study
    writes what ``flexmech study`` writes below ``<out>/<name>/``: a result
    file per run in ``runs/``, ``summary.csv``, ``summary.h5`` and
    ``charts/``. A run the solver stops is a failed row, not an exception.
    A refused key, value or model raises ``ModelError`` naming the run and
    the key; an exception of ``build`` raises ``RunError`` naming the run
    (the callable's exception is its ``__cause__``).
    """
    directory, h5 = _flexmech.run_study_py(
        name,
        dict(grid),
        build=build,
        figures=None if figures is None else list(figures),
        out=os.fspath(out),
        threads=threads,
        base=base,
    )
    return _summary(directory, h5)


def study_file(path: PathLike, out: PathLike = "studies", threads: Optional[int] = None) -> Summary:
    """Runs the study file at ``path`` as ``flexmech study PATH --out OUT``
    does and returns its summary."""
    directory, h5 = _flexmech.run_study_file(os.fspath(path), out=os.fspath(out), threads=threads)
    return _summary(directory, h5)
