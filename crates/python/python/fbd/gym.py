"""Gymnasium environments of fbd (needs ``gymnasium``, an optional
dependency: ``pip install gymnasium``). Registered on ``import fbd`` when
gymnasium is installed:

* ``fbd/HexapodWalk-v0`` — :class:`HexapodWalkEnv`: the 24-DOF hexapod
  (3D FBD dynamics, 1 kHz physics) learns to walk forward with per-joint
  PD position targets at 50 Hz; its vector entry point
  :class:`HexapodWalkVectorEnv` steps N simulators on Rust threads with the
  GIL released (``gymnasium.make_vec("fbd/HexapodWalk-v0", num_envs=N,
  vectorization_mode="vector_entry_point")``).
* ``fbd/PlanarStand-v0`` — :class:`PlanarStandEnv`: the paper's planar
  two-leg model dropped onto the ground learns to land and stand at a
  height; vector entry point :class:`PlanarStandVectorEnv`.
* ``fbd/Robot-v0`` — :class:`RobotEnv`: any imported robot
  (``model = "robot"``, URDF/MJCF) on its configured terrain learns to move
  forward with per-joint PD position targets:
  ``gymnasium.make("fbd/Robot-v0", config="examples/robots/solo12_stand.toml")``;
  vector entry point :class:`RobotVectorEnv`.

Every environment is deterministic given its seed: ``reset(seed=s)`` draws
the initial pose and the soil's friction from ``s``; equal seeds give equal
episodes, bit for bit. Environments pickle (their simulator with it).

**HexapodWalk-v0** (every layout also in ``HexapodWalkEnv.OBSERVATION_NAMES``):

* action, shape ``(18,)`` in ``[−1, 1]``: joint position targets in leg
  order (``θ1, θ2, θ3`` of leg 1, then leg 2, …), ``θ* = stance +
  ACTION_SCALE·a`` around the stance ``(0°, −20°, 290°)``
  (``ACTION_SCALE = (0.35, 0.35, 0.35)`` rad), tracked by PD inside Rust
  (``kp = 300 N·m/rad, kd = 8 N·m·s/rad, |τ| ≤ 80 N·m``) for the 20 physics
  steps of a control period;
* observation, shape ``(60,)``, float64: ``[0]`` body height ``Ry`` (m);
  ``[1:4]`` orientation ``φx, φy, φz`` (rad, SPEC §1.3); ``[4:7]`` linear and
  ``[7:10]`` angular velocity of the body in body axes (m/s, rad/s);
  ``[10:28]`` joint angles, ``[28:46]`` joint rates (leg order); ``[46:52]``
  each foot's contact state (0 free, 1 sticking, 2 sliding), ``[52:58]``
  each foot's normal force (N); ``[58:60]`` the gait clock ``sin, cos`` of
  ``2π·t/GAIT_PERIOD`` (``GAIT_PERIOD = 0.8`` s);
* reward per control period: forward speed (m/s of the body along −Z, the
  robot's forward direction at yaw 0) − ``EFFORT·Σ τ²`` (N·m, the torques of
  the period's last step, ``EFFORT = 5e-6``) − ``SLIP·Σ |v_slip|`` over the
  sliding feet (m/s; the exact slip velocity fbd solves, ``SLIP = 0.1``);
* terminated when the body touches the ground (``Ry < 0.12`` m or a hip
  contact point touches) or rolls over (the body's up axis more than 60°
  from vertical), or when a step cannot be solved (``info["error"]``);
  truncated at ``episode_seconds`` (default 2 s);
* ``reset(seed=)`` draws the body height (feet 0–3 mm above the ground),
  yaw (±5°), each joint (±2° around the stance) and the friction
  ``μS ∈ [0.6, 1.0]``, ``μD = 0.8·μS``.

**Robot-v0** (``RobotEnv(config, ...)``; names of every entry in
``env.observation_names``):

* physics: the configuration's own (its ``[time] dt``, terrain, friction,
  initial state); a control period is ``frame_skip`` physics steps,
  ``round(1/(control_hz·dt))`` by default (``control_hz = 50``);
* action, shape ``(joints,)`` in ``[−1, 1]``, joints in model order
  (``Simulator.joint_names``): PD targets ``θ* = q0 + action_scale·a``
  around the initial joint angles (``action_scale = 0.25`` rad), tracked
  inside Rust for the period with the gains of the configuration's
  ``[control]`` when it has some (``kind = "pd"``, ``"trajectory"`` or
  ``"gait"``; its ``torque_limit`` too);
  otherwise ``kp = 0.1·I/Δt²``, ``kd = I/Δt`` with ``I`` the robot's
  smallest effective joint inertia (``Simulator.joint_inertia``):
  ``kp·Δt²/I + 2·kd·Δt/I = 2.1``, about half of fbd's explicit-PD
  stability limit 4, the fastest joint mode damped without oscillation
  (its roots 0 and 0.9).
  Torques are clamped to ``torque_limit``, else to the smallest effort
  limit of the description's joints (if any). ``kp``, ``kd``,
  ``torque_limit`` may also be given;
* observation, shape ``(1 + 4 + 3 + 3 + 2·joints + 2·points,)``, float64:
  ``[0]`` the base's height (its root frame origin's ``y``, m); ``[1:5]``
  its orientation as a unit quaternion ``(w, x, y, z)`` (``w ≥ 0``; body
  → inertial); ``[5:8]`` its linear velocity (the root origin's, m/s) and
  ``[8:11]`` angular velocity (rad/s), both in body axes; the joint angles
  (rad) and rates (rad/s); per contact point (``Simulator.contact_points``)
  its state (0 free, 1 sticking, 2 sliding), then per point its normal
  force (N);
* reward per control period: forward speed − ``effort·Σ τ²`` (the torques
  of the period's last step, N·m; ``effort = 1e-3``). Forward is the
  robot's own: fbd's body frame has ``+y`` up and ``−z`` forward, and an
  imported robot's ``+x`` forward (ROS REP 103, ``[robot] up = "z"``, the
  default) is turned to ``−z``; the speed is the root origin's
  displacement over the period along the robot's forward axis at the
  episode's start, projected on the horizontal plane (``−Z`` for a robot
  not turned by ``[initial]``), divided by the period (m/s);
* terminated when the base's height falls below ``fall_fraction``
  (default 0.5) of its initial height, when its up axis tilts more than
  ``max_tilt_deg`` (60°) from vertical, or when a step cannot be solved
  (``info["error"]``); truncated at ``episode_seconds`` (default 2 s);
* ``reset(seed=)``: the configuration's initial state; with
  ``init_noise > 0`` (rad, default 0) the first control period tracks
  targets ``q0 + U(−init_noise, init_noise)`` drawn from the seed before
  the episode's first observation (equal seeds, equal episodes; a period
  that cannot be solved falls back to the initial state); the episode's
  ``episode_seconds`` count from that first observation.

**PlanarStand-v0**: action ``(4,)`` in ``[−1, 1]``: targets of hip3, knee3,
hip4, knee4 around ``(0°, 250°)`` per leg (``±0.5`` rad); observation
``(18,)``: ``q`` (7), ``q̇`` (7), the tips' states (2, as above) and normal
forces (2, N); reward ``1 − |Ry − 0.42|/0.1 − 1e-4·Σ τ²``; terminated when
``Ry < 0.25`` m or ``|φz| > 45°``; truncated at 2 s; ``reset`` draws the
drop height (2–8 cm) and the friction.
"""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

