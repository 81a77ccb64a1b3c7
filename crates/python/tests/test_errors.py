"""ConfigError names the file, line and key; SimulationError carries the
step, the time and the partial result; no Rust panic reaches Python."""

from __future__ import annotations

import json

import numpy as np
import pytest

import fbd
from conftest import run_cli

# A failing experiment: in the air, so that no contact logic is involved,
# a trajectory controller (kp = 10 N·m/rad, stable) told to turn both hips
# by 10⁶° between t = 0.25 s and 0.26 s: a torque of 1.7e5 N·m in one step,
# which Newton's method cannot solve (at step 26).
FAILING = """
[time]
duration = 1.0
[leg]
theta2_deg = [-1e6, 1e6]
theta3_deg = [-1e6, 1e6]
[terrain]
kind = "none"
[control]
kind = "trajectory"
kp = 10.0
[control.leg3]
times = [0.0, 0.25, 0.26]
target_deg = [[0.0, 245.0], [0.0, 245.0], [1e6, 245.0]]
[control.leg4]
times = [0.0, 0.25, 0.26]
target_deg = [[0.0, 255.0], [0.0, 255.0], [1e6, 255.0]]
"""

# An explicit PD controller far too stiff for its time step (kp·Δt² ≫ the
# joints' effective inertia, no damping): its torques would oscillate with
# a growing amplitude, so it is refused before the run.
UNSTABLE_PD = """
[time]
duration = 1.0
[terrain]
kind = "none"
[control]
kind = "pd"
kp = 5000.0
kd = 0.0
[control.leg3]
target_deg = [1.0, 245.0]
"""


@pytest.mark.parametrize(
    "config,key",
    [
        ({"time": {"dt": -0.01}}, "time.dt"),
        ({"leg": {"upper_mass": 0.0}}, "leg.upper_mass"),
        ({"terrain": {"mu_static": 0.2, "mu_dynamic": 0.3}}, "terrain.mu_dynamic"),
        ("[time]\ndt = -1.0\n", "time.dt"),
        ({"control": {"kind": "pd", "kp": -1.0}}, "control.kp"),
    ],
)
def test_bad_values_raise_config_error_naming_the_key(config, key):
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run(config)
    e = info.value
    assert e.key == key, str(e)
    assert key in str(e)
    assert isinstance(e, ValueError)


def test_unknown_key_names_line_and_key():
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run("[time]\ndt = 0.01\nduraton = 1.0\n")
    e = info.value
    assert e.file == "<string>"
    assert e.line == 3, str(e)
    assert "duraton" in str(e)
    assert e.key is not None and e.key.startswith("time"), str(e)


def test_syntax_error_in_a_file_names_file_and_line(tmp):
    bad = tmp / "bad.toml"
    bad.write_text("[time]\ndt = 0.01\nduration = = 1\n")
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run(bad)
    e = info.value
    assert e.file == str(bad) and e.line == 3
    assert str(e).startswith(f"{bad}:3:")


def test_dict_errors_have_no_line_but_the_key():
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run({"time": {"dt": "fast"}})
    assert info.value.file == "<dict>" and info.value.line is None
    assert info.value.key == "time.dt", str(info.value)


def test_missing_file():
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run("does/not/exist.toml")
    assert info.value.file == "does/not/exist.toml"
    assert "no such file" in str(info.value)


def test_unconvertible_dict_value_is_a_type_error():
    with pytest.raises(TypeError, match="time.dt"):
        fbd.run({"time": {"dt": object()}})


def test_kinematic_hexapod_simulator_is_a_config_error_naming_model(examples):
    # fbd.run runs the hexapod (test_hexapod.py: the kinematic gait,
    # test_spatial.py: the 3D dynamics); the step-wise Simulator steps the
    # dynamics (test_hexapod_simulator.py) and says so for a kinematic gait.
    with pytest.raises(fbd.ConfigError, match="kinematic") as info:
        fbd.Simulator(examples / "hexapod_tripod.toml")
    assert info.value.key == "model"
    assert fbd.Simulator(examples / "hexapod_stand.toml").model == "hexapod"


def test_simulator_config_errors():
    with pytest.raises(fbd.ConfigError) as info:
        fbd.Simulator({"time": {"duration": -1.0}})
    assert info.value.key == "time.duration"


