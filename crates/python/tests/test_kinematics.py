"""fbd.kinematics equals `fbd kinematics`; forward and inverse kinematics on
NumPy arrays agree with it and with each other."""

from __future__ import annotations

import json

import numpy as np
import pytest

import fbd
from conftest import run_cli


@pytest.mark.parametrize("example", ["paper.toml", "hexapod_pose.toml"])
def test_kinematics_equals_cli_json(cli, examples, example):
    p = run_cli(cli, "kinematics", str(examples / example))
    assert p.returncode == 0, p.stderr
    assert fbd.kinematics(examples / example) == json.loads(p.stdout)


def test_planar_fk_matches_kinematics(examples):
    k = fbd.kinematics(examples / "paper.toml")
    sim = fbd.Simulator(examples / "paper.toml")
    pts = fbd.planar_fk(sim.q0)
    for i, leg in enumerate(k["legs"]):
        for name in ("hip", "knee", "tip"):
            np.testing.assert_array_equal(pts[name][i], leg[name][:2])
    # Batches: one row per configuration.
    r = fbd.run({"time": {"duration": 0.3}})
    q = np.column_stack([r[c] for c in ("rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4")])
    batch = fbd.planar_fk(q)
    assert batch["tip"].shape == (r.rows, 2, 2)
    # The run's points are those of its equations: within a step the
    # simulator takes the sines and cosines of nearby iterates from their
    # series, exact to rounding, so they agree with a fresh evaluation to
    # an ulp, not to the bit.
    np.testing.assert_allclose(batch["tip"][:, 0, 0], r["tip3_x"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(batch["tip"][:, 1, 1], r["tip4_y"], rtol=0, atol=1e-15)
    # Rigid links: |knee − hip| = a, |tip − knee| = c in every row.
    np.testing.assert_allclose(np.linalg.norm(batch["knee"] - batch["hip"], axis=-1), 0.2, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(batch["tip"] - batch["knee"], axis=-1), 0.42, atol=1e-12)


def hexapod_q(position, phi_deg, joints_deg):
    return np.concatenate([position, np.radians(phi_deg), np.radians(np.ravel(joints_deg))])


def test_hexapod_fk_matches_kinematics(examples):
    cfg = examples / "hexapod_pose.toml"
    k = fbd.kinematics(cfg)
    q = hexapod_q([0.0, 0.36, 0.0], [0, 0, 0], [[0.0, -20.0, 290.0]] * 6)
    pts = fbd.hexapod_fk(q, cfg)
    assert pts["tip"].shape == (6, 3)
    for i, leg in enumerate(k["legs"]):
        for name in ("hip", "knee", "tip"):
            np.testing.assert_allclose(pts[name][i], leg[name], rtol=0, atol=1e-15)
    batch = fbd.hexapod_fk(np.stack([q, q]), cfg)
    assert batch["hip"].shape == (2, 6, 3)


def test_leg_ik_inverts_fk():
    rng = np.random.default_rng(7)
    joints = np.column_stack(
        [rng.uniform(-0.5, 0.5, 20), rng.uniform(-0.6, 0.6, 20), rng.uniform(3.6, 5.6, 20)]
    )
    for leg in range(1, 7):
        qs = []
        for j in joints:
            angles = np.zeros((6, 3))
            angles[leg - 1] = j
            qs.append(np.concatenate([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], angles.ravel()]))
        tips = fbd.hexapod_fk(np.array(qs))["tip"][:, leg - 1]
        # Body at the origin, unrotated: inertial = body coordinates.
        got = fbd.leg_ik(tips, leg=leg, knee="up")
        assert np.all((got[:, 2] >= np.pi) & (got[:, 2] <= 2 * np.pi))
        # The angles found put the tip back on every target (the solution
        # with the tip outward, which may differ from `joints` by θ1 ± π).
        back = []
        for g in got:
            angles = np.zeros((6, 3))
            angles[leg - 1] = g
            back.append(np.concatenate([np.zeros(6), angles.ravel()]))
        np.testing.assert_allclose(fbd.hexapod_fk(np.array(back))["tip"][:, leg - 1], tips, rtol=0, atol=1e-12)
        # Where the given angles are the outward solution, they come back.
        same = np.isclose(got[:, 0], joints[:, 0], atol=1e-9)
        assert same.sum() >= len(joints) // 2
        np.testing.assert_allclose(got[same], joints[same], rtol=0, atol=1e-9)


def test_leg_ik_errors():
    with pytest.raises(ValueError, match=r"targets\[1\]"):
        fbd.leg_ik([[-0.3, 0.0, -0.3], [-5.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="knee"):
        fbd.leg_ik([-0.3, 0.0, -0.3], knee="sideways")
    with pytest.raises(ValueError, match="leg"):
        fbd.leg_ik([-0.3, 0.0, -0.3], leg=7)
    with pytest.raises(ValueError, match="shape"):
        fbd.planar_fk(np.zeros(6))
    assert fbd.leg_ik([-0.3, 0.0, -0.3]).shape == (3,)