import gymnasium
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _fbd
from ._errors import SimulationError

__all__ = [
    "HexapodWalkEnv",
    "HexapodWalkVectorEnv",
    "PlanarStandEnv",
    "PlanarStandVectorEnv",
    "RobotEnv",
    "RobotVectorEnv",
    "register_envs",
]


def _checked_action(action: Any, shape: Tuple[int, ...], nan: bool = True) -> np.ndarray:
    """``action`` as a float64 array of the action space's ``shape``,
    clipped to [-1, 1] (±inf to the bounds); a wrong shape or (``nan``) a
    NaN is a ``ValueError`` that says which."""
    a = np.asarray(action, dtype=np.float64)
    if a.shape != shape:
        raise ValueError(f"action of shape {a.shape}, expected {shape} (the action space's)")
    if not nan:
        return a
    where = np.argwhere(np.isnan(a))
    if where.size:
        raise ValueError(f"action is NaN at index {tuple(int(i) for i in where[0])} ({len(where)} NaN in all)")
    return np.clip(a, -1.0, 1.0)


class _FbdEnv(gymnasium.Env):
    """What the environments share: a simulator stepped ``frame_skip``
    physics steps per action with PD targets; subclasses define the task
    (``_config``, ``_targets``, ``_observe``, ``_reward``, ``_terminated``)."""

    metadata: Dict[str, Any] = {"render_modes": []}
    #: Simulated time at the episode's first observation (s).
    _t0 = 0.0
    KP = 300.0
    KD = 8.0
    TORQUE_LIMIT: Optional[float] = 80.0

    def __init__(self, episode_seconds: float = 2.0, frame_skip: int = 20, dt: float = 0.001) -> None:
        self.episode_seconds = float(episode_seconds)
        self.frame_skip = int(frame_skip)
        self.dt = float(dt)
        self.sim: Optional[_fbd.Simulator] = None
        self._error: Optional[str] = None

    # -- the task --------------------------------------------------------
    # Each rule is written once, on a batch: ``o`` holds the fields
    # ``OBSERVED`` of ``_fbd.observe_many`` (a leading axis of N
    # simulators), ``before`` the N states ``q`` before the period; a
    # single environment is the batch of one, and the vector environment
    # evaluates its N sub-environments in one call of each.
    #: The fields of ``Simulator.observe()`` the task reads.
    OBSERVED: Tuple[str, ...] = ("t", "q")

    def _config(self) -> Dict[str, Any]:  # pragma: no cover - abstract
        raise NotImplementedError

    def _targets(self, a: np.ndarray) -> np.ndarray:  # pragma: no cover
        """PD targets of the actions ``a`` (N, actions), clipped to [−1, 1]."""
        raise NotImplementedError

    def _observe(self, o: Dict[str, np.ndarray]) -> np.ndarray:  # pragma: no cover
        """The observations, shape (N, size)."""
        raise NotImplementedError

    def _reward(self, o: Dict[str, np.ndarray], before: np.ndarray) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:  # pragma: no cover
        """The rewards (N,) and the info entries (each (N,))."""
        raise NotImplementedError

    def _terminated(self, o: Dict[str, np.ndarray]) -> np.ndarray:  # pragma: no cover
        """Whether each episode ended, (N,) bool."""
        raise NotImplementedError

    def _gains(self) -> Tuple[Any, Any, Optional[float]]:
        """``kp``, ``kd`` and the torque limit of the PD targets."""
        return self.KP, self.KD, self.TORQUE_LIMIT

    # -- the loop --------------------------------------------------------
    def _observation(self) -> np.ndarray:
        return self._observe(_fbd.observe_many([self.sim], list(self.OBSERVED)))[0]

    def _start(self) -> Tuple[np.ndarray, Dict[str, Any]]:
        self._adopt(_fbd.Simulator(self._config()))
        return self._observation(), {}

    def _adopt(self, sim: "_fbd.Simulator") -> None:
        """Takes ``sim``, built from ``_config()``, as the episode's simulator."""
        self.sim = sim
        self._error = None
        self._new_simulator()

    def _new_simulator(self) -> None:
        """After a new simulator is built (indices of its points)."""

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None):
        super().reset(seed=seed)
        return self._start()

    def _apply(self, action: Any) -> np.ndarray:
        """Sets the PD targets of ``action``; the state before the step."""
        a = _checked_action(action, self.action_space.shape)
        kp, kd, limit = self._gains()
        self.sim.set_pd_targets(self._targets(a[None])[0], kp, kd, torque_limit=limit)
        return self.sim.q

    def _finish(self, before: np.ndarray, error: Optional[BaseException]):
        if error is not None:
            self._error = str(error)
        o = _fbd.observe_many([self.sim], list(self.OBSERVED))
        obs = self._observe(o)[0]
        if self._error is not None:
            return obs, 0.0, True, False, {"error": self._error}
        reward, info = self._reward(o, before[None])
        terminated = bool(self._terminated(o)[0])
        truncated = (not terminated) and self.sim.t - self._t0 >= self.episode_seconds - 0.5 * self.dt
        return obs, float(reward[0]), terminated, truncated, {k: float(v[0]) for k, v in info.items()}

    def step(self, action: Any):
        if self.sim is None:
            raise RuntimeError("call reset() before step()")
        before = self._apply(action)
        error: Optional[BaseException] = None
        try:
            self.sim.step(steps=self.frame_skip)
        except SimulationError as e:
            error = e
        return self._finish(before, error)


