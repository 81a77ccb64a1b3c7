"""``fbd run`` of imported robots in flight against MuJoCo 4.0.0.

Each robot tossed upward and tumbling with passive joints — the lab
hexapod (``examples/robots/lab_hexapod_flight.toml``) and Solo-12 from
example-robot-data (the same initial motion on its twelve joints) — run by
fbd at Δt = 2 ms and 1 ms and by MuJoCo (``fbd export mjcf`` of the same
configuration, RK4, Δt = 0.1 ms, constraints — the ground, the joint
limits — switched off, no damping or armature) from the same state: every
joint angle and the root's position agree at the common times, fbd's error
shrinking about 4× when Δt halves (second order).
"""

from __future__ import annotations

import importlib.metadata
import os
import pathlib
import subprocess
import tomllib

import mujoco
import pytest
import numpy as np
import pandas as pd

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples/robots/lab_hexapod_flight.toml"
DURATION = 0.3


SOLO_FLIGHT = """model = "robot"
[robot]
urdf = "package://solo_description/robots/solo12.urdf"
contacts = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
[initial]
position = [0.0, 0.3, 0.0]
phi_deg = [10.0, 20.0, -5.0]
velocity = [0.2, 2.0, -0.1]
omega_deg = [40.0, 60.0, -30.0]
joints_deg = { FL_HFE = 45.0, FL_KFE = -90.0, FR_HFE = 45.0, FR_KFE = -90.0, HL_HFE = -45.0, HL_KFE = 90.0, HR_HFE = -45.0, HR_KFE = 90.0 }
rates_deg = { FL_HAA = 40.0, FR_HFE = -30.0, HL_KFE = 60.0, HR_HAA = -50.0, FL_KFE = 80.0, HR_KFE = -70.0 }
[time]
dt = 0.001
duration = 0.5
[terrain]
kind = "none"
"""


def package_env() -> dict:
    dist = importlib.metadata.distribution("example-robot-data")
    robots = dist.locate_file("cmeel.prefix/share/example-robot-data/robots")
    return {**os.environ, "ROS_PACKAGE_PATH": str(robots)}


def config(tmp_path: pathlib.Path, dt: float, robot: str = "lab") -> pathlib.Path:
    if robot == "solo12":
        text = SOLO_FLIGHT.replace("dt = 0.001", f"dt = {dt!r}").replace(
            "duration = 0.5", f"duration = {DURATION!r}")
        path = tmp_path / f"solo_{dt}.toml"
        path.write_text(text)
        return path
    text = EXAMPLE.read_text()
    urdf = (ROOT / "examples/robots/lab_hexapod.urdf").resolve()
    for old, new in [('urdf = "lab_hexapod.urdf"', f'urdf = "{urdf}"'),
                     ("dt = 0.001", f"dt = {dt!r}"),
                     ("duration = 0.5", f"duration = {DURATION!r}")]:
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / f"flight_{dt}.toml"
    path.write_text(text)
    return path


def fbd_run(cli, tmp_path, dt, robot="lab") -> pd.DataFrame:
    out = tmp_path / f"out_{robot}_{dt}"
    r = subprocess.run([str(cli), "run", str(config(tmp_path, dt, robot)), "--out", str(out)],
                       capture_output=True, text=True, env=package_env())
    assert r.returncode == 0, r.stderr
    return pd.read_csv(out / "trajectory.csv")


def mujoco_run(cli, tmp_path, times, joints, robot="lab"):
    """MuJoCo's root position and joint angles at `times` (multiples of its step)."""
    xml = tmp_path / f"flight_{robot}.xml"
    cfg = config(tmp_path, 0.001, robot)
    r = subprocess.run([str(cli), "export", "mjcf", str(cfg), "--out", str(xml)],
                       capture_output=True, text=True, env=package_env())
    assert r.returncode == 0, r.stderr
    model = mujoco.MjModel.from_xml_path(str(xml))
    h = 1e-4
    model.opt.timestep = h
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    model.dof_damping[:] = 0.0
    model.dof_armature[:] = 0.0
    data = mujoco.MjData(model)
    # The initial state of the configuration (read back from fbd's copy of
    # it: the export places the root at the initial pose already).
    init = tomllib.loads(cfg.read_text())["initial"]
    data.qpos[:] = model.qpos0
    for name, deg in init.get("joints_deg", {}).items():
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        data.qpos[model.jnt_qposadr[j]] = np.radians(deg)
    for name, deg in init.get("rates_deg", {}).items():
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        data.qvel[model.jnt_dofadr[j]] = np.radians(deg)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, data.qpos[3:7])
    rot = rot.reshape(3, 3)
    data.qvel[:3] = init["velocity"]                              # world, root origin
    data.qvel[3:6] = rot.T @ np.radians(init["omega_deg"])        # body frame
    steps = np.rint(np.asarray(times) / h).astype(int)
    adr = [model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in joints]
    rows, k = [], 0
    for target in steps:
        while k < target:
            mujoco.mj_step(model, data)
            k += 1
        rows.append(np.concatenate([data.qpos[:3], data.qpos[adr]]))
    return np.array(rows)


@pytest.mark.parametrize("robot", ["lab", "solo12"])
def test_a_tumbling_flight_converges_to_mujoco_at_second_order(cli, tmp_path, robot):
    coarse = fbd_run(cli, tmp_path, 0.002, robot)
    fine = fbd_run(cli, tmp_path, 0.001, robot)
    n = 18 if robot == "lab" else 12
    joints = list(coarse.columns[7:7 + n])
    first, last = ("lf_coxa_joint", "rr_tibia_joint") if robot == "lab" else ("FL_HAA", "HR_KFE")
    assert joints[0] == first and joints[-1] == last
    times = np.round(coarse["t"].to_numpy(), 9)
    reference = mujoco_run(cli, tmp_path, times, joints, robot)
    columns = ["rx", "ry", "rz", *joints]

    def error(run):
        at = run.set_index(np.round(run["t"].to_numpy(), 9)).loc[times, columns].to_numpy()
        return np.abs(at - reference).max()

    e2, e1 = error(coarse), error(fine)
    ratio = e2 / e1
    print(f"{robot}: max |fbd − MuJoCo| over root position and joint angles: "
          f"Δt = 2 ms {e2:.3e}, 1 ms {e1:.3e}, ratio {ratio:.2f}")
    # It moves: the joints swing and the root climbs and falls.
    assert np.ptp(reference[:, 3:], axis=0).max() > 0.2
    assert 3.0 <= ratio <= 5.0
    assert e1 < 1e-5
