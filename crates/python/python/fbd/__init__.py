"""fbd — legged robots by the Free Body Diagram method, from Python.

Run the simulator on a configuration (a path, a TOML string or a dict with
the keys of the configuration files), step it from a Python control loop,
run sweeps in parallel, and evaluate the kinematics:

>>> import fbd
>>> r = fbd.run({"time": {"duration": 0.3}})       # the paper's fall
>>> r["ry"][:3]                                      # a column as a NumPy array
array([0.6      , 0.5995095, 0.598038 ])
>>> [(e["t"], e["leg"], e["to"]) for e in r.events][:2]   # touchdowns
[(0.19, 4, 'ST2'), (0.21, 3, 'ST2')]

The GIL is released while simulating, so Python threads (e.g.
``concurrent.futures.ThreadPoolExecutor``) run simulations in parallel.
"""

from __future__ import annotations

import csv as _csv
import json as _json
import os as _os
from collections.abc import Mapping as _Mapping
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as _np

from . import _fbd
from ._errors import ConfigError, SimulationError
from ._fbd import Simulator, SimulatorState, observe_many, set_pd_targets_many, simulators_many, step_many

__all__ = [
    "ConfigError",
    "Result",
    "SimulationError",
    "Simulator",
    "SimulatorState",
    "SweepResult",
    "config_toml",
    "hexapod_fk",
    "inverse",
    "kinematics",
    "leg_ik",
    "observe_many",
    "planar_fk",
    "run",
    "set_pd_targets_many",
    "simulators_many",
    "step_many",
    "sweep",
]

__version__ = "0.1.0"


def __dir__() -> List[str]:
    """The public API only (``dir(fbd)``), not the imported helpers."""
    return sorted(__all__ + ["__version__"])

#: What a configuration may be: None (the built-in default experiment), a
#: path, TOML text, or a dict with the keys of the files.
ConfigLike = Union[None, str, "_os.PathLike[str]", _Mapping[str, Any]]