def _rotate_back(rot: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``rotᵀ·v`` of N rotations (N, 3, 3) and vectors (N, 3): ``vᵀ·rot``
    as a stack of N (1 × 3)·(3 × 3) products, each computed on its own
    whatever N (the vector environments' rows equal a single
    environment's, tested)."""
    return np.matmul(v[:, None, :], rot)[:, 0, :]


def _sum_squares(x: np.ndarray) -> np.ndarray:
    """``Σ x²`` along the last axis of (N, m), each row on its own."""
    return np.add.reduce(x * x, axis=1)


def _stance_deg() -> List[float]:
    return [0.0, -20.0, 290.0]


class HexapodWalkEnv(_FbdEnv):
    """``fbd/HexapodWalk-v0`` (see the module docs for every layout)."""

    ACTION_SCALE = np.array([0.35, 0.35, 0.35] * 6)
    GAIT_PERIOD = 0.8
    EFFORT = 5e-6
    SLIP = 0.1
    OBSERVATION_NAMES = (
        ["height", "phi_x", "phi_y", "phi_z", "vx", "vy", "vz", "wx", "wy", "wz"]
        + [f"theta{j}_{leg}" for leg in range(1, 7) for j in (1, 2, 3)]
        + [f"rate{j}_{leg}" for leg in range(1, 7) for j in (1, 2, 3)]
        + [f"state{leg}" for leg in range(1, 7)]
        + [f"n{leg}" for leg in range(1, 7)]
        + ["clock_sin", "clock_cos"]
    )

    def __init__(self, episode_seconds: float = 2.0, frame_skip: int = 20, dt: float = 0.001) -> None:
        super().__init__(episode_seconds, frame_skip, dt)
        self.stance = np.radians(_stance_deg() * 6)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(18,), dtype=np.float64)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(60,), dtype=np.float64)
        self._tips: Optional[np.ndarray] = None
        self._hips: Optional[np.ndarray] = None

    def _config(self) -> Dict[str, Any]:
        rng = self.np_random
        yaw = float(rng.uniform(-5.0, 5.0))
        legs = {}
        for leg in range(1, 7):
            legs[f"leg{leg}"] = {"theta_deg": [float(v + rng.uniform(-2.0, 2.0)) for v in _stance_deg()]}
        mu = float(rng.uniform(0.6, 1.0))
        clearance = float(rng.uniform(0.0, 0.003))
        # The height that puts the lowest foot `clearance` above the ground.
        q = np.zeros(24)
        q[1] = 1.0
        q[4] = math.radians(yaw)
        for leg in range(1, 7):
            q[6 + 3 * (leg - 1) : 9 + 3 * (leg - 1)] = np.radians(legs[f"leg{leg}"]["theta_deg"])
        low = float(np.min(_hexapod_tips_y(q)))
        height = 1.0 - low + clearance + 1e-6
        return {
            "model": "hexapod",
            "time": {"dt": self.dt, "duration": self.episode_seconds},
            "initial": {"position": [0.0, height, 0.0], "phi_deg": [0.0, yaw, 0.0], **legs},
            "terrain": {"kind": "flat", "height": 0.0, "mu_static": mu, "mu_dynamic": 0.8 * mu},
        }

    def _new_simulator(self) -> None:
        names = self.sim.contact_points
        self._tips = np.array([names.index(f"tip{leg}") for leg in range(1, 7)])
        self._hips = np.array([i for i, n in enumerate(names) if n.startswith("hip")], dtype=int)

    OBSERVED = (
        "t",
        "q",
        "body_rotation",
        "body_velocity",
        "body_angular_velocity",
        "joint_angle",
        "joint_rate",
        "joint_torque",
        "contact_state",
        "contact_normal_force",
        "contact_slip_velocity",
    )

    def _targets(self, a: np.ndarray) -> np.ndarray:
        return self.stance + self.ACTION_SCALE * a

    def _observe(self, o: Dict[str, np.ndarray]) -> np.ndarray:
        rot = o["body_rotation"][:, 0]
        v = _rotate_back(rot, o["body_velocity"][:, 0])
        w = _rotate_back(rot, o["body_angular_velocity"][:, 0])
        states = o["contact_state"][:, self._tips].astype(np.float64) - 1.0
        phase = [2.0 * math.pi * t / self.GAIT_PERIOD for t in o["t"].tolist()]
        clock = np.array([[math.sin(x), math.cos(x)] for x in phase]).reshape(len(phase), 2)
        q = o["q"]
        return np.concatenate(
            [
                q[:, 1:2],
                q[:, 3:6],
                v,
                w,
                o["joint_angle"],
                o["joint_rate"],
                states,
                o["contact_normal_force"][:, self._tips],
                clock,
            ],
            axis=1,
        )

    def _reward(self, o: Dict[str, np.ndarray], before: np.ndarray) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
        period = self.frame_skip * self.dt
        forward = -(o["q"][:, 2] - before[:, 2]) / period
        effort = self.EFFORT * _sum_squares(o["joint_torque"])
        slip_v = o["contact_slip_velocity"][:, self._tips]
        speed = np.sqrt(np.add.reduce(slip_v * slip_v, axis=2))
        sliding = o["contact_state"][:, self._tips] == 3
        slip = self.SLIP * np.add.reduce(np.where(sliding, speed, 0.0), axis=1)
        return forward - effort - slip, {"forward_speed": forward, "effort": effort, "slip": slip}

    def _terminated(self, o: Dict[str, np.ndarray]) -> np.ndarray:
        up = o["body_rotation"][:, 0, 1, 1]
        if len(self._hips):
            hips_down = np.any(o["contact_state"][:, self._hips] != 1, axis=1)
        else:
            hips_down = np.zeros(len(up), dtype=bool)
        return (o["q"][:, 1] < 0.12) | hips_down | (up < 0.5)


