#!/usr/bin/env python3
"""The fbd hexapod in MuJoCo (the model `fbd export mjcf` writes), timed with
`mujoco.rollout` on one thread.

The model is exported from the same configuration fbd runs (bench/peer/
hexapod_stand.toml, hexapod_walk.toml): bodies, inertias, joints
(qpos = fbd's joint angles), sphere feet (radius 1 cm, the ground one radius
below fbd's terrain so that a foot touches it when its centre — fbd's tip —
is on the terrain), position servos with fbd's kp and kv = kd, the initial
state as the keyframe "initial" (docs/reference.md, `fbd export mjcf`).

Cases:

* ``stand``: the servos hold the keyframe's targets (constant ctrl); the
  robot starts on its six feet. Reports the forces at the end: the normal
  force of every foot and their sum against the weight.
* ``walk``: the servos track the kinematic gait: ``--targets`` is the
  trajectory.csv of `fbd run` of the same configuration with
  `dynamics = "kinematic"` (columns theta{j}_{n}, rad, and omega{j}_{n},
  rad/s, one row per step). fbd's controller is
  ``τ = kp·(θ* − θ) + kd·(θ̇* − θ̇)``; MuJoCo's servo is
  ``τ = kp·(ctrl − θ) − kv·θ̇``, so ``ctrl = θ* + (kd/kp)·θ̇*`` gives the
  same torque. Reports the body's displacement.
* ``drop``: the passive robot (no actuators) dropped from the keyframe,
  tilted and spinning, onto its feet, knees and hips (spheres at every
  contact point; bench/peer/hexapod_drop.toml). Reports the body's
  displacement and the normal forces at the end.

Prints one JSON object: {case, steps, seconds, steps_per_second, ...}.

    mujoco_hexapod.py twin hexapod_walk.toml walk_kin.toml   # the targets' config
    fbd run walk_kin.toml --out kin
    fbd export mjcf hexapod_walk.toml --out walk.xml
    mujoco_hexapod.py walk walk.xml --steps 5001 --targets kin/trajectory.csv
"""

import argparse
import csv
import json
import math
import time

import mujoco
import numpy as np
from mujoco import rollout


def gait_controls(model, path, steps):
    """ctrl per step (steps × nu) from a kinematic trajectory.csv."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if len(rows) < steps:
        raise SystemExit(f"{path}: {len(rows)} rows, need {steps} (write every step: [output] stride = 1)")
    ctrl = np.empty((steps, model.nu))
    for a in range(model.nu):
        name = model.actuator(a).name  # tau{j}_{n}
        joint = model.joint(model.actuator_trnid[a, 0]).name  # theta{j}_{n}
        j, n = joint[len("theta") :].split("_")
        kp = model.actuator_gainprm[a, 0]
        kv = -model.actuator_biasprm[a, 2]
        theta = np.array([float(r[f"theta{j}_{n}"]) for r in rows[:steps]])
        rate = np.array([float(r[f"omega{j}_{n}"]) for r in rows[:steps]])
        ctrl[:, a] = theta + (kv / kp if kp > 0 else 0.0) * rate
        assert name == f"tau{j}_{n}", name
    return ctrl


def foot_forces(model, data):
    """Normal force (N) of the ground on every contact sphere in contact."""
    forces = {}
    f6 = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        mujoco.mj_contactForce(model, data, i, f6)
        for g in (c.geom1, c.geom2):
            name = model.geom(g).name
            if name != "ground":
                forces[name] = forces.get(name, 0.0) + float(f6[0])
    return forces


def run(case, xml, steps, repeat, targets):
    model = mujoco.MjModel.from_xml_path(xml)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("initial").id)
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    if case == "stand":
        control = data.ctrl.copy()[None, None, :]
    elif case == "walk":
        control = gait_controls(model, targets, steps)[None, :, :]
    elif case == "drop":
        control = np.zeros((1, 1, model.nu))
    else:
        raise ValueError(case)
    out = np.empty((1, steps, state0.size))
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        rollout.rollout(model, data, state0[None, :], control, nstep=steps, state=out)
        best = min(best, time.perf_counter() - t0)
    mujoco.mj_setState(model, data, out[0, -1], spec)
    data.ctrl[:] = control[0, -1]
    mujoco.mj_forward(model, data)
    result = {
        "case": case,
        "steps": steps,
        "seconds": best,
        "steps_per_second": steps / best,
        "mujoco": mujoco.__version__,
        "t_end": float(data.time),
        "body_end": [float(v) for v in data.qpos[:3]],
        "body_start": [float(v) for v in state0[1:4]],
    }
    forces = foot_forces(model, data)
    weight = float(model.body_mass.sum()) * -float(model.opt.gravity[1])
    result["weight"] = weight
    result["normal_sum"] = sum(forces.values())
    result["normal"] = dict(sorted(forces.items()))
    return result


def kinematic_twin(config, out):
    """Writes ``out``: ``config`` with ``dynamics = "kinematic"``, without
    its ``[control]`` table and writing every step (``[output] stride =
    1``): `fbd run` of it writes the gait's joint targets of every step."""
    lines, skip = ['dynamics = "kinematic"'], False
    table = None
    for line in open(config).read().splitlines():
        head = line.strip()
        if head.startswith("["):
            table = head.split("]")[0].strip("[ ")
            skip = table == "control" or table.startswith("control.")
        if skip:
            continue
        if table == "output" and head.startswith("stride"):
            continue
        lines.append(line)
    if not any(line.strip() == "[output]" for line in lines):
        lines.append("[output]")
    i = lines.index("[output]")
    lines.insert(i + 1, "stride = 1")
    open(out, "w").write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    for case in ("stand", "walk", "drop"):
        c = sub.add_parser(case, help=f"time the {case} case")
        c.add_argument("xml", help="the model, from `fbd export mjcf CONFIG`")
        c.add_argument("--steps", type=int, required=True, help="steps per rollout (fbd's count)")
        c.add_argument("--repeat", type=int, default=3, help="rollouts; the fastest is reported")
        if case == "walk":
            c.add_argument("--targets", required=True, help="trajectory.csv of the kinematic gait (every step)")
    t = sub.add_parser("twin", help="write the kinematic twin of a gait-tracking configuration")
    t.add_argument("config")
    t.add_argument("out")
    args = ap.parse_args()
    if args.command == "twin":
        kinematic_twin(args.config, args.out)
        return
    targets = getattr(args, "targets", None)
    print(json.dumps(run(args.command, args.xml, args.steps, args.repeat, targets)), flush=True)


if __name__ == "__main__":
    main()