def test_an_unstable_pd_gain_is_a_config_error_naming_the_key():
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run(UNSTABLE_PD)
    e = info.value
    assert e.key == "control.kp", str(e)
    assert "unstable" in str(e) and "time.dt below" in str(e), str(e)
    with pytest.raises(fbd.ConfigError) as info:
        fbd.run(UNSTABLE_PD.replace("kp = 5000.0\nkd = 0.0", "kp = 100.0\nkd = 50.0"))
    assert info.value.key == "control.kd", str(info.value)


def test_failing_run_raises_simulation_error_with_partial_rows():
    with pytest.raises(fbd.SimulationError) as info:
        fbd.run(FAILING)
    e = info.value
    assert isinstance(e, RuntimeError)
    # The step of the commanded jump.
    assert e.step == 26
    assert e.time == pytest.approx(e.step * 0.01, abs=1e-12)
    assert f"step {e.step}" in str(e)
    r = e.result
    assert isinstance(r, fbd.Result)
    # Every step before the failing one, and nothing after.
    assert r.rows == e.step and r["t"][-1] == pytest.approx((e.step - 1) * 0.01)
    assert r.error == str(e) and r.summary["status"] == "error"
    assert r.summary["steps"] == e.step
    assert np.all(np.isfinite(r["theta3_3"]))


def test_failing_run_with_out_writes_every_file(cli, tmp):
    cfg = tmp / "failing.toml"
    cfg.write_text(FAILING)
    with pytest.raises(fbd.SimulationError) as info:
        fbd.run(cfg, out=tmp / "py")
    p = run_cli(cli, "run", str(cfg), "--out", str(tmp / "cli"))
    assert p.returncode == 3
    for name in ("trajectory.csv", "events.csv"):
        assert (tmp / "py" / name).read_bytes() == (tmp / "cli" / name).read_bytes()
    s = json.loads((tmp / "py" / "summary.json").read_text())
    assert s["status"] == "error" and s["rows_written"] == info.value.result.rows


def test_unwritable_out_is_an_os_error(tmp):
    f = tmp / "file"
    f.write_text("x")
    with pytest.raises(OSError, match="not a directory"):
        fbd.run("[time]\nduration = 0.05\n", out=f)


def test_ctrl_c_interrupts_a_long_run_and_a_long_step_call(ctrl_c):
    # Long enough to outlast the timer at any speed (3e6 steps of a free
    # fall, a row every 10 steps: the signals are looked at every 4096
    # rows).
    long = {
        "time": {"dt": 1e-4, "duration": 300.0},
        "terrain": {"kind": "none"},
        "output": {"stride": 10},
    }
    with ctrl_c(), pytest.raises(KeyboardInterrupt, match="interrupted after"):
        fbd.run(long)
    sim = fbd.Simulator(long)
    with ctrl_c(), pytest.raises(KeyboardInterrupt):
        sim.step(steps=sim.steps)
    # Stopped between steps: the state is a solved one, and stepping goes on.
    k = sim.k
    assert 0 < k < sim.steps
    sim.step()
    assert sim.k == k + 1


def test_unstable_gains_in_a_python_loop_end_with_a_hint():
    # A PD law written in Python with gains far too stiff for Δt (the
    # torques are applied explicitly: kp·Δt²/I ≈ 50 ≫ 4): the oscillation
    # grows until Newton's method cannot solve a step. The error says why
    # and what to change, not only "Newton did not converge".
    sim = fbd.Simulator(
        {
            "terrain": {"kind": "none"},
            "leg": {"theta2_deg": [-1e6, 1e6], "theta3_deg": [-1e6, 1e6]},
        }
    )
    target = sim.q0[3:7] + 0.05
    with pytest.raises(fbd.SimulationError) as info:
        while sim.k < sim.steps:
            sim.step(5000.0 * (target - sim.q[3:7]))
    msg = str(info.value)
    assert "did not converge" in msg, msg
    assert "the torques given to step() are applied explicitly" in msg, msg
    assert "lower the gains or time.dt" in msg and "set_pd_targets()" in msg, msg
    # The configured controller's steps get no such hint: the hint is
    # about the torques a caller gives.
    with pytest.raises(fbd.SimulationError) as ref:
        fbd.Simulator(FAILING).step(steps=100)
    assert "applied explicitly" not in str(ref.value), str(ref.value)