def _hexapod_tips_y(q: np.ndarray) -> np.ndarray:
    from . import hexapod_fk

    return hexapod_fk(q)["tip"][:, 1]


class PlanarStandEnv(_FbdEnv):
    """``fbd/PlanarStand-v0`` (see the module docs)."""

    ACTION_SCALE = 0.5
    HEIGHT = 0.42
    KP = 3000.0
    KD = 10.0
    TORQUE_LIMIT = 200.0
    STANCE_DEG = [0.0, 250.0, 0.0, 250.0]

    def __init__(self, episode_seconds: float = 2.0, frame_skip: int = 10, dt: float = 0.002) -> None:
        super().__init__(episode_seconds, frame_skip, dt)
        self.stance = np.radians(self.STANCE_DEG)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(4,), dtype=np.float64)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(18,), dtype=np.float64)

    def _config(self) -> Dict[str, Any]:
        rng = self.np_random
        drop = float(rng.uniform(0.02, 0.08))
        mu = float(rng.uniform(0.5, 0.9))
        # Tips at 0.3946709 m below the body at (0°, 250°) (pd_loop.py).
        return {
            "time": {"dt": self.dt, "duration": self.episode_seconds},
            "initial": {
                "position": [0.0, 0.3946709007300815 + drop],
                "leg3": {"theta_deg": [0.0, 250.0]},
                "leg4": {"theta_deg": [0.0, 250.0]},
            },
            "terrain": {"kind": "flat", "height": 0.0, "mu_static": mu, "mu_dynamic": 0.8 * mu},
        }

    OBSERVED = ("t", "q", "qdot", "joint_torque", "contact_state", "contact_normal_force")

    def _targets(self, a: np.ndarray) -> np.ndarray:
        return self.stance + self.ACTION_SCALE * a

    def _observe(self, o: Dict[str, np.ndarray]) -> np.ndarray:
        tips = [0, 1]
        return np.concatenate(
            [
                o["q"],
                o["qdot"],
                o["contact_state"][:, tips].astype(np.float64) - 1.0,
                o["contact_normal_force"][:, tips],
            ],
            axis=1,
        )

    def _reward(self, o: Dict[str, np.ndarray], before: np.ndarray) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
        height = np.abs(o["q"][:, 1] - self.HEIGHT) / 0.1
        effort = 1e-4 * _sum_squares(o["joint_torque"])
        return 1.0 - height - effort, {"height_error": height, "effort": effort}

    def _terminated(self, o: Dict[str, np.ndarray]) -> np.ndarray:
        q = o["q"]
        return (q[:, 1] < 0.25) | (np.abs(q[:, 2]) > math.radians(45.0))


