"""Solo-12 from example-robot-data trotting (``examples/robots/solo12_trot.toml``).

``fbd run`` of the example (its URDF found through ``ROS_PACKAGE_PATH``,
set here to example-robot-data's ``robots`` folder): the diagonal pairs
lift off and touch down in turn, the robot moves forward (along −Z) at
most of its commanded 0.2 m/s (PD tracking of the planned joints, no body
feedback), stays upright and at its height, and every row of
``trajectory.csv`` obeys the contact laws it reports (``N ≥ 0``,
``|Ft| ≤ μS·N`` sticking, ``|Ft| = μD·N`` sliding, no force free) and the
whole robot's balance (``M·Δ²C/Δt² = M·g + Σ F``, from the ``com_*``
columns).
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import pathlib
import subprocess

import numpy as np
import pandas as pd

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples/robots/solo12_trot.toml"
FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]


def package_env() -> dict:
    dist = importlib.metadata.distribution("example-robot-data")
    robots = dist.locate_file("cmeel.prefix/share/example-robot-data/robots")
    return {**os.environ, "ROS_PACKAGE_PATH": str(robots)}


def test_solo12_trots_forward_within_the_laws(cli, tmp_path):
    out = tmp_path / "trot"
    r = subprocess.run([str(cli), "run", str(EXAMPLE), "--out", str(out)],
                       capture_output=True, text=True, env=package_env())
    assert r.returncode == 0, r.stderr
    fb = pd.read_csv(out / "trajectory.csv")
    events = pd.read_csv(out / "events.csv")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["retried_steps"] == 0

    # The diagonal pairs alternate: each foot lifts off once a period
    # (0.5 s) from t = 0.5 s, FL with HR and FR with HL.
    lift = {f: events[(events.point == f) & (events.to == "ST1")].t.to_numpy() for f in FEET}
    for f in FEET:
        assert len(lift[f]) == 5, (f, lift[f])
    assert np.allclose(lift["FL_FOOT"], lift["HR_FOOT"], atol=0.01)
    assert np.allclose(lift["FR_FOOT"], lift["HL_FOOT"], atol=0.01)
    assert np.allclose(np.diff(lift["FL_FOOT"]), 0.5, atol=0.01)
    assert np.allclose(lift["FR_FOOT"] - lift["FL_FOOT"], 0.25, atol=0.01)

    # Forward at most of 0.2 m/s once the ramp is over, upright, at height.
    t = fb.t.to_numpy()
    a, b = np.argmin(abs(t - 1.5)), len(t) - 1
    speed = -(fb.rz[b] - fb.rz[a]) / (t[b] - t[a])
    print(f"Solo-12 trot: {speed:.3f} m/s forward over the last 1.5 s")
    assert 0.1 < speed < 0.22
    assert abs(fb.rx[b] - fb.rx[a]) < 0.03
    assert np.abs(fb[["phi_x", "phi_z"]].to_numpy()).max() < 0.05
    assert fb.ry.min() > 0.19

    # The contact laws on every row (flat ground: the normal is +Y).
    mu_s, mu_d = 0.8, 0.6
    weight = 0.0
    for f in FEET:
        n = fb[f + "_fy"].to_numpy()
        ft = np.hypot(fb[f + "_fx"], fb[f + "_fz"]).to_numpy()
        st = fb[f + "_state"].to_numpy()
        free = st == "ST1"
        assert np.abs(fb.loc[free, [f + "_fx", f + "_fy", f + "_fz"]].to_numpy()).max(initial=0) == 0
        assert n[~free].min() > -1e-7
        assert (ft - mu_s * n)[st == "ST2"].max(initial=-1) < 1e-6
        assert np.abs(ft - mu_d * n)[st == "ST3"].max(initial=0) < 1e-6
        weight += n.mean()
    # The whole robot: M·Δ²C/Δt² = M·g + Σ contact forces.
    mass = weight / 9.81  # about (the mean vertical force of a walk ≈ weight)
    dt = 0.001
    com = fb[["com_x", "com_y", "com_z"]].to_numpy()
    acc = (com[2:] - 2 * com[1:-1] + com[:-2]) / dt**2
    forces = sum(fb[[f + "_fx", f + "_fy", f + "_fz"]].to_numpy() for f in FEET)[1:-1]
    m = float(json.loads(subprocess.run([str(cli), "kinematics", str(EXAMPLE)], capture_output=True,
                                        text=True, env=package_env()).stdout)["mass"])
    assert abs(mass - m) < 0.05 * m
    residual = m * acc - (forces + np.array([0.0, -m * 9.81, 0.0]))
    assert np.abs(residual).max() < 1e-5 * m * 9.81, np.abs(residual).max()
