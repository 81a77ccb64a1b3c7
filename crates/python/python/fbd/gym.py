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
    def _config(self) -> Dict[str, Any]:  # pragma: no cover - abstract
        raise NotImplementedError

    def _targets(self, action: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def _observe(self, o: Dict[str, Any]) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def _reward(self, o: Dict[str, Any], before: np.ndarray) -> Tuple[float, Dict[str, Any]]:  # pragma: no cover
        raise NotImplementedError

    def _terminated(self, o: Dict[str, Any]) -> bool:  # pragma: no cover
        raise NotImplementedError

    # -- the loop --------------------------------------------------------
    def _start(self) -> Tuple[np.ndarray, Dict[str, Any]]:
        self.sim = _fbd.Simulator(self._config())
        self._error = None
        self._new_simulator()
        return self._observe(self.sim.observe()), {}

    def _new_simulator(self) -> None:
        """After a new simulator is built (indices of its points)."""

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None):
        super().reset(seed=seed)
        return self._start()

    def _apply(self, action: Any) -> np.ndarray:
        """Sets the PD targets of ``action``; the state before the step."""
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.sim.set_pd_targets(self._targets(a), self.KP, self.KD, torque_limit=self.TORQUE_LIMIT)
        return self.sim.q

    def _finish(self, before: np.ndarray, error: Optional[BaseException]):
        if error is not None:
            self._error = str(error)
        o = self.sim.observe()
        obs = self._observe(o)
        if self._error is not None:
            return obs, 0.0, True, False, {"error": self._error}
        reward, info = self._reward(o, before)
        terminated = self._terminated(o)
        truncated = (not terminated) and self.sim.t - self._t0 >= self.episode_seconds - 0.5 * self.dt
        return obs, reward, terminated, truncated, info

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

    def _targets(self, a: np.ndarray) -> np.ndarray:
        return self.stance + self.ACTION_SCALE * a

    def _observe(self, o: Dict[str, Any]) -> np.ndarray:
        rot = o["body_rotation"][0]
        v = rot.T @ o["body_velocity"][0]
        w = rot.T @ o["body_angular_velocity"][0]
        states = o["contact_state"][self._tips].astype(np.float64) - 1.0
        phase = 2.0 * math.pi * o["t"] / self.GAIT_PERIOD
        return np.concatenate(
            [
                [o["q"][1]],
                o["q"][3:6],
                v,
                w,
                o["joint_angle"],
                o["joint_rate"],
                states,
                o["contact_normal_force"][self._tips],
                [math.sin(phase), math.cos(phase)],
            ]
        )

    def _reward(self, o: Dict[str, Any], before: np.ndarray) -> Tuple[float, Dict[str, Any]]:
        period = self.frame_skip * self.dt
        forward = -(o["q"][2] - before[2]) / period
        effort = self.EFFORT * float(np.sum(o["joint_torque"] ** 2))
        sliding = o["contact_state"][self._tips] == 3
        slip = self.SLIP * float(np.sum(np.linalg.norm(o["contact_slip_velocity"][self._tips][sliding], axis=1)))
        info = {"forward_speed": forward, "effort": effort, "slip": slip}
        return forward - effort - slip, info

    def _terminated(self, o: Dict[str, Any]) -> bool:
        up = o["body_rotation"][0][1, 1]
        hips_down = bool(np.any(o["contact_state"][self._hips] != 1)) if len(self._hips) else False
        return bool(o["q"][1] < 0.12 or hips_down or up < 0.5)


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

    def _targets(self, a: np.ndarray) -> np.ndarray:
        return self.stance + self.ACTION_SCALE * a

    def _observe(self, o: Dict[str, Any]) -> np.ndarray:
        tips = [0, 1]
        return np.concatenate(
            [o["q"], o["qdot"], o["contact_state"][tips].astype(np.float64) - 1.0, o["contact_normal_force"][tips]]
        )

    def _reward(self, o: Dict[str, Any], before: np.ndarray) -> Tuple[float, Dict[str, Any]]:
        height = abs(o["q"][1] - self.HEIGHT) / 0.1
        effort = 1e-4 * float(np.sum(o["joint_torque"] ** 2))
        return 1.0 - height - effort, {"height_error": height, "effort": effort}

    def _terminated(self, o: Dict[str, Any]) -> bool:
        q = o["q"]
        return bool(q[1] < 0.25 or abs(q[2]) > math.radians(45.0))