def _quaternions(r: np.ndarray) -> np.ndarray:
    """The unit quaternions ``(w, x, y, z)`` (``w ≥ 0``) of N rotations
    ``r`` (N, 3, 3), shape (N, 4): Shepperd's method, each row on its own."""
    r00, r11, r22 = r[:, 0, 0], r[:, 1, 1], r[:, 2, 2]
    t = r00 + r11 + r22
    with np.errstate(all="ignore"):  # the branches not taken
        s = 2.0 * np.sqrt(1.0 + t)
        q0 = [0.25 * s, (r[:, 2, 1] - r[:, 1, 2]) / s, (r[:, 0, 2] - r[:, 2, 0]) / s, (r[:, 1, 0] - r[:, 0, 1]) / s]
        s = 2.0 * np.sqrt(1.0 + r00 - r11 - r22)
        q1 = [(r[:, 2, 1] - r[:, 1, 2]) / s, 0.25 * s, (r[:, 0, 1] + r[:, 1, 0]) / s, (r[:, 0, 2] + r[:, 2, 0]) / s]
        s = 2.0 * np.sqrt(1.0 + r11 - r00 - r22)
        q2 = [(r[:, 0, 2] - r[:, 2, 0]) / s, (r[:, 0, 1] + r[:, 1, 0]) / s, 0.25 * s, (r[:, 1, 2] + r[:, 2, 1]) / s]
        s = 2.0 * np.sqrt(1.0 + r22 - r00 - r11)
        q3 = [(r[:, 1, 0] - r[:, 0, 1]) / s, (r[:, 0, 2] + r[:, 2, 0]) / s, (r[:, 1, 2] + r[:, 2, 1]) / s, 0.25 * s]
    first = t > 0.0
    second = ~first & (r00 > r11) & (r00 > r22)
    third = ~first & ~second & (r11 > r22)
    q = np.select(
        [first[:, None], second[:, None], third[:, None]],
        [np.stack(q0, axis=1), np.stack(q1, axis=1), np.stack(q2, axis=1)],
        np.stack(q3, axis=1),
    )
    q = q / np.sqrt(np.add.reduce(q * q, axis=1))[:, None]
    return np.where(q[:, 0:1] < 0.0, -q, q)


