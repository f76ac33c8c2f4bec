"""Type stubs of the extension module ``flexmech._flexmech`` (the Rust part of
the package; ``flexmech`` re-exports ``Model``, ``Simulation``,
``ModelError``, ``RunError`` and ``joint_kinds``)."""

import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Value = Union[bool, int, float, str, Sequence[Any], Mapping[str, Any], np.generic, np.ndarray]
_Vector = Union[Sequence[float], npt.NDArray[np.float64]]

__version__: str

class ModelError(ValueError):
    """A model was refused: a model file, text or builder call, a key set
    with ``Model.set``, or a run's model in a study. ``str(e)`` is the
    located message (``file:line: key `solver.dt`: ...``)."""

    key: str
    """The key path (``solver.dt``, ``joint[0].pitch``); empty when the
    error concerns the whole model."""
    file: Optional[str]
    """The model file or text name (None for a model built in Python)."""
    line: Optional[int]
    """The 1-based line in that file or text, where known."""
    message: str
    """The message without its location."""

class RunError(RuntimeError):
    """A run, stepping or study could not go on for a reason other than its
    model: a file that cannot be written or read, a restart of another
    mechanism, a study function that raised (its exception is
    ``__cause__``), a solver stopping under ``Simulation.step``."""

class Model:
    """A model: its model-file tables (docs/MODEL_FORMAT.md), read from a
    file or text or written with builder calls, checked by the model-file
    validation before it runs. Builder calls and ``set`` change the model
    in place and return it, so calls chain."""

    def __init__(self, name: str) -> None:
        """A model named ``name`` (its result file is ``<name>.h5``) to be
        written with builder calls: ``Model("arm").section(...).beam(...)``."""
    @staticmethod
    def load(path: _Path) -> Model:
        """Reads and checks the model file at ``path``; raises ``ModelError``
        with its file, line and key."""
    @staticmethod
    def from_toml(text: str, path: Optional[_Path] = None) -> Model:
        """Reads and checks model-file ``text``; ``path`` names it in
        messages (default ``<string>``)."""
    def to_toml(self) -> str:
        """The model as model-file text (the text it was read from while
        unchanged)."""
    def to_dict(self) -> Dict[str, Any]:
        """The model's tables as a dict (a copy)."""
    @property
    def name(self) -> str:
        """The model's name."""
    @property
    def file(self) -> Optional[str]:
        """The file or text name it was read from (None when built)."""
    def set(self, key: str, value: _Value) -> Model:
        """Sets the value at the study key path ``key`` (``solver.dt``,
        ``joint.screw.pitch``, ``beam[0].elements``, ``section.rod.EI[0]``);
        a missing key of an existing table is added. A valid model must stay
        valid: otherwise nothing changes and ``ModelError`` names the key."""
    def get(self, key: str) -> Any:
        """The value at the study key path ``key``."""
    def check(self) -> Model:
        """Checks the model as a model file is checked (``ModelError``)."""
    def build(self) -> Model:
        """The same as ``check`` (the Rust builder's last call)."""
    def copy(self) -> Model:
        """A copy that changes independently."""
    def gravity(self, g: _Vector) -> Model:
        """Gravity's acceleration."""
    def section(
        self,
        name: str,
        *,
        EA: float,
        GA: _Vector,
        GJ: float,
        EI: _Vector,
        rhoA: Optional[float] = None,
        rhoJ: Optional[_Vector] = None,
        damping: Optional[float] = None,
        **keys: _Value,
    ) -> Model:
        """A ``[[section]]``: stiffnesses and masses per unit length."""
    def beam(
        self,
        name: str,
        section: str,
        *,
        elements: int,
        start: Optional[_Vector] = None,
        end: Optional[_Vector] = None,
        e2: Optional[_Vector] = None,
        arc: Optional[Mapping[str, Any]] = None,
        nodes_per_element: Optional[int] = None,
        **keys: _Value,
    ) -> Model:
        """A ``[[beam]]``, straight (``start``, ``end``, ``e2``) or an
        ``arc``; its nodes are ``name.start``, ``name.1``, ..., ``name.end``."""
    def support(self, node: str, fixed: Optional[Union[str, Sequence[str]]] = None) -> Model:
        """A ``[[support]]``: ``fixed`` is ``"all"`` (default), ``"ux, rz"`` or
        a list of DOF names."""
    def joint(
        self,
        name: str,
        kind: str,
        master: str,
        slave: str,
        params: Optional[Union[str, Mapping[str, Any]]] = None,
        **keys: _Value,
    ) -> Model:
        """A ``[[joint]]`` of a registered kind (``joint_kinds()``); its
        parameters as keywords, a dict or model-file text."""
    def nodal_load(
        self,
        node: str,
        force: Optional[_Vector] = None,
        moment: Optional[_Vector] = None,
        *,
        time: Optional[_Value] = None,
        follower: Optional[bool] = None,
        **keys: _Value,
    ) -> Model:
        """A ``[[load]]`` on ``node`` (the Rust builder's ``load``)."""
    def distributed_load(
        self,
        beam: str,
        force: Optional[_Vector] = None,
        moment: Optional[_Vector] = None,
        *,
        time: Optional[_Value] = None,
        follower: Optional[bool] = None,
        **keys: _Value,
    ) -> Model:
        """A ``[[distributed_load]]`` per unit length on ``beam``."""
    def drive(self, joint: str, angle: Union[str, float, Mapping[str, Any]]) -> Model:
        """A ``[[prescribed]]`` released angle of ``joint``: an expression of
        ``t``, a number or a time-function dict."""
    def add(self, array: str, **keys: _Value) -> Model:
        """Any other entry of an array of tables (``"prescribed"``, ...)."""
    def rigid_body(
        self,
        node: str,
        mass: float,
        *,
        inertia: Optional[_Value] = None,
        offset: Optional[_Vector] = None,
        name: Optional[str] = None,
    ) -> Model:
        """A ``[[rigid_body]]`` carried by ``node``."""
    def initial_velocity(
        self,
        nodes: Union[str, Sequence[str]],
        *,
        linear: Optional[_Vector] = None,
        angular: Optional[_Vector] = None,
        origin: Optional[_Vector] = None,
    ) -> Model:
        """An ``[[initial_velocity]]`` field on a beam or a list of nodes."""
    def statics(self, load_steps: int, **keys: _Value) -> Model:
        """Statics in ``load_steps`` load steps (``control="arc-length"``...)."""
    def dynamic(self, integrator: str, dt: float, t_end: float, **keys: _Value) -> Model:
        """Time integration with ``integrator`` in steps of ``dt`` to ``t_end``."""
    def modal(self, modes: int, **keys: _Value) -> Model:
        """The ``modes`` lowest vibration modes (``analysis = "modal"``), under ``/modes``."""
    def buckling(self, modes: int, **keys: _Value) -> Model:
        """The ``modes`` lowest linear buckling load factors (``analysis = "buckling"``)."""
    def solver(self, key: Optional[str] = None, value: Optional[_Value] = None, **keys: _Value) -> Model:
        """``[solver]`` keys: ``solver("tolerance", 1e-8)`` or ``solver(tolerance=1e-8)``."""
    def output(self, key: Optional[str] = None, value: Optional[_Value] = None, **keys: _Value) -> Model:
        """``[output]`` keys: ``output(every=10)``."""
    def track(self, *nodes: str) -> Model:
        """Records ``nodes`` under ``/nodes/<label>`` of the result."""
    def sensitivity(self, *keys: str) -> Model:
        """Writes the exact derivatives of the results with respect to the
        model values at ``keys`` (``"section.rod.EI[0]"``,
        ``"load[0].force[2]"``) under ``/sensitivity/<key>/...``."""

