"""Type stubs of the native module ``fbd._fbd`` (PyO3)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

TRAJECTORY_SPEC_COLUMNS: List[str]

def run(config: Any = None, out: Optional[str] = None) -> Dict[str, Any]:
    """Simulates ``config`` (planar, the hexapod's 3D dynamics or its
    kinematic gait, an imported robot ``model = "robot"``) with the GIL
    released: ``{"columns", "data", "events",
    "summary" (JSON text), "error", "source"}``; ``fbd.run`` wraps it."""
def sweep(
    sweep_config: str,
    out: str,
    jobs: Optional[int] = None,
    plot: str = "touchdown",
    viewer: bool = False,
    plots: bool = False,
) -> Tuple[str, Optional[str]]: ...
def kinematics_json(config: Any = None) -> str: ...
def inverse_json(config: Any) -> str: ...
def inverse_motion(
    config: Any, columns: List[str], values: npt.NDArray[np.float64]
) -> Tuple[List[str], npt.NDArray[np.float64]]: ...
def config_toml(config: Any = None) -> str: ...
def planar_fk(
    q: npt.NDArray[np.float64], config: Any = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def hexapod_fk(
    q: npt.NDArray[np.float64], config: Any = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def leg_ik(
    targets: npt.NDArray[np.float64],
    config: Any = None,
    leg: Optional[int] = None,
    knee: str = "up",
) -> npt.NDArray[np.float64]: ...

class SimulatorState:
    """A saved state of a :class:`Simulator` (``get_state()``); picklable."""

    @property
    def k(self) -> int:
        """Steps solved at this state."""

def step_many(
    sims: List["Simulator"],
    torques: Optional[npt.NDArray[np.float64]] = None,
    steps: int = 1,
) -> List[Optional[BaseException]]: ...
def observe_many(sims: List["Simulator"], names: Optional[List[str]] = None) -> Dict[str, Any]: ...
def simulators_many(configs: List[Any]) -> List["Simulator"]: ...
def set_pd_targets_many(
    sims: List["Simulator"],
    targets: npt.NDArray[np.float64],
    kp: Any,
    kd: Any,
    torque_limit: Optional[float] = None,
) -> None: ...

class Simulator:
    """The planar model, the 24-DOF hexapod or an imported robot
    (``model = "robot"``) stepped one Δt at a time.

    ``Simulator(config=None)`` takes a configuration like :func:`fbd.run`
    (None, a path, TOML text or a dict). ``step()`` advances with the
    PD targets of :meth:`set_pd_targets` when set, else the configured
    controller; ``step(torques)`` with the given joint torques (N·m, one
    per joint of ``joint_names``) instead, applied as given (no
    saturation). The GIL is released while stepping.
    """

    def __init__(self, config: Any = None) -> None: ...
    def set_pd_targets(
        self,
        targets: Union[Sequence[float], npt.NDArray[np.float64]],
        kp: Union[float, Sequence[float], npt.NDArray[np.float64]],
        kd: Union[float, Sequence[float], npt.NDArray[np.float64]],
        rates: Union[None, Sequence[float], npt.NDArray[np.float64]] = None,
        torque_limit: Optional[float] = None,
    ) -> None:
        """PD tracked inside Rust by ``step()`` without torques."""
    def clear_pd_targets(self) -> None: ...
    @property
    def pd_targets(self) -> Optional[Dict[str, Any]]: ...
    def get_state(self) -> SimulatorState: ...
    def set_state(self, state: SimulatorState) -> None: ...
    def copy(self) -> "Simulator": ...
    def observe(self) -> Dict[str, Any]:
        """Every readout as NumPy arrays (docs/reference.md, "Observations")."""
    @property
    def model(self) -> str:
        """``"planar"``, ``"hexapod"`` or ``"robot"``."""
    @property
    def coordinate_names(self) -> List[str]:
        """Names of the coordinates of ``q`` (``trajectory.csv``'s)."""
    @property
    def joint_names(self) -> List[str]:
        """Names of the actuated joints: the order of torques and targets."""
    @property
    def robot_name(self) -> Optional[str]:
        """An imported robot's name; None for the paper's models."""
    @property
    def body_names(self) -> List[str]:
        """An imported robot's bodies (``observe()``'s ``body_*`` rows)."""
    @property
    def reaction_names(self) -> List[str]:
        """An imported robot's joint reactions, each by its first joint."""
    @property
    def effort_limits(self) -> Optional[npt.NDArray[np.float64]]:
        """An imported robot's effort limit per joint (N·m, NaN for none)."""
    @property
    def control(self) -> Optional[Dict[str, Any]]:
        """An imported robot's ``[control]``: ``kind``, ``kp``, ``kd``,
        ``torque_limit`` (and ``targets`` for ``"pd"``)."""
    @property
    def joint_inertia(self) -> Optional[Tuple[float, str]]:
        """An imported robot's smallest effective joint inertia at ``q0``
        (kg·m², the ``I`` of the PD stability rule) and its joint."""
    def step(
        self,
        torques: Union[None, Sequence[float], npt.NDArray[np.float64]] = None,
        steps: int = 1,
    ) -> None:
        """Solves ``steps`` steps (default 1) with ``torques`` held constant
        (or the configured controller). Raises ``fbd.SimulationError``
        (``step``, ``time``) when a step fails; the simulator then refuses
        to step until :meth:`reset`."""
    def reset(self) -> None:
        """Back to the initial state of the configuration."""
    @property
    def t(self) -> float:
        """Time of the current state ``q``: ``k·Δt`` (s)."""
    @property
    def k(self) -> int:
        """Steps solved so far; the current state is ``q[k]``."""
    @property
    def dt(self) -> float:
        """Time step Δt (s)."""
    @property
    def steps(self) -> int:
        """Steps of the configured duration, ``round(duration/dt) + 1``."""
    @property
    def past_duration(self) -> bool:
        """Whether ``k ≥ steps − 1``: ``step()`` goes on past the configured
        duration (it only bounds :func:`fbd.run`)."""
    @property
    def q(self) -> npt.NDArray[np.float64]:
        """``q[k]`` (m, rad): the planar ``(Rx, Ry, φz, θ2₃, θ3₃, θ2₄,
        θ3₄)``, the hexapod's 24 coordinates, an imported robot's root
        ``(R, φ)`` then its joint angles (``coordinate_names``)."""
    @property
    def qdot(self) -> npt.NDArray[np.float64]:
        """``(q[k] − q[k−1])/Δt`` (the initial velocity at k = 0): the rate
        the built-in PD controller uses."""
    @property
    def q0(self) -> npt.NDArray[np.float64]:
        """The initial configuration ``q[0]``."""
    @property
    def contact_points(self) -> List[str]:
        """Contact point names, e.g. ``["tip3", "tip4", "knee3", ...]``."""
    @property
    def contact_states(self) -> npt.NDArray[np.uint8]:
        """1 (ST1, free), 2 (ST2, sticking), 3 (ST3, sliding) per point at
        the last solved step (the initial states before any step)."""
    @property
    def contact_forces(self) -> npt.NDArray[np.float64]:
        """Planar: ``(Fa, N)`` per point at the last solved step (N), shape
        ``(points, 2)``, along the terrain tangent and normal; hexapod and
        imported robot: the ground's force, inertial, ``(points, 3)``."""
    @property
    def contact_positions(self) -> npt.NDArray[np.float64]:
        """Planar: inertial ``(x, y)`` of each point at the last solved
        step (m); hexapod and imported robot: ``(x, y, z)`` at ``q[k]``."""
    @property
    def joint_forces(self) -> npt.NDArray[np.float64]:
        """At the last solved step (N, parent on child, inertial frame):
        planar ``(Fx, Fy)`` of hip3, knee3, hip4, knee4, shape ``(4, 2)``;
        hexapod hip and knee per leg ``(legs, 2, 3)``; imported robot per
        reaction ``(reactions, 3)``."""
    @property
    def joint_torques(self) -> npt.NDArray[np.float64]:
        """Torques applied at the last solved step (N·m)."""
    @property
    def energy(self) -> Optional[Tuple[float, float]]:
        """``(kinetic, potential)`` at the last solved step (J)."""
    @property
    def events(self) -> List[Dict[str, Any]]:
        """Events so far (``t``, ``step``, ``leg``, ``point``, ``from``,
        ``to``; an imported robot's without ``leg``)."""