class RobotEnv(_FbdEnv):
    """``fbd/Robot-v0``: any imported robot (see the module docs).

    Args:
        config: a ``model = "robot"`` configuration (a path, TOML text or a
            dict, as for :class:`fbd.Simulator`).
        episode_seconds: episode length (s).
        control_hz: policy rate (Hz); ``frame_skip`` physics steps per
            action, ``max(1, round(1/(control_hz·dt)))``.
        action_scale: target offset of ``a = ±1`` (rad; a number or one per
            joint).
        kp, kd, torque_limit: PD gains (numbers or one per joint) and the
            torque clamp; default from the configuration (module docs).
        effort: the effort penalty's weight (per N·m²).
        fall_fraction, max_tilt_deg: the termination thresholds.
        init_noise: the reset's random first targets (rad), 0 for none.
    """

    DEFAULT_ACTION_SCALE = 0.25
    DEFAULT_EFFORT = 1e-3

    def __init__(
        self,
        config: Any = None,
        episode_seconds: float = 2.0,
        control_hz: float = 50.0,
        action_scale: Any = DEFAULT_ACTION_SCALE,
        kp: Any = None,
        kd: Any = None,
        torque_limit: Optional[float] = None,
        effort: float = DEFAULT_EFFORT,
        fall_fraction: float = 0.5,
        max_tilt_deg: float = 60.0,
        init_noise: float = 0.0,
    ) -> None:
        if config is None:
            raise ValueError("fbd/Robot-v0: give config=, a model = \"robot\" configuration")
        sim = _fbd.Simulator(config)
        if sim.model != "robot":
            raise ValueError(
                f"fbd/Robot-v0: {config!r} is a model = \"{sim.model}\" configuration; "
                "it takes model = \"robot\""
            )
        dt = sim.dt
        frame_skip = max(1, int(round(1.0 / (float(control_hz) * dt))))
        super().__init__(episode_seconds, frame_skip, dt)
        self.config = config
        self.sim = sim
        self.q0 = np.array(sim.q0)
        n = len(sim.joint_names)
        self.joints = n
        self.stance = self.q0[6:]
        self.action_scale = np.broadcast_to(np.asarray(action_scale, dtype=np.float64), (n,)).copy()
        control = sim.control
        if control["kind"] != "none":
            self.kp = np.array(control["kp"])
            self.kd = np.array(control["kd"])
            limit = control["torque_limit"]
        else:
            inertia = sim.joint_inertia
            i = inertia[0] if inertia is not None else 1.0
            self.kp = np.full(n, 0.1 * i / dt**2)
            self.kd = np.full(n, i / dt)
            limit = None
        if kp is not None:
            self.kp = np.broadcast_to(np.asarray(kp, dtype=np.float64), (n,)).copy()
        if kd is not None:
            self.kd = np.broadcast_to(np.asarray(kd, dtype=np.float64), (n,)).copy()
        if torque_limit is not None:
            limit = float(torque_limit)
        if limit is None:
            efforts = np.asarray(sim.effort_limits)
            efforts = efforts[np.isfinite(efforts)]
            limit = float(np.min(efforts)) if efforts.size else None
        self.TORQUE_LIMIT = limit
        self.effort = float(effort)
        self.fall_fraction = float(fall_fraction)
        self.cos_tilt = math.cos(math.radians(float(max_tilt_deg)))
        self.init_noise = float(init_noise)
        self.height0 = float(self.q0[1])
        rot0 = np.asarray(sim.observe()["body_rotation"][0])
        forward = rot0 @ np.array([0.0, 0.0, -1.0])
        forward[1] = 0.0
        norm = float(np.linalg.norm(forward))
        self.forward = forward / norm if norm > 1e-9 else np.array([0.0, 0.0, -1.0])
        self.points = list(sim.contact_points)
        self.observation_names = (
            ["height", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz"]
            + [f"q_{j}" for j in sim.joint_names]
            + [f"qd_{j}" for j in sim.joint_names]
            + [f"state_{p}" for p in self.points]
            + [f"n_{p}" for p in self.points]
        )
        size = len(self.observation_names)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n,), dtype=np.float64)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float64)
        self._started = False

    def _start(self) -> Tuple[np.ndarray, Dict[str, Any]]:
        self.sim.reset()
        self._error = None
        self._started = True
        if self.init_noise > 0.0:
            noise = self.np_random.uniform(-self.init_noise, self.init_noise, self.joints)
            self.sim.set_pd_targets(self.stance + noise, self.kp, self.kd, torque_limit=self.TORQUE_LIMIT)
            try:
                self.sim.step(steps=self.frame_skip)
            except SimulationError:
                self.sim.reset()  # the configuration's own initial state
        self._t0 = self.sim.t
        return self._observation(), {}

    def step(self, action: Any):
        if not self._started:
            raise RuntimeError("call reset() before step()")
        return super().step(action)

    OBSERVED = (
        "t",
        "q",
        "qdot",
        "body_rotation",
        "body_angular_velocity",
        "joint_angle",
        "joint_rate",
        "joint_torque",
        "contact_state",
        "contact_normal_force",
    )

    def _gains(self) -> Tuple[Any, Any, Optional[float]]:
        return self.kp, self.kd, self.TORQUE_LIMIT

    def _targets(self, a: np.ndarray) -> np.ndarray:
        return self.stance + self.action_scale * a

    def _observe(self, o: Dict[str, np.ndarray]) -> np.ndarray:
        rot = o["body_rotation"][:, 0]
        v = _rotate_back(rot, o["qdot"][:, 0:3])
        w = _rotate_back(rot, o["body_angular_velocity"][:, 0])
        states = o["contact_state"].astype(np.float64) - 1.0
        return np.concatenate(
            [
                o["q"][:, 1:2],
                _quaternions(rot),
                v,
                w,
                o["joint_angle"],
                o["joint_rate"],
                states,
                o["contact_normal_force"],
            ],
            axis=1,
        ).astype(np.float64)

    def _reward(self, o: Dict[str, np.ndarray], before: np.ndarray) -> Tuple[np.ndarray, Dict[str, np.ndarray]]:
        period = self.frame_skip * self.dt
        d = o["q"][:, 0:3] - before[:, 0:3]
        f = self.forward
        forward = (d[:, 0] * f[0] + d[:, 1] * f[1] + d[:, 2] * f[2]) / period
        effort = self.effort * _sum_squares(o["joint_torque"])
        return forward - effort, {"forward_speed": forward, "effort": effort}

    def _terminated(self, o: Dict[str, np.ndarray]) -> np.ndarray:
        up = o["body_rotation"][:, 0, 1, 1]
        return (o["q"][:, 1] < self.fall_fraction * self.height0) | (up < self.cos_tilt)


