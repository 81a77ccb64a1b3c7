"""Imported robots (``model = "robot"``) against Pinocchio.

``fbd kinematics`` of a URDF robot — real descriptions from PyPI
``example-robot-data`` and the lab hexapod of ``examples/robots`` — is
compared with Pinocchio (PyPI ``pin``) loading the same file with a free
flyer: every body's frame, every foot, every body's mass, centre of mass
and inertia (fixed links merged), and the total mass and centre of mass.
fbd's inertial frame is Y-up; a URDF's is Z-up, so fbd places the
description turned by ``x → −z, y → −x, z → y``.
"""

from __future__ import annotations

import importlib.metadata
import math
import pathlib
import subprocess

import numpy as np
import pytest

import pinocchio as pin  # installed by scripts/test-python.sh
from robot_state import TURN, fbd_json, write_config

ROOT = pathlib.Path(__file__).resolve().parents[3]



def robots_dir() -> pathlib.Path:
    dist = importlib.metadata.distribution("example-robot-data")
    return pathlib.Path(dist.locate_file("cmeel.prefix/share/example-robot-data/robots"))


# (name, URDF path, foot links)
ROBOTS = [
    ("solo12", "solo_description/robots/solo12.urdf", ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]),
    ("anymal_c", "anymal_c_simple_description/urdf/anymal.urdf", ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"]),
    ("go1", "go1_description/urdf/go1.urdf", ["FR_foot", "FL_foot", "RR_foot", "RL_foot"]),
    ("a1", "a1_description/urdf/a1.urdf", ["FR_foot", "FL_foot", "RR_foot", "RL_foot"]),
    ("hyq", "hyq_description/robots/hyq_no_sensors.urdf", ["lf_foot", "rf_foot", "lh_foot", "rh_foot"]),
    ("bolt", "bolt_description/robots/bolt.urdf", ["FL_FOOT", "FR_FOOT"]),
]


def urdf_path(rel: str) -> pathlib.Path:
    if rel.startswith("examples/"):
        return ROOT / rel
    return robots_dir() / rel


def fbd_kinematics(cli, tmp_path, urdf: pathlib.Path, feet, angles_deg, position):
    cfg = write_config(tmp_path / "robot.toml", urdf, contacts=feet, angles=angles_deg,
                       position=position)
    return fbd_json(cli, "kinematics", cfg)


def random_angles(model, rng):
    """Joint angles (deg) inside each joint's limits (±2 rad where wide)."""
    angles = {}
    for jid in range(2, model.njoints):
        name = model.names[jid]
        i = model.joints[jid].idx_q
        lo = max(model.lowerPositionLimit[i], -2.0)
        hi = min(model.upperPositionLimit[i], 2.0)
        if not lo < hi:
            lo, hi = -2.0, 2.0
        angles[name] = math.degrees(rng.uniform(lo, hi))
    return angles


@pytest.mark.parametrize("name,rel,feet", ROBOTS + [
    ("lab_hexapod", "examples/robots/lab_hexapod.urdf",
     [f"{leg}_foot" for leg in ("lf", "lm", "lr", "rf", "rm", "rr")]),
])
def test_imported_urdf_matches_pinocchio(cli, tmp_path, name, rel, feet):
    path = urdf_path(rel)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    rng = np.random.default_rng(7)
    position = np.array([0.3, 0.5, -0.2])
    for trial in range(3):
        angles = random_angles(model, rng) if trial else {}
        fbd = fbd_kinematics(cli, tmp_path, path, feet, angles, position)

        q = pin.neutral(model)
        for jname, deg in angles.items():
            q[model.joints[model.getJointId(jname)].idx_q] = math.radians(deg)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)

        def world(p):
            return position + TURN @ np.asarray(p)

        # Same joints, same bodies.
        assert sorted(j["name"] for j in fbd["joints"]) == sorted(model.names[2:])
        bodies = {b["name"]: b for b in fbd["bodies"]}
        for j in fbd["joints"]:
            jid = model.getJointId(j["name"])
            oMi = data.oMi[jid]
            body = bodies[j["child"]]
            np.testing.assert_allclose(body["position"], world(oMi.translation), atol=1e-12)
            np.testing.assert_allclose(np.array(body["rotation"]), TURN @ oMi.rotation, atol=1e-12)
            axis = TURN @ oMi.rotation @ np.asarray(data.joints[jid].S).reshape(6, -1)[3:, 0]
            np.testing.assert_allclose(j["axis"], axis, atol=1e-12)
            # Mass properties, fixed children merged (Pinocchio merges
            # them into the joint's inertia too).
            inertia = model.inertias[jid]
            assert body["mass"] == pytest.approx(inertia.mass, rel=1e-12, abs=1e-15)
            np.testing.assert_allclose(body["com"], inertia.lever, atol=1e-12)
            np.testing.assert_allclose(np.array(body["inertia"]), inertia.inertia, atol=1e-12)
        # The root (turned into fbd's body frame).
        root = fbd["bodies"][0]
        inertia = model.inertias[1]
        assert root["mass"] == pytest.approx(inertia.mass, rel=1e-12)
        np.testing.assert_allclose(root["com"], TURN @ inertia.lever, atol=1e-12)
        np.testing.assert_allclose(np.array(root["inertia"]), TURN @ inertia.inertia @ TURN.T, atol=1e-12)
        # Feet.
        for c in fbd["contacts"]:
            fid = model.getFrameId(c["name"])
            np.testing.assert_allclose(c["position"], world(data.oMf[fid].translation), atol=1e-12)
        # Whole robot.
        assert fbd["mass"] == pytest.approx(pin.computeTotalMass(model), rel=1e-12)
        com = pin.centerOfMass(model, data, q)
        np.testing.assert_allclose(fbd["com"], world(com), atol=1e-12)


