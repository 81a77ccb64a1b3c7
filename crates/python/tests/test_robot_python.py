"""Imported robots (``model = "robot"``) from Python: ``fbd.run`` equals the
CLI's ``trajectory.csv`` bit for bit (the lab hexapod set down on its feet
under PD), ``fbd.Simulator`` steps them with restorable, copyable and
picklable states (bit-identical stepping after a restore), its PD targets
give the configured ``[control] kind = "pd"`` run bit for bit, and the
Gymnasium environment ``fbd/Robot-v0`` passes Gymnasium's ``check_env``,
is deterministic given its seed and rolls out (the lab hexapod; Solo-12
from example-robot-data through ``ROS_PACKAGE_PATH``)."""

from __future__ import annotations

import importlib.metadata
import math
import os
import pathlib
import pickle
import subprocess

import numpy as np
import pandas as pd
import pytest

import fbd

ROOT = pathlib.Path(__file__).resolve().parents[3]
ROBOTS = ROOT / "examples/robots"
KP, KD = 20.0, 0.2


def lab_config(
    tmp_path: pathlib.Path, duration: float = 0.3, control: bool = True, name: str = "lab_stand.toml"
) -> pathlib.Path:
    """``lab_hexapod_stand.toml`` with its URDF's absolute path, a short
    duration and (``control``) PD holding the initial angles."""
    text = (ROBOTS / "lab_hexapod_stand.toml").read_text()
    old = 'urdf = "lab_hexapod.urdf"'
    assert old in text
    text = text.replace(old, f'urdf = "{ROBOTS / "lab_hexapod.urdf"}"')
    text += f"\n[time]\ndt = 0.001\nduration = {duration!r}\n"
    if control:
        text += f'\n[control]\nkind = "pd"\nkp = {KP!r}\nkd = {KD!r}\n'
    path = tmp_path / name
    path.write_text(text)
    return path


def package_env() -> dict:
    dist = importlib.metadata.distribution("example-robot-data")
    robots = dist.locate_file("cmeel.prefix/share/example-robot-data/robots")
    return {**os.environ, "ROS_PACKAGE_PATH": str(robots)}


def bits(a) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64)).view(np.uint64)