class Simulation:
    """A dynamic model stepped from Python; its state as the rows of the
    result file's ``/configuration`` datasets."""

    def __init__(self, model: Model) -> None:
        """Starts ``model`` at t = 0 as a run starts it."""
    @staticmethod
    def restart(model: Model, path: _Path) -> Simulation:
        """Continues the run stored in the result file ``path`` (its
        ``/restart`` state) with ``model``, as ``flexmech run --restart``."""
    def step(self) -> bool:
        """One converged step; False (no step) once ``t_end`` is reached.
        Raises ``RunError`` when the solver stops."""
    def run_until(self, t: float) -> int:
        """Steps until the time reaches ``t`` (or ``t_end``); the number of
        steps taken."""
    def run(self) -> int:
        """Steps to ``t_end``; the number of steps taken."""
    @property
    def time(self) -> float:
        """The current time."""
    @property
    def t_end(self) -> float:
        """The model's end time."""
    @property
    def steps(self) -> int:
        """Converged steps taken."""
    @property
    def status(self) -> str:
        """``"running"``, ``"completed"`` or ``"failed: ..."``."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Every node's position (nodes × 3), a ``/configuration/position`` row."""
    @property
    def quaternions(self) -> npt.NDArray[np.float64]:
        """Every node's triad as (w, x, y, z) (nodes × 4), a
        ``/configuration/quaternion`` row."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """Every node's velocity (nodes × 3), a ``/configuration/velocity`` row."""
    @property
    def angular_velocities(self) -> npt.NDArray[np.float64]:
        """Every node's spatial angular velocity (nodes × 3), a
        ``/configuration/angular_velocity`` row."""
    @property
    def node_labels(self) -> List[str]:
        """Every node's label in ``/configuration`` order."""
    @property
    def energy(self) -> Dict[str, float]:
        """``kinetic``, ``strain``, ``potential``, ``total``, ``driver_work``."""
    def save(self, path: _Path) -> str:
        """Writes the kept steps and the ``/restart`` state into the result
        file ``path`` (``status`` ``"running"`` before ``t_end``)."""

def joint_kinds() -> List[str]:
    """The joint kinds a model can name."""

def run_model(
    model: Model, out: Optional[str] = None
) -> Tuple[Optional[str], Dict[str, Any], Dict[str, Dict[str, Any]], Optional[str]]:
    """The engine of ``flexmech.run``: (file, datasets, attributes, error)."""

def read_h5(path: _Path) -> Tuple[Dict[str, Any], Dict[str, Dict[str, Any]]]:
    """Every dataset and attribute of an HDF5 file."""

def run_study_py(
    name: str,
    grid: Mapping[str, Sequence[Any]],
    build: Optional[Callable[[Dict[str, Any]], Model]] = None,
    figures: Optional[Sequence[Union[str, Mapping[str, Any]]]] = None,
    out: Optional[str] = None,
    threads: Optional[int] = None,
    base: Optional[Model] = None,
) -> Tuple[str, str]:
    """The engine of ``flexmech.study``: (directory, summary.h5)."""

def run_study_file(path: _Path, out: Optional[str] = None, threads: Optional[int] = None) -> Tuple[str, str]:
    """The engine of ``flexmech.study_file``: (directory, summary.h5)."""
