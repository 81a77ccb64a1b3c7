"""fbd.run of a hexapod configuration: the kinematic gait's columns equal
the CLI's trajectory.csv bit for bit; the defaults walk and stand."""

from __future__ import annotations

import json

import numpy as np
import pytest

import fbd
from conftest import run_cli
from test_run import assert_same_as_csv, bits, read_csv


def test_hexapod_walk_equals_cli_csv_bit_for_bit(cli, examples, tmp):
    cfg = examples / "hexapod_tripod.toml"
    out = tmp / "cli"
    p = run_cli(cli, "run", str(cfg), "--out", str(out))
    assert p.returncode == 0, p.stderr
    r = fbd.run(cfg)
    assert r.columns[:7] == ["t", "rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
    for name in ("theta3_6", "omega2_1", "alpha1_4", "foot5_y", "stance2", "com_x", "margin"):
        assert name in r.columns, name
    assert_same_as_csv(r, out / "trajectory.csv")
    # Events as events.csv: t, leg, event, margin.
    header, rows = read_csv(out / "events.csv")
    assert header == ["t", "leg", "event", "margin"]
    assert len(r.events) == len(rows) > 0
    for e, row in zip(r.events, rows):
        assert bits(e["t"]) == bits(float(row[0]))
        assert ("" if e["leg"] is None else str(e["leg"])) == row[1]
        assert e["event"] == row[2]
    want = json.loads((out / "summary.json").read_text())
    got = dict(r.summary)
    for k in ("wall_seconds", "steps_per_second"):
        want.pop(k)
        got.pop(k)
    assert got == want
    # The walk: 1 m forward (−Z), stance feet still, three feet down.
    assert r.summary["distance"] == pytest.approx(1.0, abs=1e-9)
    assert r["rz"][-1] == pytest.approx(-1.0, abs=1e-9)
    stance = np.stack([r[f"stance{n}"] for n in range(1, 7)])
    assert stance.sum(axis=0).min() == 3


def test_a_gait_table_alone_walks_and_a_kinematic_hexapod_stands(tmp):
    walk = fbd.run({"model": "hexapod", "gait": {}})
    assert walk.error is None
    assert walk.summary["run"] == "walking" and walk.summary["distance"] > 0.4
    assert walk["t"][-1] == 6.0
    # Without [gait] a hexapod runs the 3D dynamics unless told otherwise.
    stand = fbd.run('model = "hexapod"\ndynamics = "kinematic"\n', out=tmp / "stand")
    assert stand.summary["run"] == "standing"
    # Every foot on the ground and still.
    for n in range(1, 7):
        assert np.abs(stand[f"foot{n}_y"]).max() < 1e-9
        assert np.ptp(stand[f"foot{n}_x"]) == 0.0
    assert (tmp / "stand" / "gait.svg").is_file()


def test_hexapod_error_keeps_the_steps_computed():
    # A stride far beyond the legs' reach stops the walk naming the leg.
    with pytest.raises(fbd.SimulationError) as info:
        fbd.run({"model": "hexapod", "gait": {"period": 2.0, "forward_speed": 0.45, "ramp": 0.0}})
    assert "leg " in str(info.value)
    assert info.value.result.rows > 0
