"""Solo-12 from example-robot-data standing under PD: ``fbd run`` against
MuJoCo 4.0.0 on ``fbd export mjcf`` of the same configuration.

``examples/robots/solo12_stand.toml`` names its URDF as
``package://solo_description/robots/solo12.urdf``, found through
``ROS_PACKAGE_PATH`` (set here to example-robot-data's ``robots`` folder).
fbd runs it for 1.5 s at Δt = 1 ms; MuJoCo steps the exported model (the
same bodies, the feet as spheres of radius 0.005 m raised by that radius,
the ground a plane) with the same explicit PD torques (kp = 5, kd = 0.1,
the backward-difference rate), the same Δt, an elliptic cone with μ = 0.8,
contacts as stiff as MuJoCo allows (``solref = 2Δt``) and its no-slip
iterations on (without them MuJoCo's soft contacts let the feet creep
apart while the robot settles, and the standing pose, which is statically
indeterminate, keeps that creep: its hip abduction torques reach 0.074 N·m
against fbd's 0 for a stance that is symmetric left to right).

After 1.5 s both stand still; asserted: every foot's normal force (to 1e-3
of the weight; both carry a quarter of it), the joint angles (to 3e-3 rad),
the body height (to 0.5 mm: MuJoCo's contacts are soft) and every joint
torque (to 2 % of the largest) agree, and fbd's run writes no events.
"""

from __future__ import annotations

import importlib.metadata
import os
import pathlib
import subprocess

import mujoco
import numpy as np
import pandas as pd

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples/robots/solo12_stand.toml"
FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
KP, KD, DT, DURATION = 5.0, 0.1, 0.001, 1.5


def package_env() -> dict:
    dist = importlib.metadata.distribution("example-robot-data")
    robots = dist.locate_file("cmeel.prefix/share/example-robot-data/robots")
    return {**os.environ, "ROS_PACKAGE_PATH": str(robots)}


def config(tmp_path: pathlib.Path) -> pathlib.Path:
    text = EXAMPLE.read_text()
    for old, new in [("duration = 2.0", f"duration = {DURATION!r}"),
                     ("kp = 5.0", f"kp = {KP!r}"), ("kd = 0.1", f"kd = {KD!r}"),
                     ("dt = 0.001", f"dt = {DT!r}")]:
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / "solo12_stand.toml"
    path.write_text(text)
    return path


def test_package_paths_need_ros_package_path(cli, tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"}
    r = subprocess.run([str(cli), "run", str(config(tmp_path)), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 2, r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert "robot.urdf" in line and "ROS_PACKAGE_PATH" in line and "unset" in line, line


def test_solo12_stands_as_in_mujoco(cli, tmp_path):
    env = package_env()
    cfg = config(tmp_path)
    out = tmp_path / "out"
    r = subprocess.run([str(cli), "run", str(cfg), "--out", str(out)],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    fb = pd.read_csv(out / "trajectory.csv")
    events = pd.read_csv(out / "events.csv")
    assert len(events) == 0, events
    assert (fb[[f + "_state" for f in FEET]] == "ST2").all().all()

    xml = tmp_path / "solo.xml"
    r = subprocess.run([str(cli), "export", "mjcf", str(cfg), "--out", str(xml)],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    m = mujoco.MjModel.from_xml_path(str(xml))
    m.opt.timestep = DT
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    m.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    m.opt.noslip_iterations = 30
    m.geom_friction[:, 0] = 0.8
    m.geom_solref[:] = [2 * DT, 1.0]
    m.dof_damping[:] = 0.0
    m.dof_armature[:] = 0.0
    d = mujoco.MjData(m)
    joints = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(1, m.njnt)]
    adr = [m.jnt_qposadr[j] for j in range(1, m.njnt)]
    d.qpos[:] = m.qpos0
    for n, a in zip(joints, adr):
        d.qpos[a] = fb[n][0]
    radius = 0.005  # fbd_robot::mjcf_export::POINT_RADIUS: the feet are points in fbd
    d.qpos[1] += radius
    target = np.array([fb[n][0] for n in joints])
    prev = d.qpos[adr].copy()
    for k in range(int(round(DURATION / DT))):
        theta = d.qpos[adr].copy()
        rate = (theta - prev) / DT if k else np.zeros(len(adr))
        d.ctrl[:] = KP * (target - theta) - KD * rate
        prev = theta
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    foot_ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f) for f in FEET]
    normal = dict.fromkeys(FEET, 0.0)
    for i in range(d.ncon):
        c = d.contact[i]
        f = np.zeros(6)
        mujoco.mj_contactForce(m, d, i, f)
        g = c.geom1 if c.geom1 in foot_ids else c.geom2
        normal[FEET[foot_ids.index(g)]] += f[0]

    last = fb.iloc[-1]
    weight = float(np.sum([last[f + "_fy"] for f in FEET]))
    mass = float(m.body_subtreemass[1])
    assert abs(weight - mass * 9.81) < 1e-4 * weight, (weight, mass)  # at rest to 4e-5 m/s²
    for f in FEET:
        assert abs(last[f + "_n"] - normal[f]) < 1e-3 * weight, (f, last[f + "_n"], normal[f])
    angles = np.array([last[n] for n in joints])
    assert np.abs(angles - d.qpos[adr]).max() < 3e-3
    assert abs(last["ry"] - (d.qpos[1] - radius)) < 5e-4, (last["ry"], d.qpos[1] - radius)
    tau = np.array([last["tau_" + n] for n in joints])
    assert np.abs(tau - d.ctrl).max() < 0.02 * np.abs(tau).max(), (tau, d.ctrl)