def _quaternion(r: np.ndarray) -> np.ndarray:
    """The unit quaternion ``(w, x, y, z)`` (``w ≥ 0``) of rotation ``r``."""
    t = float(np.trace(r))
    if t > 0.0:
        s = 2.0 * math.sqrt(1.0 + t)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = [(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s]
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = [(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = [(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[0] < 0.0 else q


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
        return self._observe(self.sim.observe()), {}

    def step(self, action: Any):
        if not self._started:
            raise RuntimeError("call reset() before step()")
        return super().step(action)

    def _apply(self, action: Any) -> np.ndarray:
        a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.sim.set_pd_targets(self._targets(a), self.kp, self.kd, torque_limit=self.TORQUE_LIMIT)
        return self.sim.q

    def _targets(self, a: np.ndarray) -> np.ndarray:
        return self.stance + self.action_scale * a

    def _observe(self, o: Dict[str, Any]) -> np.ndarray:
        rot = np.asarray(o["body_rotation"][0])
        v = rot.T @ o["qdot"][0:3]
        w = rot.T @ o["body_angular_velocity"][0]
        states = o["contact_state"].astype(np.float64) - 1.0
        return np.concatenate(
            [
                [o["q"][1]],
                _quaternion(rot),
                v,
                w,
                o["joint_angle"],
                o["joint_rate"],
                states,
                o["contact_normal_force"],
            ]
        ).astype(np.float64)

    def _reward(self, o: Dict[str, Any], before: np.ndarray) -> Tuple[float, Dict[str, Any]]:
        period = self.frame_skip * self.dt
        forward = float(np.dot(o["q"][0:3] - before[0:3], self.forward)) / period
        effort = self.effort * float(np.sum(o["joint_torque"] ** 2))
        return forward - effort, {"forward_speed": forward, "effort": effort}

    def _terminated(self, o: Dict[str, Any]) -> bool:
        up = float(o["body_rotation"][0][1, 1])
        return bool(o["q"][1] < self.fall_fraction * self.height0 or up < self.cos_tilt)


class _FbdVectorEnv(VectorEnv):
    """N environments of one class stepped together: the physics of every
    sub-environment on Rust threads (``fbd._fbd.step_many``, the GIL
    released), the rest exactly as N serial environments would, with the
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
        obs, infos = [], {}
        for i, (env, s) in enumerate(zip(self.envs, seeds)):
            o, info = env.reset(seed=s, options=options)
            obs.append(o)
            infos = self._add_info(infos, info, i)
        self._autoreset[:] = False
        return np.stack(obs), infos

    def step(self, actions: Any):
        actions = np.asarray(actions, dtype=np.float64)
        n = self.num_envs
        obs: List[Optional[np.ndarray]] = [None] * n
        rewards = np.zeros(n, dtype=np.float64)
        terminated = np.zeros(n, dtype=np.bool_)
        truncated = np.zeros(n, dtype=np.bool_)
        infos: List[Dict[str, Any]] = [{} for _ in range(n)]
        stepping, before = [], {}
        for i, env in enumerate(self.envs):
            if self._autoreset[i]:
                obs[i], infos[i] = env.reset()
            else:
                before[i] = env._apply(actions[i])
                stepping.append(i)
        if stepping:
            errors = _fbd.step_many([self.envs[i].sim for i in stepping], None, self.envs[0].frame_skip)
            for i, err in zip(stepping, errors):
                obs[i], rewards[i], terminated[i], truncated[i], infos[i] = self.envs[i]._finish(before[i], err)
        merged: Dict[str, Any] = {}
        for i, info in enumerate(infos):
            merged = self._add_info(merged, info, i)
        self._autoreset = np.logical_or(terminated, truncated)
        return np.stack(obs), rewards, terminated, truncated, merged

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