class _FbdVectorEnv(VectorEnv):
    """N environments of one class stepped together: the physics of every
    sub-environment on Rust threads (``fbd._fbd.step_many``, the GIL
    released), the task's rules once for the whole batch
    (``_step_batch``), new simulators built together (``_reset_envs``),
    each result as N serial environments would give it, with the
    ``NEXT_STEP`` autoreset of Gymnasium ≥ 1.1: the step after a
    sub-environment terminated or truncated resets it (its action is
    ignored; reward 0, not terminated, not truncated)."""

    ENV: type = _FbdEnv
    metadata: Dict[str, Any] = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, **kwargs: Any) -> None:
        kwargs.pop("max_episode_steps", None)
        self.num_envs = int(num_envs)
        self.envs = [self.ENV(**kwargs) for _ in range(self.num_envs)]
        self.single_action_space = self.envs[0].action_space
        self.single_observation_space = self.envs[0].observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)

    def reset(self, *, seed: Any = None, options: Optional[Dict[str, Any]] = None):
        if seed is None:
            seeds: List[Optional[int]] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed: expected {self.num_envs} seeds, got {len(seeds)}")
        obs = np.zeros((self.num_envs,) + self.single_observation_space.shape, dtype=np.float64)
        infos: Dict[str, Any] = {}
        infos = self._reset_envs(np.arange(self.num_envs), seeds, options, obs, infos)
        self._autoreset[:] = False
        return obs, infos

    def _reset_envs(self, ids, seeds, options, obs: np.ndarray, infos: Dict[str, Any]) -> Dict[str, Any]:
        """Resets the sub-environments ``ids`` (with ``seeds``), their first
        observations into ``obs``: environments that build a new simulator
        per episode draw their configurations one after the other and
        build the simulators together on Rust threads
        (``_fbd.simulators_many``), each as its own ``reset`` would."""
        envs = [self.envs[i] for i in ids]
        if not envs:
            return infos
        if type(envs[0])._start is not _FbdEnv._start:
            for i, env, s in zip(ids, envs, seeds):
                obs[i], info = env.reset(seed=s, options=options)
                infos = self._add_info(infos, info, i)
            return infos
        configs = []
        for env, s in zip(envs, seeds):
            gymnasium.Env.reset(env, seed=s)
            configs.append(env._config())
        sims = _fbd.simulators_many(configs)
        for env, sim in zip(envs, sims):
            env._adopt(sim)
        task = envs[0]
        obs[ids] = task._observe(_fbd.observe_many(sims, list(task.OBSERVED)))
        return infos

    def step(self, actions: Any):
        # NaN checked in the rows that step (a resetting row's is unused).
        actions = _checked_action(actions, self.action_space.shape, nan=False)
        n = self.num_envs
        if not self._autoreset.any():
            # Every sub-environment steps (the common case).
            obs, rewards, terminated, truncated, infos = self._step_batch(np.arange(n), actions)
        else:
            rewards = np.zeros(n, dtype=np.float64)
            terminated = np.zeros(n, dtype=np.bool_)
            truncated = np.zeros(n, dtype=np.bool_)
            obs = np.zeros((n,) + self.single_observation_space.shape, dtype=np.float64)
            infos: Dict[str, Any] = {}
            resetting = np.flatnonzero(self._autoreset)
            infos = self._reset_envs(resetting, [None] * len(resetting), None, obs, infos)
            stepping = np.flatnonzero(~self._autoreset)
            if stepping.size:
                o, r, te, tr, batch_infos = self._step_batch(stepping, actions[stepping])
                obs[stepping], rewards[stepping], terminated[stepping], truncated[stepping] = o, r, te, tr
                for key, values in batch_infos.items():
                    if key.startswith("_"):
                        continue
                    column = np.zeros(n, dtype=values.dtype) if values.dtype != object else np.full(n, None, dtype=object)
                    column[stepping] = values
                    mask = np.zeros(n, dtype=np.bool_)
                    mask[stepping] = batch_infos[f"_{key}"]
                    infos[key], infos[f"_{key}"] = column, mask
        self._autoreset = np.logical_or(terminated, truncated)
        return obs, rewards, terminated, truncated, infos

    def _step_batch(self, stepping: np.ndarray, actions: np.ndarray):
        """One control period of the sub-environments ``stepping`` with
        ``actions`` (one row each): the task's rules once for the whole
        batch, each row as its environment alone would compute it, bit for
        bit. Returns the batch's observations, rewards, terminated,
        truncated and infos (with their ``_key`` masks)."""
        task = self.envs[0]
        envs = [self.envs[i] for i in stepping]
        sims = [e.sim for e in envs]
        kp, kd, limit = task._gains()
        a = _checked_action(actions, actions.shape)
        _fbd.set_pd_targets_many(sims, np.ascontiguousarray(task._targets(a)), kp, kd, torque_limit=limit)
        before = _fbd.observe_many(sims, ["q"])["q"]
        errors = _fbd.step_many(sims, None, task.frame_skip)
        o = _fbd.observe_many(sims, list(task.OBSERVED))
        obs = task._observe(o)
        reward, info = task._reward(o, before)
        terminated = task._terminated(o)
        t0 = np.array([e._t0 for e in envs])
        truncated = ~terminated & (o["t"] - t0 >= task.episode_seconds - 0.5 * task.dt)
        ok = np.ones(len(envs), dtype=np.bool_)
        infos: Dict[str, Any] = {}
        if any(err is not None for err in errors):
            messages = np.full(len(envs), None, dtype=object)
            for k, (env, err) in enumerate(zip(envs, errors)):
                if err is not None:
                    env._error = str(err)
                    messages[k] = env._error
                    ok[k] = False
            infos["error"], infos["_error"] = messages, ~ok
            reward = np.where(ok, reward, 0.0)
            terminated = terminated | ~ok
            truncated = truncated & ok
            info = {k: np.where(ok, v, 0.0) for k, v in info.items()}
        for key, values in info.items():
            infos[key], infos[f"_{key}"] = values, ok.copy()
        return obs, reward, terminated, truncated, infos

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.close()


