#!/usr/bin/env python3
"""The fbd planar model in MuJoCo, timed with `mujoco.rollout` on one thread.

Same robot as fbd's default experiment (`fbd_sim::PlanarParams::default()`,
docs/reference.md), written in fbd's inertial frame (X horizontal, Y up, joints
about Z):

* central body: 10 kg, I = 0.3 kg·m² about Z, joints slide X, slide Y,
  hinge Z (the planar floating base Rx, Ry, φz); hips at ±d,
  d = 0.25·cos 30° = 0.2165 m;
* upper links: a = 0.2 m, 0.3 kg, centre of mass at 0.5·a from the hip,
  I = m·a²/12; lower links: c = 0.42 m, 1.1 kg, centre of mass at 0.75·c
  from the knee, I = m·c²/12. (MuJoCo needs a full inertia: the diagonal is
  (I, I, I); only Izz matters, the motion is planar.)
* joint axes: leg 3's hip and knee +Z, leg 4's −Z (docs/reference.md); the joint
  reference (qpos = 0) is θ2 = θ3 = 0, so qpos equals fbd's θ2, θ3;
* no joint damping, armature, limits or actuators (passive joints);
* feet: spheres of radius 5 mm centred on the tips; they are the only
  collision geoms (contype 1 / conaffinity 0; the floor 0 / 1), as in fbd
  where only the tips touch the terrain; friction 0.4 (sliding), MuJoCo's
  default contact softness (solref 0.02 1, default solimp), pyramidal cones,
  Newton constraint solver (MuJoCo defaults);
* integrator Euler (semi-implicit; fbd's scheme is the central difference),
  Δt = 1 ms, gravity (0, −9.81, 0).

Cases (the same initial states as bench/peer/*.toml):

* ``flight``: gravity on, no floor at all, the default pose
  q0 = (0, 0.6, 0, 0, 245°, 0, 255°), at rest;
* ``stand``: floor plane y = 0 (normal +Y); legs θ = (0°, 250°), Ry so
  that the feet spheres rest on the floor (fbd's tips at y = 0 plus the
  5 mm radius): the passive robot collapses with both feet on the floor;
* ``hang``: floor plane y = 0; legs θ = (0°, 90°), Ry = −0.42 (+ radius):
  the body hangs below the floor (nothing but the feet collides) from both
  feet, which stay on it;
* ``moving_flight``: as ``flight`` with the body spinning and the legs
  swinging from t = 0: φ̇z = −115°/s, (θ̇2₃, θ̇3₃, θ̇2₄, θ̇3₄) =
  (170, −60, 140, 60) °/s;
* ``passive_fall``: the built-in experiment (fbd's default configuration):
  the default pose at rest, floor plane y = −radius (so that a sphere
  touches it when its centre, fbd's point, is at y = 0), spheres at the
  tips, knees (lower link, at the knee) and hips (central body), fbd's
  default joint ranges (MuJoCo's soft limits; fbd's are plastic stops),
  friction μS = 0.4.

Prints one JSON object per case: {case, steps, seconds, steps_per_second}
(and the number of contacts at the end, as a sanity check).
"""

import argparse
import json
import math
import time

import mujoco
import numpy as np
from mujoco import rollout

D = 0.25 * math.cos(math.pi / 6)
A, C = 0.2, 0.42
M_BODY, I_BODY = 10.0, 0.3
M_UP, M_LOW = 0.3, 1.1
I_UP, I_LOW = M_UP * A * A / 12, M_LOW * C * C / 12
UP_COM, LOW_COM = 0.5, 0.75
RADIUS = 0.005
DT = 0.001
FRICTION = 0.4
HIP_LIMIT = math.radians(120)
KNEE_LIMITS = (math.radians(180), math.radians(330))


