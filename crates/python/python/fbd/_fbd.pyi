"""Type stubs of the native module ``fbd._fbd`` (PyO3)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

TRAJECTORY_SPEC_COLUMNS: List[str]

def run(config: Any = None, out: Optional[str] = None) -> Dict[str, Any]:
    """Simulates ``config`` (planar, the hexapod's 3D dynamics or its
    kinematic gait) with the GIL released: ``{"columns", "data", "events",
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

class Simulator:
    """The planar model stepped one Δt at a time.

    ``Simulator(config=None)`` takes a configuration like :func:`fbd.run`
    (None, a path, TOML text or a dict). ``step()`` advances with the
    configured controller; ``step(torques)`` with the given joint torques
    (N·m: hip3, knee3, hip4, knee4) instead, applied as given (no
    saturation). The GIL is released while stepping.
    """

    def __init__(self, config: Any = None) -> None: ...
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
        """``q[k] = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)`` (m, rad)."""
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
        """``(Fa, N)`` per point at the last solved step (N), shape
        ``(points, 2)``, along the terrain tangent and normal."""
    @property
    def contact_positions(self) -> npt.NDArray[np.float64]:
        """Inertial ``(x, y)`` of each point at the last solved step (m)."""
    @property
    def joint_forces(self) -> npt.NDArray[np.float64]:
        """``(Fx, Fy)`` of hip3, knee3, hip4, knee4 at the last solved step
        (N, parent on child, inertial frame), shape ``(4, 2)``."""
    @property
    def joint_torques(self) -> npt.NDArray[np.float64]:
        """Torques applied at the last solved step (N·m)."""
    @property
    def energy(self) -> Optional[Tuple[float, float]]:
        """``(kinetic, potential)`` at the last solved step (J)."""
    @property
    def events(self) -> List[Dict[str, Any]]:
        """Contact events so far (``t``, ``step``, ``leg``, ``point``,
        ``from``, ``to``)."""
