"""`Result`: the datasets and attributes of one run, as NumPy arrays under
the names of the result-file contract (docs/MODEL_FORMAT.md)."""

from __future__ import annotations

import difflib
import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _flexmech

_COMPONENTS = {"x": 0, "y": 1, "z": 2, "w": 0}


def _as_array(value: Any) -> np.ndarray:
    """A dataset as NumPy: strings become an object array of str (as
    h5py's ``asstr()`` reads them)."""
    if isinstance(value, list):
        out = np.empty(len(value), dtype=object)
        out[:] = value
        return out
    return value


def _split_column(name: str) -> Tuple[str, Optional[str]]:
    """``"/nodes/tip/position[z]"`` -> ``("/nodes/tip/position", "z")``."""
    if name.endswith("]") and "[" in name:
        head, _, col = name[:-1].rpartition("[")
        return head, col.strip()
    return name, None


class Result(Mapping[str, np.ndarray]):
    """One run's result: every dataset of its result file as a NumPy array,
    keyed by the contract's path (``"/time"``, ``"/energy/total"``,
    ``"/nodes/arm.end/position"``, ``"/configuration/quaternion"``, ...), and
    its attributes.

    A run that the solver stopped part-way is a result too: every step
    computed before the failure, with ``status == "failed: ..."``.

    >>> result = flexmech.run(flexmech.Model.load("data/paper/screw_driven.toml"))
    >>> result.time.shape, result["/nodes/arm.end/position"].shape
    """

    def __init__(
        self,
        datasets: Dict[str, Any],
        attributes: Dict[str, Dict[str, Any]],
        file: Optional[str] = None,
        error: Optional[str] = None,
    ) -> None:
        self._data = {k: _as_array(v) for k, v in datasets.items()}
        self._attributes = attributes
        self._file = file
        self._error = error

    @classmethod
    def load(cls, path: Union[str, "os.PathLike[str]"]) -> "Result":
        """Reads the result file at ``path`` (any flexmech result file,
        written by ``flexmech run``, ``flexmech.run(..., out=DIR)``,
        ``Simulation.save`` or a study)."""
        datasets, attributes = _flexmech.read_h5(os.fspath(path))
        return cls(datasets, attributes, file=os.fspath(path))

    # -- the mapping of datasets ------------------------------------------
    def _key(self, name: str) -> str:
        return name if name.startswith("/") else "/" + name

    def __getitem__(self, name: str) -> np.ndarray:
        """The dataset ``name`` (``"/nodes/arm.end/position"``; the leading
        ``/`` may be left out; ``"...[z]"`` or ``"...[2]"`` takes a column)."""
        path, column = _split_column(name)
        key = self._key(path)
        if key not in self._data:
            close = difflib.get_close_matches(key, list(self._data), n=3, cutoff=0.5)
            hint = f"; did you mean {', '.join(close)}?" if close else ""
            raise KeyError(f"no dataset {key!r} in this result{hint} (result.keys() lists them)")
        data = self._data[key]
        if column is None:
            return data
        return data[..., self._column(key, column, data)]

    def _column(self, key: str, column: str, data: np.ndarray) -> int:
        if column.isdigit():
            k = int(column)
        elif column in _COMPONENTS:
            k = _COMPONENTS[column] + (1 if data.shape[-1] == 4 and column != "w" else 0)
        else:
            raise KeyError(f"{key}[{column}]: a column is x, y, z (w for quaternions) or an index")
        if data.ndim < 2 or not 0 <= k < data.shape[-1]:
            raise KeyError(f"{key} of shape {data.shape} has no column {column!r}")
        return k

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and self._key(name) in self._data

    # -- what the run was ------------------------------------------------
    @property
    def time(self) -> np.ndarray:
        """``/time``: the stored times (statics: load factors), shape (T,)."""
        return self._data["/time"]

    @property
    def attrs(self) -> Dict[str, Any]:
        """The root attributes: ``status``, ``model`` (the TOML text),
        ``integrator``, ``energy_drift``, ``max_displacement``,
        ``newton_iterations``, ``steps``, ``wall_time_s``, ``version``, ..."""
        return self._attributes.get("/", {})

    def attributes(self, name: str) -> Dict[str, Any]:
        """The attributes of a group or dataset (``"/nodes/arm.end"`` ->
        ``{"node_index": 12}``; a dataset's ``description``)."""
        return self._attributes.get(self._key(name).rstrip("/") or "/", {})

    def description(self, name: str) -> str:
        """The ``description`` attribute of dataset ``name``."""
        return str(self.attributes(_split_column(name)[0]).get("description", ""))

    @property
    def status(self) -> str:
        """``"completed"``, ``"failed: <reason>"`` or ``"running"``."""
        return str(self.attrs.get("status", ""))

    @property
    def completed(self) -> bool:
        """Whether the run completed."""
        return self.status == "completed"

    @property
    def failed(self) -> bool:
        """Whether the solver stopped part-way (the steps before are here)."""
        return self.status.startswith("failed")

    @property
    def error(self) -> Optional[str]:
        """The full message of a run that failed part-way (None otherwise)."""
        return self._error

    @property
    def file(self) -> Optional[str]:
        """The result file (None for a run without ``out``)."""
        return self._file

    @property
    def model(self) -> str:
        """The model text the run stored (root attribute ``model``)."""
        return str(self.attrs.get("model", ""))

    @property
    def nodes(self) -> List[str]:
        """The tracked nodes' labels (groups of ``/nodes``)."""
        return sorted({k.split("/")[2] for k in self._data if k.startswith("/nodes/")})

    @property
    def joints(self) -> List[str]:
        """The joints' names (groups of ``/joints``)."""
        return sorted({k.split("/")[2] for k in self._data if k.startswith("/joints/")})

    @property
    def node_labels(self) -> List[str]:
        """Every node's label in ``/configuration`` order."""
        labels = self._data.get("/mesh/node_labels")
        return [] if labels is None else list(labels)

    # -- linearised analyses and critical points ---------------------------
    @property
    def frequencies(self) -> np.ndarray:
        """``/modes/frequency`` of a modal run: the natural frequencies in
        cycles per unit of model time, ascending (rigid modes 0)."""
        return self["/modes/frequency"]

    @property
    def load_factors(self) -> np.ndarray:
        """``/buckling/load_factor`` of a buckling run, ascending."""
        return self["/buckling/load_factor"]

    def mode(self, k: int) -> Tuple[np.ndarray, np.ndarray]:
        """Mode ``k`` (from 1, the lowest) of a modal or buckling run: its
        nodal displacements and rotation vectors, each (nodes × 3) in
        ``/configuration`` order (modal: unit mass norm)."""
        group = "/modes" if "/modes/displacement" in self._data else "/buckling"
        u = self[f"{group}/displacement"]
        if not 1 <= k <= u.shape[0]:
            raise IndexError(f"mode {k}: this result has modes 1..{u.shape[0]} under {group}")
        return u[k - 1], self[f"{group}/rotation"][k - 1]

    @property
    def critical_points(self) -> List[Tuple[str, float]]:
        """The limit and bifurcation points a static path located
        (``/stability``): ``[("bifurcation", 0.725), ...]`` in path order,
        empty when it crossed none."""
        if "/stability/critical_load_factor" not in self._data:
            return []
        kinds = self._data["/stability/critical_kind"]
        factors = self._data["/stability/critical_load_factor"]
        return [(str(k), float(f)) for k, f in zip(kinds, factors)]

    @property
    def end_reason(self) -> Optional[str]:
        """Why a static path ended (root attribute ``end_reason``): its load
        factor reached, a ``stop`` or the step budget; None for other runs."""
        reason = self.attrs.get("end_reason")
        return None if reason is None else str(reason)

    def __repr__(self) -> str:
        name = ""
        for line in self.model.splitlines():
            if line.strip().startswith("name"):
                name = line.split("=", 1)[-1].strip()
                break
        steps = self.time.shape[0] if "/time" in self._data else 0
        status = self.status if len(self.status) <= 60 else self.status[:57] + "..."
        return f"<flexmech.Result {name} {status!r}, {steps} stored steps, {len(self)} datasets>"

    # -- charts ------------------------------------------------------------
    def plot(
        self,
        *names: str,
        x: Optional[str] = None,
        ax: Any = None,
        labels: Optional[Sequence[str]] = None,
        **kwargs: Any,
    ) -> Any:
        """Draws datasets over time (or over ``x``, a dataset name with an
        optional column, ``"/nodes/arm.end/position[x]"``) with matplotlib
        and returns the axes. A T×k dataset draws one curve per column
        unless a column is named (``"/nodes/arm.end/position[z]"``). Without
        names, ``/energy/total``. ``kwargs`` go to ``ax.plot``.

        Needs matplotlib (``pip install matplotlib``)."""
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Result.plot needs matplotlib: pip install matplotlib") from e
        if ax is None:
            _, ax = plt.subplots()
        names = names or ("/energy/total",)
        xs = self.time if x is None else self[x]
        if x is None:
            static = self.attrs.get("integrator") == "static"
            ax.set_xlabel("load factor" if static else "time")
        else:
            ax.set_xlabel(self.description(x) or x)
        n = 0
        for name in names:
            ys = self[name]
            columns = [ys] if ys.ndim == 1 else [ys[..., k] for k in range(ys.shape[-1])]
            suffix = "" if ys.ndim == 1 else ("wxyz" if ys.shape[-1] == 4 else "xyz")
            for k, y in enumerate(columns):
                label = name if ys.ndim == 1 else f"{name}[{suffix[k] if k < len(suffix) else k}]"
                if labels is not None and n < len(labels):
                    label = labels[n]
                ax.plot(xs, y, label=label, **kwargs)
                n += 1
        if len(names) == 1:
            ax.set_ylabel(self.description(names[0]) or names[0])
        if n > 1 or labels is not None:
            ax.legend()
        return ax