def leg(n, s, knees=False, limits=False):
    """Leg n (3 or 4) with side sign s (−1 left, +1 right), at θ2 = θ3 = 0;
    ``knees``: a contact sphere at the knee too; ``limits``: fbd's default
    joint ranges (θ2 ∈ [−120°, 120°], θ3 ∈ [180°, 330°])."""
    axis = "0 0 1" if s < 0 else "0 0 -1"
    hip_range = f' range="{-HIP_LIMIT!r} {HIP_LIMIT!r}"' if limits else ""
    knee_range = f' range="{KNEE_LIMITS[0]!r} {KNEE_LIMITS[1]!r}"' if limits else ""
    knee = (
        f"""
          <geom name="knee{n}" type="sphere" size="{RADIUS!r}" pos="0 0 0"
                contype="1" conaffinity="0" friction="{FRICTION!r} 0.005 0.0001"/>"""
        if knees
        else ""
    )
    return f"""
      <body name="upper{n}" pos="{s * D!r} 0 0">
        <joint name="hip{n}" type="hinge" axis="{axis}"{hip_range}/>
        <inertial pos="{s * UP_COM * A!r} 0 0" mass="{M_UP!r}" diaginertia="{I_UP!r} {I_UP!r} {I_UP!r}"/>
        <body name="lower{n}" pos="{s * A!r} 0 0">
          <joint name="knee{n}" type="hinge" axis="{axis}"{knee_range}/>
          <inertial pos="{-s * LOW_COM * C!r} 0 0" mass="{M_LOW!r}" diaginertia="{I_LOW!r} {I_LOW!r} {I_LOW!r}"/>
          <geom name="foot{n}" type="sphere" size="{RADIUS!r}" pos="{-s * C!r} 0 0"
                contype="1" conaffinity="0" friction="{FRICTION!r} 0.005 0.0001"/>{knee}
        </body>
      </body>"""


def mjcf(floor, floor_y=0.0, every_point=False):
    """The model; ``floor``: a ground plane at y = ``floor_y``;
    ``every_point``: spheres at the knees and hips too and fbd's joint
    ranges (the built-in experiment's robot)."""
    floor_geom = (
        f'<geom name="floor" type="plane" zaxis="0 1 0" size="0 0 1" pos="0 {floor_y!r} 0" contype="0" conaffinity="1"/>'
        if floor
        else ""
    )
    hips = (
        "".join(
            f"""
      <geom name="hip{n}" type="sphere" size="{RADIUS!r}" pos="{s * D!r} 0 0"
            contype="1" conaffinity="0" friction="{FRICTION!r} 0.005 0.0001"/>"""
            for n, s in ((3, -1.0), (4, 1.0))
        )
        if every_point
        else ""
    )
    return f"""
<mujoco model="fbd_planar">
  <compiler angle="radian"/>
  <option timestep="{DT!r}" integrator="Euler" gravity="0 -9.81 0"/>
  <worldbody>
    {floor_geom}
    <body name="body">
      <joint name="rx" type="slide" axis="1 0 0"/>
      <joint name="ry" type="slide" axis="0 1 0"/>
      <joint name="phiz" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{M_BODY!r}" diaginertia="{I_BODY!r} {I_BODY!r} {I_BODY!r}"/>{hips}
      {leg(3, -1.0, every_point, every_point)}
      {leg(4, +1.0, every_point, every_point)}
    </body>
  </worldbody>
</mujoco>"""


def case_setup(case):
    """(mjcf text, qpos, qvel) of a case; qpos = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)."""
    r = math.radians
    rest = [0.0] * 7
    q_default = [0.0, 0.6, 0.0, 0.0, r(245), 0.0, r(255)]
    if case == "flight":
        return mjcf(False), q_default, rest
    if case == "stand":
        th3 = r(250)
        return mjcf(True), [0.0, -C * math.sin(th3) + RADIUS, 0.0, 0.0, th3, 0.0, th3], rest
    if case == "hang":
        return mjcf(True), [0.0, -C + RADIUS, 0.0, 0.0, r(90), 0.0, r(90)], rest
    if case == "moving_flight":
        return mjcf(False), q_default, [0.0, 0.0, r(-115), r(170), r(-60), r(140), r(60)]
    if case == "passive_fall":
        return mjcf(True, -RADIUS, every_point=True), q_default, rest
    raise ValueError(case)


def run(case, steps, repeat):
    xml, qpos, qvel = case_setup(case)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    data.qvel[:] = qvel
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    out = np.empty((1, steps, state0.size))
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        rollout.rollout(model, data, state0[None, :], nstep=steps, state=out)
        best = min(best, time.perf_counter() - t0)
    # Contacts at the end of the rollout (sanity check of the case).
    mujoco.mj_setState(model, data, out[0, -1], spec)
    mujoco.mj_forward(model, data)
    return {
        "case": case,
        "steps": steps,
        "seconds": best,
        "steps_per_second": steps / best,
        "contacts_at_end": int(data.ncon),
        "mujoco": mujoco.__version__,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cases", nargs="*", default=["flight", "stand", "hang", "moving_flight", "passive_fall"])
    ap.add_argument("--steps", type=int, default=100_000, help="steps per rollout (default 100000 = 100 s)")
    ap.add_argument("--repeat", type=int, default=3, help="rollouts per case; the fastest is reported")
    args = ap.parse_args()
    for case in args.cases:
        print(json.dumps(run(case, args.steps, args.repeat)), flush=True)


if __name__ == "__main__":
    main()