class HexapodWalkVectorEnv(_FbdVectorEnv):
    """The vector entry point of ``fbd/HexapodWalk-v0``."""

    ENV = HexapodWalkEnv


class PlanarStandVectorEnv(_FbdVectorEnv):
    """The vector entry point of ``fbd/PlanarStand-v0``."""

    ENV = PlanarStandEnv


class RobotVectorEnv(_FbdVectorEnv):
    """The vector entry point of ``fbd/Robot-v0`` (``config=`` as for
    :class:`RobotEnv`)."""

    ENV = RobotEnv


def register_envs() -> None:
    """Registers ``fbd/HexapodWalk-v0``, ``fbd/PlanarStand-v0`` and
    ``fbd/Robot-v0`` (done by ``import fbd`` when gymnasium is installed)."""
    for name, env, vec in [
        ("fbd/HexapodWalk-v0", "HexapodWalkEnv", "HexapodWalkVectorEnv"),
        ("fbd/PlanarStand-v0", "PlanarStandEnv", "PlanarStandVectorEnv"),
        ("fbd/Robot-v0", "RobotEnv", "RobotVectorEnv"),
    ]:
        if name not in gymnasium.registry:
            gymnasium.register(
                id=name,
                entry_point=f"fbd.gym:{env}",
                vector_entry_point=f"fbd.gym:{vec}",
            )
