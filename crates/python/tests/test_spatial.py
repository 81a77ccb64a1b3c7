"""fbd.run of a dynamic hexapod configuration (the 3D FBD dynamics): the
columns of its trajectory.csv in memory, bit for bit those of the file;
the drop lands; errors name the key; a two-legged model works."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import fbd
from conftest import run_cli
from test_run import bits, read_csv

G = 9.81
#: Body 10 kg and six legs of 0.3 + 1.1 kg (the examples' masses).
MASS = 10.0 + 6 * (0.3 + 1.1)


def assert_columns_equal_csv(result: fbd.Result, path) -> None:
    """Every column of ``result`` equals the file's, bit for bit (vectorised:
    the dynamic hexapod has some 230 columns)."""
    header, rows = read_csv(path)
    assert result.columns == header
    assert result.rows == len(rows) > 0
    cells = np.array(rows, dtype=object)
    for j, name in enumerate(header):
        col = result[name]
        if col.dtype.kind == "U":
            assert list(col) == list(cells[:, j]), name
        elif col.dtype.kind == "i":
            assert col.tolist() == [int(c) for c in cells[:, j]], name
        else:
            want = np.array([float(c) for c in cells[:, j]])
            bad = np.flatnonzero(col.view(np.int64) != want.view(np.int64))
            assert bad.size == 0, f"{name}[{bad[0]}]: {col[bad[0]]!r} != {rows[bad[0]][j]}"


def without_timings(summary: dict) -> dict:
    s = dict(summary)
    for k in ("wall_seconds", "steps_per_second"):
        s.pop(k)
    s.pop("stability_check_seconds", None)
    return s


def test_dynamic_walk_equals_the_trajectory_csv_of_the_same_call(cli, examples, tmp):
    cfg = examples / "hexapod_walk.toml"
    r = fbd.run(cfg, out=tmp / "py")
    assert r.error is None and r.summary["run"] == "dynamic"
    assert r.summary["control"] == "gait"
    # The columns of the dynamic run, not of the kinematic gait.
    assert r.columns[:7] == ["t", "rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
    for name in ("state3", "foot3_n", "hip2_mz", "knee5_fx", "tau3_6", "kneepoint1_state",
                 "hippoint6_n", "kinetic", "newton_iterations"):
        assert name in r.columns, name
    assert "stance1" not in r.columns and "margin" not in r.columns
    assert r["state3"].dtype.kind == "U" and r["newton_iterations"].dtype.kind == "i"
    assert set(np.unique(r["state1"])) <= {"ST1", "ST2", "ST3"}
    assert_columns_equal_csv(r, tmp / "py" / "trajectory.csv")
    # The CLI writes the same file.
    p = run_cli(cli, "run", str(cfg), "--out", str(tmp / "cli"))
    assert p.returncode == 0, p.stderr
    for f in ("trajectory.csv", "events.csv", "config.toml"):
        assert (tmp / "py" / f).read_bytes() == (tmp / "cli" / f).read_bytes(), f
    # Events as events.csv; the summary as summary.json.
    header, rows = read_csv(tmp / "py" / "events.csv")
    assert header == ["t", "leg", "from", "to", "point"]
    assert len(r.events) == len(rows) > 0
    for e, row in zip(r.events, rows):
        assert bits(e["t"]) == bits(float(row[0]))
        assert ("" if e["leg"] is None else str(e["leg"])) == row[1]
        assert [e["from"], e["to"], e["point"]] == row[2:]
    want = json.loads((tmp / "py" / "summary.json").read_text())
    assert without_timings(r.summary) == without_timings(want)
    # The robot walks forward (up the 3.5° slope, along +X) and stays up.
    assert r["rx"][-1] > 0.1
    assert r["ry"].min() > 0.25
    # A tripod: the feet lift off and touch down again (swing phases).
    assert any(e["point"] == "tip" and e["to"] == "ST1" for e in r.events)


def test_the_drop_lands_on_its_feet_then_its_body_and_rests(examples):
    r = fbd.run(examples / "hexapod_drop.toml")
    assert r.error is None
    # Free fall until the feet, 0.85 + 0.42·sin 235° = 0.506 m up, reach
    # the ground: t = √(2h/g) = 0.321 s (the step from t puts them down).
    h = 0.85 + 0.42 * math.sin(math.radians(235.0))
    t_fall = math.sqrt(2 * h / G)
    for n in range(1, 7):
        td = r.summary["first_touchdown"][f"leg{n}"]
        assert td is not None and t_fall - 1e-3 <= td + 1e-3 <= t_fall + 1e-3, (n, td)
    first = [e for e in r.events if e["point"] == "tip"][0]
    assert first["from"] == "ST1" and first["to"] in ("ST2", "ST3")
    # At rest at the end: no kinetic energy, the contact forces carry the
    # weight (feet, knees and hips together).
    assert r["kinetic"][-1] < 1e-9
    normals = [c for c in r.columns if c.endswith("_n")]
    total = sum(r[c][-1] for c in normals)
    assert total == pytest.approx(MASS * G, rel=1e-6)
    # Every point above the ground (to the solver's tolerance).
    for n in range(1, 7):
        assert r[f"foot{n}_y"].min() > -1e-6


def test_a_bad_key_is_a_config_error_naming_it():
    # An unknown key: named in the message, its table in `key` (as for the
    # planar model), the line for TOML text.
    with pytest.raises(fbd.ConfigError, match="unknown field `kpp`") as info:
        fbd.run({"model": "hexapod", "control": {"kind": "pd", "kpp": 1.0}})
    assert info.value.key == "control"
    with pytest.raises(fbd.ConfigError, match="kpp") as info:
        fbd.run('model = "hexapod"\n[control]\nkind = "pd"\nkpp = 1.0\n')
    assert (info.value.key, info.value.line) == ("control", 4)
    # A bad value of the dynamics, and a leg the model does not have.
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run({"model": "hexapod", "control": {"kind": "pd", "kp": -1.0}})
    assert info.value.key == "control.kp"
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run({"model": "hexapod", "legs": [3, 4], "initial": {"leg1": {"theta_deg": [0, 0, 250]}}})
    assert info.value.key == "initial.leg1"


def test_a_two_legged_dynamic_hexapod(tmp):
    cfg = {
        "model": "hexapod",
        "legs": [3, 4],
        "time": {"dt": 0.001, "duration": 0.4},
        "initial": {"position": [0.0, 0.6, 0.0]},
        "terrain": {"mu_static": 0.6, "mu_dynamic": 0.45},
    }
    r = fbd.run(cfg, out=tmp / "two")
    assert r.error is None and r.summary["legs"] == [3, 4]
    assert_columns_equal_csv(r, tmp / "two" / "trajectory.csv")
    # Only the legs of the model have columns.
    thetas = [c for c in r.columns if c.startswith("theta")]
    assert thetas == ["theta1_3", "theta2_3", "theta3_3", "theta1_4", "theta2_4", "theta3_4"]
    assert "foot1_x" not in r.columns and "state6" not in r.columns
    assert r.rows == 401
    assert {e["leg"] for e in r.events if e["leg"] is not None} <= {3, 4}
    # It falls freely until the first contact: Ry(t) = 0.6 − g t²/2.
    t = r["t"]
    free = t < (min(e["t"] for e in r.events) if r.events else 0.4)
    assert free.sum() > 10
    assert np.allclose(r["ry"][free], 0.6 - 0.5 * G * t[free] ** 2, atol=1e-9)


def test_ctrl_c_interrupts_a_dynamic_run(ctrl_c, examples):
    # Long enough to outlast the timer at any speed (the PD stand at rest
    # steps fastest: 2e5 steps, a row every 10; the signals are looked at
    # every 4096 rows).
    text = (examples / "hexapod_stand.toml").read_text()
    long = text.replace("duration = 1.0", "duration = 200.0") + "\n[output]\nstride = 10\n"
    assert "duration = 200.0" in long
    with ctrl_c(), pytest.raises(KeyboardInterrupt, match="interrupted after"):
        fbd.run(long)


def test_dynamic_runs_in_threads_equal_the_same_runs_in_turn(examples):
    # The GIL is released: threads run the 3D dynamics side by side, and
    # each result is the one of the same run alone (deterministic).
    from concurrent.futures import ThreadPoolExecutor

    configs = [
        {"model": "hexapod", "time": {"dt": 0.001, "duration": 0.3},
         "terrain": {"mu_static": mu, "mu_dynamic": 0.75 * mu}}
        for mu in (0.1, 0.8)
    ]
    with ThreadPoolExecutor(2) as pool:
        together = list(pool.map(fbd.run, configs))
    for r, c in zip(together, configs):
        alone = fbd.run(c)
        assert r.columns == alone.columns and r.events == alone.events
        for name in r.columns:
            assert np.array_equal(r[name], alone[name]), name