def test_a_mesh_only_foot_is_one_clear_error(cli, tmp_path):
    path = urdf_path(ROBOTS[0][1])
    cfg = tmp_path / "robot.toml"
    cfg.write_text(f'model = "robot"\n[robot]\nurdf = "{path}"\n')
    out = subprocess.run([str(cli), "kinematics", str(cfg)], capture_output=True, text=True)
    assert out.returncode != 0
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert "solo12.urdf:" in lines[0] and "<mesh>" in lines[0] and "a foot whose collision is a mesh" in lines[0]
    assert "[robot] contacts" in lines[0]


def rot_fbd(phi):
    """fbd's Rot = Rx(φx)·Rz(φz)·Ry(φy)."""
    (sx, cx), (sy, cy), (sz, cz) = [(math.sin(p), math.cos(p)) for p in phi]
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rx @ rz @ ry



@pytest.mark.parametrize("name,rel,feet", ROBOTS + [
    ("lab_hexapod", "examples/robots/lab_hexapod.urdf", ["lf_foot"]),
])
def test_fbd_inverse_dynamics_matches_pinocchio_rnea(cli, tmp_path, name, rel, feet):
    """Every joint's force, moment and torque by the FBD method (each body
    isolated, leaves to root) against Pinocchio's recursive Newton–Euler
    (``rnea`` and the joint forces ``data.f`` it leaves), for random
    states: base pose, velocities and accelerations, joint angles, rates
    and accelerations."""
    path = urdf_path(rel)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    rng = np.random.default_rng(11)
    for trial in range(3):
        position = rng.uniform(-1, 1, 3)
        phi = rng.uniform(-1.5, 1.5, 3)
        vel, omega = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
        acc, alpha = rng.uniform(-5, 5, 3), rng.uniform(-10, 10, 3)
        angles = random_angles(model, rng)
        rates = {k: math.degrees(rng.uniform(-3, 3)) for k in angles}
        accels = {k: math.degrees(rng.uniform(-30, 30)) for k in angles}
        cfg = write_config(tmp_path / "robot.toml", path, contacts=feet, position=position,
                           phi=phi, velocity=vel, omega=omega, angles=angles, rates=rates,
                           acceleration=acc, alpha=alpha, accelerations=accels)
        fbd = fbd_json(cli, "inverse", cfg)

        # Pinocchio's state: its world is fbd's turned back (TURNᵀ).
        r_pin = TURN.T @ rot_fbd(phi) @ TURN
        q = pin.neutral(model)
        q[:3] = TURN.T @ position
        q[3:7] = pin.Quaternion(r_pin).coeffs()  # x, y, z, w
        v = np.zeros(model.nv)
        a = np.zeros(model.nv)
        v_lin = r_pin.T @ (TURN.T @ vel)
        w_loc = r_pin.T @ (TURN.T @ omega)
        v[:3], v[3:6] = v_lin, w_loc
        a[:3] = r_pin.T @ (TURN.T @ acc) - np.cross(w_loc, v_lin)
        a[3:6] = r_pin.T @ (TURN.T @ alpha)
        for jname in angles:
            jm = model.joints[model.getJointId(jname)]
            q[jm.idx_q] = math.radians(angles[jname])
            v[jm.idx_v] = math.radians(rates[jname])
            a[jm.idx_v] = math.radians(accels[jname])
        tau = pin.rnea(model, data, q, v, a)
        pin.forwardKinematics(model, data, q)  # rnea leaves data.oMi as it was

        weight = pin.computeTotalMass(model) * 9.81
        tol = 1e-9 * (1 + weight)
        for j in fbd["joints"]:
            jid = model.getJointId(j["name"])
            rot = TURN @ data.oMi[jid].rotation
            f = data.f[jid]
            np.testing.assert_allclose(j["force"], rot @ f.linear, atol=tol, err_msg=j["name"])
            np.testing.assert_allclose(j["moment"], rot @ f.angular, atol=tol, err_msg=j["name"])
            assert j["torque"] == pytest.approx(tau[model.joints[jid].idx_v], abs=tol), j["name"]
        rot = TURN @ r_pin
        np.testing.assert_allclose(fbd["base_force"], rot @ tau[:3], atol=tol)
        np.testing.assert_allclose(fbd["base_moment"], rot @ tau[3:6], atol=tol)