class Result(_Mapping):
    """The outcome of :func:`run`: every column of ``trajectory.csv``.

    ``result["rx"]`` is a column as a NumPy array (float64; the state
    columns ``state3``, ``tip``/``knee``/``hip`` ``*_state`` are string
    arrays of ``"ST1"``, ``"ST2"``, ``"ST3"``; ``newton_iterations`` is
    int64). Values are those of the CLI's file, bit for bit.

    A hexapod running the 3D FBD dynamics has the columns of its
    ``trajectory.csv``: ``t``, the body pose ``rx`` … ``phi_z``,
    ``theta{1,2,3}_{n}`` of each leg n of the model, per leg the foot
    ``foot{n}_x/y/z``, its state ``state{n}`` (strings as above), the
    ground's force on it ``foot{n}_fx/fy/fz`` and normal ``foot{n}_n``,
    the hip and knee forces and moments ``hip{n}_fx`` … ``knee{n}_mz`` and
    the torques ``tau{1,2,3}_{n}``; the knee and hip contact points
    ``kneepoint{n}_state/fx/fy/fz/n`` (``hippoint…``); ``kinetic``,
    ``potential``, ``newton_iterations`` (int64). The kinematic gait's
    columns are all float64. An imported robot (``model = "robot"``) has
    the columns of its ``trajectory.csv``: ``t``, ``rx`` … ``phi_z``, its
    joint angles by name, per reaction ``<joint>_fx`` … ``<joint>_mz``,
    ``tau_<joint>``, per contact point ``<c>_state`` (strings as above),
    ``<c>_x/y/z``, ``<c>_fx/fy/fz``, ``<c>_n``; ``com_x/y/z``,
    ``kinetic``, ``potential``, ``newton_iterations`` (int64).

    Attributes:
        columns: the column names, in the file's order.
        events: contact, joint-limit and retried-step events, dicts with
            ``t``, ``step``, ``leg``, ``point``, ``from``, ``to`` (as
            ``events.csv``; also for the hexapod's 3D dynamics; an imported
            robot's without ``leg``: ``point`` is a contact point,
            ``<joint>_limit`` or ``substeps``); for the
            hexapod's kinematic gait lift-offs, touchdowns and stability
            warnings, dicts with ``t``, ``leg``, ``event``, ``margin``.
        summary: the content of ``summary.json`` as a dict.
        source: the configuration's name (a file, ``<string>``, ``<dict>``).
        error: None, or the message of the error that stopped the run (then
            the columns hold the steps solved before it).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.columns: List[str] = list(raw["columns"])
        data = raw["data"]
        self._data: Dict[str, _np.ndarray] = {}
        for name in self.columns:
            v = data[name]
            self._data[name] = v if isinstance(v, _np.ndarray) else _np.array(v, dtype="<U3")
        self.events: List[Dict[str, Any]] = list(raw["events"])
        self.summary: Dict[str, Any] = _json.loads(raw["summary"])
        self.source: str = raw["source"]
        err = raw.get("error")
        self.error: Optional[str] = None if err is None else err["message"]

    def __getitem__(self, name: str) -> _np.ndarray:
        try:
            return self._data[name]
        except KeyError:
            raise KeyError(
                f"{name!r}: no such column (columns: {', '.join(self.columns)})"
            ) from None

    def __iter__(self) -> Iterator[str]:
        return iter(self.columns)

    def __len__(self) -> int:
        return len(self.columns)

    @property
    def rows(self) -> int:
        """Rows (written steps) of the trajectory."""
        return len(self._data["t"]) if "t" in self._data else 0

    def to_pandas(self) -> "Any":
        """The trajectory as a ``pandas.DataFrame`` (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the env
            raise ImportError("Result.to_pandas() needs pandas: pip install pandas") from e
        return pd.DataFrame({c: self._data[c] for c in self.columns}, columns=self.columns)

    def __repr__(self) -> str:
        status = "ok" if self.error is None else "error"
        return f"<fbd.Result {self.source}: {self.rows} rows, {len(self.events)} events, {status}>"


def run(config: ConfigLike = None, out: Union[None, str, "_os.PathLike[str]"] = None) -> Result:
    """Simulates ``config`` and returns its :class:`Result`.

    Args:
        config: None (the built-in default experiment: the paper's §6
            fall), a path to a TOML file, TOML text, or a dict with the
            same keys as the files, e.g. ``{"time": {"duration": 0.5}}``.
            A hexapod (``model = "hexapod"``) runs as ``fbd run`` runs it:
            the 3D FBD dynamics, or the kinematic gait; so does an imported
            robot (``model = "robot"``, on its terrain or in flight).
        out: when given, the directory where the files of ``fbd run`` are
            written (``trajectory.csv``, ``events.csv``, ``summary.json``,
            ``config.toml`` and the plots); nothing is written otherwise.

    Raises:
        ConfigError: the configuration is invalid (names file, line, key).
        SimulationError: the run stopped; ``e.result`` holds the rows solved
            before, and with ``out`` every file is written as well.
        OSError: a file could not be read or written.

    The GIL is released while simulating.
    """
    raw = _fbd.run(config, None if out is None else _os.fspath(out))
    result = Result(raw)
    err = raw.get("error")
    if err is not None:
        raise SimulationError(err["message"], step=err["step"], time=err["t"], result=result)
    return result


def config_toml(config: ConfigLike = None) -> str:
    """The complete configuration with every key and its value, as ``fbd
    run`` writes ``config.toml`` (validates ``config`` first)."""
    return _fbd.config_toml(config)


def kinematics(config: ConfigLike = None) -> Dict[str, Any]:
    """Hip, knee and tip of every leg at the configuration's initial state,
    inertial frame (m): the JSON of ``fbd kinematics`` as Python objects,
    ``{"legs": [{"leg": 3, "hip": [x, y, z], "knee": ..., "tip": ...}, ...]}``.
    For an imported robot (``model = "robot"``): every body, joint and
    contact point (``{"robot", "mass", "com", "bodies", "joints",
    "contacts", ...}``, docs/reference.md).
    """
    return _json.loads(_fbd.kinematics_json(config))


def inverse(config: ConfigLike, motion: Any = None) -> Dict[str, Any]:
    """Inverse dynamics of an imported robot (``model = "robot"``) by the FBD
    method, as ``fbd inverse``.

    Without ``motion``: for the configuration's state and ``[inverse]``
    accelerations, ``{"base_force", "base_moment", "joints": [{"name",
    "force", "moment", "torque", "constraint_moment"}, ...]}`` (N, N·m,
    inertial frame). With ``motion`` (a mapping of column name to values,
    e.g. a pandas DataFrame: ``t``, one column per joint in rad, optionally
    ``rx, ry, rz, phi_x, phi_y, phi_z``): the forces at every interior
    sample as a dict of NumPy columns (``t``, ``base_fx`` …, ``tau_<joint>``,
    ``<joint>_fx`` …), velocities and accelerations by central differences.
    """
    if motion is None:
        return _json.loads(_fbd.inverse_json(config))
    columns = [str(c) for c in (motion.keys() if isinstance(motion, _Mapping) else motion.columns)]
    values = _np.column_stack([_np.asarray(motion[c], dtype=_np.float64) for c in columns])
    names, table = _fbd.inverse_motion(config, columns, values)
    return {name: table[:, i] for i, name in enumerate(names)}


def _rows(a: Any, width: int, name: str) -> Tuple[_np.ndarray, bool]:
    arr = _np.ascontiguousarray(_np.asarray(a, dtype=_np.float64))
    single = arr.ndim == 1
    if single:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"{name}: expected shape ({width},) or (N, {width}), got {_np.shape(a)}")
    return arr, single