def test_run_equals_the_cli_bit_for_bit(cli, tmp_path):
    cfg = lab_config(tmp_path)
    out = tmp_path / "cli"
    r = subprocess.run([str(cli), "run", str(cfg), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    csv = pd.read_csv(out / "trajectory.csv", engine="python")
    res = fbd.run(cfg)
    assert res.columns == list(csv.columns)
    assert res.rows == len(csv) == 301
    for name in res.columns:
        col = res[name]
        if name.endswith("_state"):
            assert list(col) == list(csv[name]), name
        elif name == "newton_iterations":
            assert col.dtype == np.int64 and np.array_equal(col, csv[name].to_numpy()), name
        else:
            assert np.array_equal(bits(col), bits(csv[name].to_numpy())), name
    # The robot stands: its feet carry its weight at the end, sticking.
    feet = [c[: -len("_state")] for c in res.columns if c.endswith("_state")]
    assert len(feet) == 6
    assert all(res[f"{f}_state"][-1] == "ST2" for f in feet)
    mass = fbd.kinematics(cfg)["mass"]
    fy = sum(res[f"{f}_fy"][-1] for f in feet)
    assert abs(fy - mass * 9.81) < 0.02 * mass * 9.81, (fy, mass)
    # Events and summary as the CLI's files.
    events = pd.read_csv(out / "events.csv")
    assert [e["point"] for e in res.events] == list(events["point"])
    assert [e["to"] for e in res.events] == list(events["to"])
    assert all(set(e) >= {"t", "point", "from", "to"} for e in res.events)
    assert res.summary["model"] == "robot" and res.summary["steps"] == 301
    assert res.summary["contact_points"] == feet
    # With out=: the CLI's own files, the same columns.
    res2 = fbd.run(cfg, out=tmp_path / "py")
    for f in ["trajectory.csv", "events.csv", "summary.json", "config.toml"]:
        assert (tmp_path / "py" / f).is_file(), f
    assert (tmp_path / "py" / "trajectory.csv").read_bytes() == (out / "trajectory.csv").read_bytes()
    for name in res.columns:
        if res[name].dtype.kind == "f":
            assert np.array_equal(bits(res2[name]), bits(res[name])), name
        else:
            assert list(res2[name]) == list(res[name]), name
    assert res2.summary["rows_written"] == 301


def test_config_toml(tmp_path):
    cfg = lab_config(tmp_path)
    text = fbd.config_toml(cfg)
    assert 'model = "robot"' in text and 'kind = "pd"' in text
    # The complete configuration loads again, to the same simulator.
    again = fbd.Simulator(text)
    assert np.array_equal(bits(again.q0), bits(fbd.Simulator(cfg).q0))


def test_simulator_pd_is_the_configured_pd(tmp_path):
    configured = fbd.run(lab_config(tmp_path, name="pd.toml"))
    sim = fbd.Simulator(lab_config(tmp_path, control=False, name="passive.toml"))
    assert sim.model == "robot"
    names = sim.joint_names
    assert sim.coordinate_names == ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"] + names
    assert len(names) == 18 and sim.q.shape == (24,)
    assert sim.control["kind"] == "none"
    sim.set_pd_targets(sim.q0[6:], KP, KD)
    sim.step(steps=configured.rows - 1)
    effort = sim.effort_limits
    tau = np.column_stack([configured[f"tau_{j}"] for j in names])
    # Through the API the PD torques are clamped by torque_limit only; the
    # run clamps to the joints' effort limits: equal while none is reached.
    assert not np.any(np.abs(tau) >= np.where(np.isfinite(effort), effort, np.inf))
    q = np.column_stack([configured[c] for c in sim.coordinate_names])
    assert np.array_equal(bits(sim.q), bits(q[-1]))
    o = sim.observe()
    assert np.array_equal(bits(o["joint_torque"]), bits(tau[-2]))
    assert sim.reaction_names and o["reaction_force"].shape == (len(sim.reaction_names), 3)
    first = sim.reaction_names[0]
    assert np.array_equal(bits(o["reaction_force"][0]), bits([configured[f"{first}_f{a}"][-2] for a in "xyz"]))
    assert sim.joint_forces.shape == (len(sim.reaction_names), 3)
    feet = sim.contact_points
    assert list(sim.contact_states) == [2] * 6
    assert np.allclose(o["contact_slip_velocity"], 0.0, atol=1e-9)
    weight = fbd.kinematics(lab_config(tmp_path, name="k.toml"))["mass"] * 9.81
    assert abs(o["contact_force"][:, 1].sum() - weight) < 0.02 * weight
    assert [f"{p}_state" for p in feet] == [c for c in configured.columns if c.endswith("_state")]
    assert len(o["body_position"]) == len(sim.body_names) and sim.body_names[0]
    inertia, joint = sim.joint_inertia
    assert inertia > 0 and joint in names
    # PD stability: kp·Δt²/I + 2·kd·Δt/I < 4 for the gains used.
    assert KP * 1e-6 / inertia + 2 * KD * 1e-3 / inertia < 4


def test_simulator_state_round_trip_and_pickle(tmp_path):
    sim = fbd.Simulator(lab_config(tmp_path, duration=1.0))
    sim.step(steps=5)
    saved = sim.get_state()
    copy = sim.copy()

    def run(s):
        out = []
        for k in range(40):
            if k % 2:
                s.step(np.full(18, 0.02))
            else:
                s.step()
            o = s.observe()
            out.append(np.concatenate([bits(o["q"]), bits(o["contact_force"].ravel()), bits(o["reaction_moment"].ravel())]))
        return np.array(out)

    first = run(sim)
    assert sim.observe()["contact_normal_force"].sum() > 0.0
    sim.set_state(saved)
    assert np.array_equal(run(sim), first)
    assert np.array_equal(run(copy), first)
    # A pickled state (replayed in Rust) and a pickled simulator.
    other = fbd.Simulator(lab_config(tmp_path, duration=1.0))
    other.set_state(pickle.loads(pickle.dumps(saved)))
    assert np.array_equal(run(other), first)
    sim.set_state(saved)
    clone = pickle.loads(pickle.dumps(sim))
    assert clone.model == "robot" and clone.k == 5
    assert np.array_equal(bits(clone.q), bits(sim.q))
    assert np.array_equal(run(clone), first)
    events = sim.events
    assert all(set(e) >= {"t", "point", "from", "to"} for e in events)


def test_simulator_in_flight(tmp_path):
    """``[terrain] kind = "none"``: no contact points; the free robot's
    centre of mass falls g·t²/2 (passive joints, from rest)."""
    text = (ROBOTS / "lab_hexapod_flight.toml").read_text()
    text = text.replace('urdf = "lab_hexapod.urdf"', f'urdf = "{ROBOTS / "lab_hexapod.urdf"}"')
    cfg = tmp_path / "flight.toml"
    cfg.write_text(text)
    sim = fbd.Simulator(cfg)
    assert sim.contact_points == []
    res = fbd.run(cfg)
    assert res.rows == 501 and "com_y" in res.columns
    dt = 0.001
    accel = np.diff(res["com_y"], 2) / dt**2
    assert np.allclose(accel, -9.81, rtol=1e-6), (accel.min(), accel.max())
    sim.step(steps=res.rows - 1)
    assert np.array_equal(bits(sim.q), bits([res[c][-1] for c in sim.coordinate_names]))


@pytest.fixture
def gym():
    gymnasium = pytest.importorskip("gymnasium")
    return gymnasium


def test_robot_env_check_env_lab_hexapod(gym, tmp_path):
    from gymnasium.utils.env_checker import check_env

    cfg = lab_config(tmp_path, control=False)
    env = gym.make("fbd/Robot-v0", config=str(cfg), episode_seconds=0.2)
    check_env(env.unwrapped, skip_render_check=True)
    check_env(env, skip_render_check=True)
    u = env.unwrapped
    assert u.frame_skip == 20 and u.dt == 0.001
    n = 18
    assert env.action_space.shape == (n,)
    assert env.observation_space.shape == (11 + 2 * n + 2 * 6,)
    assert len(u.observation_names) == env.observation_space.shape[0]
    # Default gains: about half of the PD stability limit 4 on the robot's
    # smallest effective joint inertia.
    inertia, _ = u.sim.joint_inertia
    a = u.kp * u.dt**2 / inertia + 2 * u.kd * u.dt / inertia
    assert np.allclose(a, 2.1)
    assert u.TORQUE_LIMIT == 3.0  # the URDF's effort limits
    obs, _ = env.reset(seed=3)
    assert obs[0] == pytest.approx(u.q0[1])
    assert np.allclose(obs[1:5], [1, 0, 0, 0])  # unrotated
    rng = np.random.default_rng(0)
    total, steps = 0.0, 0
    while True:
        obs, r, term, trunc, info = env.step(0.3 * rng.uniform(-1, 1, n))
        assert np.all(np.isfinite(obs)) and math.isfinite(r)
        total += r
        steps += 1
        if term or trunc:
            break
    assert trunc and not term and steps == 10
    assert "error" not in info
    # Zero actions hold the initial pose: the robot settles and stands,
    # every foot sticking, the normal forces carrying its weight, at rest.
    env = gym.make("fbd/Robot-v0", config=str(cfg), episode_seconds=0.4)
    env.reset(seed=0)
    for _ in range(20):
        obs, r, term, trunc, info = env.step(np.zeros(n))
        assert not term
    assert trunc
    weight = fbd.kinematics(cfg)["mass"] * 9.81
    assert np.array_equal(obs[11 + 2 * n : 11 + 2 * n + 6], np.ones(6))
    assert abs(obs[11 + 2 * n + 6 :].sum() - weight) < 1e-5 * weight
    assert abs(info["forward_speed"]) < 1e-5 and r == info["forward_speed"] - info["effort"]
    assert np.allclose(obs[5:11], 0.0, atol=1e-5)  # base at rest


def test_robot_env_deterministic_and_pickles(gym, tmp_path):
    cfg = lab_config(tmp_path, control=False)

    def episode(seed):
        env = gym.make("fbd/Robot-v0", config=str(cfg), episode_seconds=0.1, init_noise=0.05)
        obs, _ = env.reset(seed=seed)
        out = [obs]
        rng = np.random.default_rng(seed)
        for _ in range(3):
            out.append(env.step(rng.uniform(-1, 1, 18))[0])
        return np.array(out), env

    a, env = episode(7)
    b, _ = episode(7)
    c, _ = episode(8)
    assert np.array_equal(bits(a), bits(b))
    assert not np.array_equal(a[0], c[0])
    clone = pickle.loads(pickle.dumps(env.unwrapped))
    act = np.zeros(18)
    assert np.array_equal(bits(clone.step(act)[0]), bits(env.unwrapped.step(act)[0]))


def test_robot_env_refuses_other_models(gym):
    with pytest.raises(ValueError, match="model = \"robot\""):
        gym.make("fbd/Robot-v0", config={"time": {"duration": 0.1}})


def test_robot_env_solo12(gym, tmp_path, monkeypatch):
    try:
        importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    from gymnasium.utils.env_checker import check_env

    monkeypatch.setenv("ROS_PACKAGE_PATH", package_env()["ROS_PACKAGE_PATH"])
    env = gym.make("fbd/Robot-v0", config=str(ROBOTS / "solo12_stand.toml"), episode_seconds=0.2)
    check_env(env.unwrapped, skip_render_check=True)
    u = env.unwrapped
    assert env.action_space.shape == (12,)
    assert u.sim.control["kind"] == "pd"
    assert np.all(u.kp == 5.0) and np.all(u.kd == 0.1)
    assert np.allclose(u.forward, [0.0, 0.0, -1.0])
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(1)
    for _ in range(10):
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, 12))
        assert np.all(np.isfinite(obs)) and "error" not in info
        if term or trunc:
            break
    assert trunc


def test_robot_vector_env_equals_serial_envs(gym, tmp_path):
    cfg = str(lab_config(tmp_path, control=False))
    vec = gym.make_vec(
        "fbd/Robot-v0", num_envs=2, vectorization_mode="vector_entry_point",
        config=cfg, episode_seconds=0.1, init_noise=0.02,
    )
    serial = [gym.make("fbd/Robot-v0", config=cfg, episode_seconds=0.1, init_noise=0.02) for _ in range(2)]
    obs, _ = vec.reset(seed=11)
    for i, env in enumerate(serial):
        o, _ = env.reset(seed=11 + i)
        assert np.array_equal(bits(o), bits(obs[i]))
    rng = np.random.default_rng(5)
    for _ in range(5):
        actions = rng.uniform(-1, 1, (2, 18))
        obs, rewards, term, trunc, _ = vec.step(actions)
        for i, env in enumerate(serial):
            o, r, te, tr, _ = env.step(actions[i])
            assert np.array_equal(bits(o), bits(obs[i])) and r == rewards[i]
            assert (te, tr) == (term[i], trunc[i])
    assert trunc.all()  # 5 periods of 20 ms