def test_fbd_inverse_along_a_motion_matches_pinocchio(cli, tmp_path):
    """``fbd inverse --motion``: a recorded motion of Solo-12 (every joint
    and the base moving smoothly, sampled at 100 Hz) against Pinocchio's
    ``rnea`` fed the same central differences (joints and base position:
    ``(x[k+1] − x[k−1])/2Δt``, ``(x[k+1] − 2x[k] + x[k−1])/Δt²``; base
    rotation: ``ω`` at the half steps from ``log(R[k+1]·R[k]ᵀ)/Δt``)."""
    import pandas as pd

    name, rel, feet = ROBOTS[0]
    path = urdf_path(rel)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    names = [model.names[i] for i in range(2, model.njoints)]
    dt, n = 0.01, 40
    t = np.arange(n) * dt
    rng = np.random.default_rng(3)
    amp, freq, phase = rng.uniform(0.2, 0.8, len(names)), rng.uniform(1, 4, len(names)), rng.uniform(0, 6, len(names))
    q = {nm: amp[i] * np.sin(freq[i] * t + phase[i]) for i, nm in enumerate(names)}
    base = {
        "rx": 0.1 * t, "ry": 0.3 + 0.05 * np.sin(3 * t), "rz": -0.2 * t * t,
        "phi_x": 0.3 * np.sin(2 * t), "phi_y": 0.5 * t, "phi_z": 0.2 * np.cos(t),
    }
    motion = pd.DataFrame({"t": t, **base, **q})
    motion_csv = tmp_path / "motion.csv"
    motion.to_csv(motion_csv, index=False, float_format="%.17g")
    cfg = write_config(tmp_path / "robot.toml", path, contacts=feet)
    out_csv = tmp_path / "forces.csv"
    r = subprocess.run([str(cli), "inverse", str(cfg), "--motion", str(motion_csv), "--out", str(out_csv)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    fbd = pd.read_csv(out_csv)
    assert len(fbd) == n - 2
    np.testing.assert_allclose(fbd["t"], t[1:-1], atol=1e-12)

    def rot(k):
        return rot_fbd([base["phi_x"][k], base["phi_y"][k], base["phi_z"][k]])

    def pos(k):
        return np.array([base["rx"][k], base["ry"][k], base["rz"][k]])

    weight = pin.computeTotalMass(model) * 9.81
    for row, k in enumerate(range(1, n - 1)):
        r0, r1, r2 = rot(k - 1), rot(k), rot(k + 1)
        w_minus = pin.log3(r1 @ r0.T) / dt
        w_plus = pin.log3(r2 @ r1.T) / dt
        omega, alpha = (w_minus + w_plus) / 2, (w_plus - w_minus) / dt
        vel = (pos(k + 1) - pos(k - 1)) / (2 * dt)
        acc = (pos(k + 1) - 2 * pos(k) + pos(k - 1)) / dt**2
        r_pin = TURN.T @ r1 @ TURN
        qv = pin.neutral(model)
        qv[:3] = TURN.T @ pos(k)
        qv[3:7] = pin.Quaternion(r_pin).coeffs()
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v_lin, w_loc = r_pin.T @ (TURN.T @ vel), r_pin.T @ (TURN.T @ omega)
        v[:3], v[3:6] = v_lin, w_loc
        a[:3] = r_pin.T @ (TURN.T @ acc) - np.cross(w_loc, v_lin)
        a[3:6] = r_pin.T @ (TURN.T @ alpha)
        for nm in names:
            jm = model.joints[model.getJointId(nm)]
            x = q[nm]
            qv[jm.idx_q] = x[k]
            v[jm.idx_v] = (x[k + 1] - x[k - 1]) / (2 * dt)
            a[jm.idx_v] = (x[k + 1] - 2 * x[k] + x[k - 1]) / dt**2
        tau = pin.rnea(model, data, qv, v, a)
        pin.forwardKinematics(model, data, qv)
        tol = 1e-8 * (1 + weight)
        got = fbd.iloc[row]
        for nm in names:
            jid = model.getJointId(nm)
            assert got[f"tau_{nm}"] == pytest.approx(tau[model.joints[jid].idx_v], abs=tol), (k, nm)
            rot_j = TURN @ data.oMi[jid].rotation
            f = [got[f"{nm}_f{c}"] for c in "xyz"]
            np.testing.assert_allclose(f, rot_j @ data.f[jid].linear, atol=tol)
            m = [got[f"{nm}_m{c}"] for c in "xyz"]
            np.testing.assert_allclose(m, rot_j @ data.f[jid].angular, atol=tol)
        rb = TURN @ r_pin
        np.testing.assert_allclose([got[f"base_f{c}"] for c in "xyz"], rb @ tau[:3], atol=tol)
        np.testing.assert_allclose([got[f"base_m{c}"] for c in "xyz"], rb @ tau[3:6], atol=tol)


def test_the_python_api_gives_what_the_cli_gives(cli, tmp_path):
    """``fbd.kinematics``, ``fbd.inverse`` and ``fbd.inverse(motion=…)`` on
    an imported robot equal ``fbd kinematics``, ``fbd inverse`` and ``fbd
    inverse --motion`` (one library under both), for a path, TOML text and
    a dict."""
    import fbd
    import pandas as pd

    lab = ROOT / "examples/robots/lab_hexapod.toml"
    for command, call in (("kinematics", fbd.kinematics), ("inverse", fbd.inverse)):
        want = fbd_json(cli, command, lab)
        assert call(lab) == want
        assert call(str(lab)) == want
        text = lab.read_text().replace('urdf = "lab_hexapod.urdf"', f'urdf = "{lab.parent / "lab_hexapod.urdf"}"')
        assert call(text) == want
    d = {"model": "robot", "robot": {"urdf": str(lab.parent / "lab_hexapod.urdf")}}
    assert fbd.kinematics(d)["mass"] == pytest.approx(3.76)

    t = np.arange(12) * 0.02
    motion = pd.DataFrame({"t": t, "ry": 0.2 + 0.1 * t})
    for i, j in enumerate(fbd.kinematics(lab)["joints"]):
        motion[j["name"]] = 0.3 * np.sin(3 * t + i)
    motion_csv = tmp_path / "motion.csv"
    motion.to_csv(motion_csv, index=False, float_format="%.17g")
    out = subprocess.run([str(cli), "inverse", str(lab), "--motion", str(motion_csv)],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    want = pd.read_csv(__import__("io").StringIO(out.stdout))
    got = fbd.inverse(lab, motion)
    assert list(got) == list(want.columns)
    for c in want.columns:
        np.testing.assert_array_equal(got[c], want[c].to_numpy(), err_msg=c)
    got_dict = fbd.inverse(lab, {c: motion[c].to_numpy() for c in motion.columns})
    np.testing.assert_array_equal(got_dict["tau_lf_femur_joint"], got["tau_lf_femur_joint"])
    with pytest.raises(fbd.ConfigError, match="samples must be uniformly spaced"):
        fbd.inverse(lab, motion.assign(t=t * t))
    with pytest.raises(ValueError, match="model = \"robot\""):
        fbd.inverse(ROOT / "examples/paper.toml")