def planar_fk(q: Any, config: ConfigLike = None) -> Dict[str, _np.ndarray]:
    """Forward kinematics of the planar model.

    Args:
        q: ``(Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)`` (m, rad), shape ``(7,)`` or
            ``(N, 7)``.
        config: the geometry (body side, link lengths); default the built-in.

    Returns:
        ``{"hip", "knee", "tip"}``, each of shape ``(2, 2)`` or ``(N, 2, 2)``:
        legs 3 and 4, ``(x, y)`` in the inertial frame (m).
    """
    arr, single = _rows(q, 7, "q")
    hip, knee, tip = _fbd.planar_fk(arr, config)
    out = {"hip": hip, "knee": knee, "tip": tip}
    return {k: v[0] for k, v in out.items()} if single else out


def hexapod_fk(q: Any, config: ConfigLike = None) -> Dict[str, _np.ndarray]:
    """Forward kinematics of the 24-DOF hexapod (D-H, eqs. 1–5).

    Args:
        q: ``(Rx, Ry, Rz, φx, φy, φz)`` then ``(θ1, θ2, θ3)`` of legs 1–6
            (m, rad), shape ``(24,)`` or ``(N, 24)``.
        config: the geometry (body side, link lengths); default the built-in.

    Returns:
        ``{"hip", "knee", "tip"}``, each of shape ``(6, 3)`` or
        ``(N, 6, 3)``: legs 1–6, inertial ``(x, y, z)`` (m).
    """
    arr, single = _rows(q, 24, "q")
    hip, knee, tip = _fbd.hexapod_fk(arr, config)
    out = {"hip": hip, "knee": knee, "tip": tip}
    return {k: v[0] for k, v in out.items()} if single else out


def leg_ik(
    targets: Any,
    config: ConfigLike = None,
    leg: Optional[int] = None,
    knee: str = "up",
) -> _np.ndarray:
    """Inverse kinematics of one leg: ``(θ1, θ2, θ3)`` (rad) placing the tip
    at each target.

    Args:
        targets: tip positions, shape ``(3,)`` or ``(N, 3)`` (m): in the leg
            base frame (eq. 1) when ``leg`` is None, else in body
            coordinates for hexapod leg ``leg`` (1–6).
        config: the geometry; default the built-in.
        knee: ``"up"`` (θ3 in [π, 2π], the paper's posture) or ``"down"``.

    Raises:
        ValueError: a target is out of reach or on the hip axis (names the
            row).
    """
    arr, single = _rows(targets, 3, "targets")
    out = _fbd.leg_ik(arr, config, leg, knee)
    return out[0] if single else out


class SweepResult:
    """The outcome of :func:`sweep`.

    Attributes:
        out: the output directory (``index.csv``, ``sweep.json``,
            ``sweep.svg``, ``runs/<i>/``).
        index: the columns of ``index.csv``: NumPy float arrays where every
            value is a number (empty cells are NaN), lists of str otherwise.
        failed: None, or the message naming the runs that failed.
        message: what ``fbd sweep`` prints.
    """

    def __init__(self, out: str, message: str, failed: Optional[str]) -> None:
        self.out = out
        self.message = message
        self.failed = failed
        self.index: Dict[str, Union[_np.ndarray, List[str]]] = {}
        with open(_os.path.join(out, "index.csv"), newline="") as f:
            rows = list(_csv.reader(f))
        header, body = rows[0], rows[1:]
        for i, name in enumerate(header):
            cells = [r[i] if i < len(r) else "" for r in body]
            try:
                self.index[name] = _np.array(
                    [float(c) if c != "" else _np.nan for c in cells], dtype=_np.float64
                )
            except ValueError:
                self.index[name] = cells

    @property
    def runs(self) -> int:
        """Runs listed in ``index.csv``."""
        return len(next(iter(self.index.values()), []))

    def __repr__(self) -> str:
        return f"<fbd.SweepResult {self.out}: {self.runs} runs, {'ok' if self.failed is None else 'some failed'}>"


def sweep(
    sweep_config: Union[str, "_os.PathLike[str]"],
    out: Union[str, "_os.PathLike[str]"],
    jobs: Optional[int] = None,
    viewer: bool = False,
    plots: bool = False,
) -> SweepResult:
    """Runs a sweep file (the format of ``fbd sweep``) into ``out`` on
    ``jobs`` threads (every core by default), with the GIL released.

    Failed runs do not raise: they are rows of ``index.csv`` with their
    error, and ``SweepResult.failed`` says which. Each run's ``viewer.html``
    and plots are written only with ``viewer=True``, ``plots=True`` (as
    ``fbd sweep --viewer --plots``).

    Raises:
        ConfigError: the sweep file or its base configuration is invalid.
        OSError: the output directory cannot be written.
    """
    out = _os.fspath(out)
    message, failed = _fbd.sweep(
        _os.fspath(sweep_config), out, jobs, viewer=viewer, plots=plots
    )
    return SweepResult(out, message, failed)


def _register_gym() -> None:
    """Registers the Gymnasium environments (``fbd.gym``) when gymnasium is
    installed; ``import fbd`` works without it."""
    try:
        import gymnasium  # noqa: F401
    except ImportError:
        return
    from . import gym as _gym

    _gym.register_envs()


_register_gym()
