"""Imported MJCF robots against MuJoCo loading the same file.

Also ``fbd export mjcf`` of imported URDF robots (the lab hexapod, Solo-12):
MuJoCo and fbd read the exported file alike.

``fbd kinematics`` and ``fbd inverse`` of an MJCF description — the
hexapod that ``fbd export mjcf`` writes and a small quadruped with
defaults, classes, Euler angles, two hinges at different points of one
body, a welded body and masses from geoms
(``crates/robot/tests/data/mjcf_quadruped.xml``) — against MuJoCo 4.0.0
(PyPI ``mujoco``): every body's mass and centre of mass, every contact
sphere, the whole robot's mass and centre of mass (``mj_kinematics``), and
every joint torque and the root's wrench (``mj_inverse``, with MuJoCo's
constraints, damping and armature switched off: fbd's inverse dynamics
is the rigid-body part).
"""

from __future__ import annotations

import math
import pathlib
import subprocess

import mujoco
import numpy as np
import pytest
from robot_state import TURN, fbd_json, write_config

ROOT = pathlib.Path(__file__).resolve().parents[3]



def hexapod_xml(cli, tmp_path):
    out = tmp_path / "hexapod.xml"
    r = subprocess.run([str(cli), "export", "mjcf", str(ROOT / "examples/hexapod_drop.toml"),
                        "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out, "y"


def quadruped_xml(cli, tmp_path):
    return ROOT / "crates/robot/tests/data/mjcf_quadruped.xml", "z"


def exported(cli, tmp_path, config):
    out = tmp_path / "exported.xml"
    r = subprocess.run([str(cli), "export", "mjcf", str(config), "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out, "y"


def lab_export_xml(cli, tmp_path):
    """``fbd export mjcf`` of an imported URDF robot (the lab hexapod)."""
    return exported(cli, tmp_path, ROOT / "examples/robots/lab_hexapod.toml")


def solo_export_xml(cli, tmp_path):
    """``fbd export mjcf`` of Solo-12 from example-robot-data (feet named)."""
    import importlib.metadata

    dist = importlib.metadata.distribution("example-robot-data")
    urdf = dist.locate_file("cmeel.prefix/share/example-robot-data/robots/solo_description/robots/solo12.urdf")
    cfg = write_config(tmp_path / "solo.toml", urdf,
                       contacts=["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"])
    return exported(cli, tmp_path, cfg)


@pytest.mark.parametrize("which", [hexapod_xml, quadruped_xml, lab_export_xml, solo_export_xml])
def test_imported_mjcf_matches_mujoco(cli, tmp_path, which):
    path, up = which(cli, tmp_path)
    turn = TURN if up == "z" else np.eye(3)
    model = mujoco.MjModel.from_xml_path(str(path))
    model.dof_damping[:] = 0.0
    model.dof_armature[:] = 0.0
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    data = mujoco.MjData(model)
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    rng = np.random.default_rng(5)
    for trial in range(3):
        position = rng.uniform(-1, 1, 3)
        vel, omega = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
        acc, alpha = rng.uniform(-5, 5, 3), rng.uniform(-10, 10, 3)
        angles, rates, accels = {}, {}, {}
        for j in hinges:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
            lo, hi = model.jnt_range[j] if model.jnt_limited[j] else (-2.0, 2.0)
            mid, half = (lo + hi) / 2, min((hi - lo) / 2, 2.0)
            angles[name] = math.degrees(rng.uniform(mid - half, mid + half))
            rates[name] = math.degrees(rng.uniform(-3, 3))
            accels[name] = math.degrees(rng.uniform(-30, 30))
        cfg = write_config(tmp_path / "robot.toml", path, kind="mjcf", up=up,
                           position=position, velocity=vel, omega=omega, angles=angles,
                           rates=rates, acceleration=acc, alpha=alpha, accelerations=accels)
        kin = fbd_json(cli, "kinematics", cfg)
        inv = fbd_json(cli, "inverse", cfg)

        # MuJoCo's state: the root at its world origin, unturned; fbd's
        # world is MuJoCo's turned and shifted by `position`.
        data.qpos[:] = model.qpos0
        data.qpos[:3] = 0.0
        data.qpos[3:7] = [1.0, 0.0, 0.0, 0.0]
        data.qvel[:] = 0.0
        data.qacc[:] = 0.0
        data.qvel[:3] = turn.T @ vel
        data.qvel[3:6] = turn.T @ omega          # root frame = world here
        data.qacc[:3] = turn.T @ acc
        data.qacc[3:6] = turn.T @ alpha
        for j in hinges:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
            data.qpos[model.jnt_qposadr[j]] = math.radians(angles[name])
            data.qvel[model.jnt_dofadr[j]] = math.radians(rates[name])
            data.qacc[model.jnt_dofadr[j]] = math.radians(accels[name])
        mujoco.mj_inverse(model, data)  # runs the kinematics too

        def world(p):
            return position + turn @ np.asarray(p)

        # Each of fbd's bodies is a MuJoCo body with its welded (jointless)
        # descendants merged in: the same mass and centre of mass.
        def welded_group(b):
            group = [b]
            for child in range(b + 1, model.nbody):
                if model.body_parentid[child] in group and model.body_jntnum[child] == 0:
                    group.append(child)
            return group

        compared = 0
        for ours in kin["bodies"]:
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, ours["name"])
            if b < 0:
                assert ours["mass"] == 0.0, ours["name"]  # a frame between two hinges
                continue
            group = welded_group(b)
            mass = sum(model.body_mass[g] for g in group)
            assert ours["mass"] == pytest.approx(mass, rel=1e-12), ours["name"]
            if mass > 0:
                want = sum(model.body_mass[g] * data.xipos[g] for g in group) / mass
                rot = np.array(ours["rotation"])
                com = np.array(ours["position"]) + rot @ np.array(ours["com"])
                np.testing.assert_allclose(com, world(want), atol=1e-10, err_msg=ours["name"])
                compared += 1
        assert compared == sum(1 for o in kin["bodies"] if o["mass"] > 0)
        for c in kin["contacts"]:
            g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, c["name"])
            assert g >= 0, c["name"]
            np.testing.assert_allclose(c["position"], world(data.geom_xpos[g]), atol=1e-10, err_msg=c["name"])
            assert c["radius"] == pytest.approx(model.geom_size[g][0])
        assert kin["mass"] == pytest.approx(sum(model.body_mass), rel=1e-12)
        np.testing.assert_allclose(kin["com"], world(data.subtree_com[1]), atol=1e-10)

        scale = 1.0 + sum(model.body_mass) * 9.81
        tau = {j["name"]: j["torque"] for j in inv["joints"]}
        for j in hinges:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
            got = tau[name]
            want = data.qfrc_inverse[model.jnt_dofadr[j]]
            assert got == pytest.approx(want, abs=1e-9 * scale), name
        # The free joint: a world force, and a torque in the root's frame
        # (= world here) about the root's origin.
        np.testing.assert_allclose(inv["base_force"], turn @ data.qfrc_inverse[:3], atol=1e-9 * scale)
        np.testing.assert_allclose(inv["base_moment"], turn @ data.qfrc_inverse[3:6], atol=1e-9 * scale)
