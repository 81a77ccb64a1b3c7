"""fbd.gym: the environments pass Gymnasium's own check_env, are
deterministic in their seed, and the vector entry point (N simulators on
Rust threads) equals N serial environments with Gymnasium's NEXT_STEP
autoreset, bit for bit. Episodes here are short (CI budget)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

import fbd  # noqa: E402  (registers the environments)
from gymnasium.utils.env_checker import check_env  # noqa: E402
from gymnasium.vector import AutoresetMode  # noqa: E402


@pytest.mark.parametrize("name", ["fbd/HexapodWalk-v0", "fbd/PlanarStand-v0"])
def test_check_env(name):
    env = gymnasium.make(name, episode_seconds=0.2)
    check_env(env.unwrapped, skip_render_check=True)
    check_env(env, skip_render_check=True)


def test_hexapod_walk_layout_and_determinism():
    env = gymnasium.make("fbd/HexapodWalk-v0", episode_seconds=0.2)
    obs, _ = env.reset(seed=3)
    assert obs.shape == (60,) and env.action_space.shape == (18,)
    assert len(env.unwrapped.OBSERVATION_NAMES) == 60
    again, _ = env.reset(seed=3)
    np.testing.assert_array_equal(obs, again)
    other, _ = env.reset(seed=4)
    assert not np.array_equal(obs, other)
    rng = np.random.default_rng(0)
    actions = rng.uniform(-0.05, 0.05, size=(12, 18))

    def episode(e, seed):
        out = [e.reset(seed=seed)[0]]
        for a in actions:
            o, r, term, trunc, info = e.step(a)
            out.append(np.concatenate([o, [r, term, trunc]]))
            if term or trunc:
                break
        return out

    a = episode(env, 7)
    # The feet touch down and carry the robot.
    assert a[-1][46:52].min() >= 1.0 and a[-1][52:58].sum() > 100.0
    b = episode(pickle.loads(pickle.dumps(env.unwrapped)), 7)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert a[-1][-1] == 1.0, "truncated at the time limit (0.2 s, 10 actions)"


def serial_next_step(envs, actions_seq, seed, infos=None):
    """N serial environments driven with the NEXT_STEP autoreset rule
    (each step's infos appended to ``infos``, a list per step of a list
    per environment, None for a reset)."""
    obs = [e.reset(seed=seed + i)[0] for i, e in enumerate(envs)]
    out = [np.stack(obs)]
    done = [False] * len(envs)
    for actions in actions_seq:
        step = []
        step_infos = []
        for i, e in enumerate(envs):
            if done[i]:
                o, _ = e.reset()
                r, te, tr = 0.0, False, False
                step_infos.append(None)
            else:
                o, r, te, tr, info = e.step(actions[i])
                step_infos.append(info)
            done[i] = te or tr
            step.append(np.concatenate([o, [r, te, tr]]))
        out.append(np.stack(step))
        if infos is not None:
            infos.append(step_infos)
    return out


@pytest.mark.parametrize("name,steps", [("fbd/HexapodWalk-v0", 9), ("fbd/PlanarStand-v0", 12)])
def test_vector_env_equals_serial_envs(name, steps):
    n = 3
    venv = gymnasium.make_vec(name, num_envs=n, vectorization_mode="vector_entry_point", episode_seconds=0.08)
    assert venv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    rng = np.random.default_rng(1)
    seq = rng.uniform(-1, 1, size=(steps,) + venv.action_space.shape)
    obs, _ = venv.reset(seed=11)
    got = [obs]
    got_infos = []
    resets = 0
    for actions in seq:
        o, r, te, tr, info = venv.step(actions)
        got.append(np.column_stack([o, r, te, tr]))
        got_infos.append(info)
        resets += int(np.sum(te | tr))
    assert resets >= n, "episodes ended and were reset within the test"
    envs = [gymnasium.make(name, episode_seconds=0.08).unwrapped for _ in range(n)]
    want_infos = []
    want = serial_next_step(envs, seq, 11, want_infos)
    for x, y in zip(got, want):
        np.testing.assert_array_equal(x, y)
    # The infos too: each key with its mask, as Gymnasium's vector
    # environments lay them out, equal to the serial environment's.
    for info, serial in zip(got_infos, want_infos):
        keys = {k for s in serial if s for k in s}
        assert {k for k in info if not k.startswith("_")} == keys
        for key in keys:
            for i, s in enumerate(serial):
                has = s is not None and key in s
                assert bool(info[f"_{key}"][i]) == has, (key, i)
                if has:
                    assert info[key][i] == s[key], (key, i)
    venv.close()


@pytest.mark.parametrize("name", ["fbd/HexapodWalk-v0", "fbd/PlanarStand-v0"])
def test_observe_many_and_set_pd_targets_many_equal_one_by_one(name):
    from fbd import _fbd

    envs = [gymnasium.make(name).unwrapped for _ in range(3)]
    for i, e in enumerate(envs):
        e.reset(seed=20 + i)
        e.step(e.action_space.sample() * 0.1)
    sims = [e.sim for e in envs]
    batch = _fbd.observe_many(sims)
    for i, sim in enumerate(sims):
        one = sim.observe()
        assert set(one) == set(batch)
        for key, value in one.items():
            got = batch[key][i]
            assert np.asarray(got).dtype == np.asarray(value).dtype, key
            np.testing.assert_array_equal(got, value, err_msg=key)
    assert set(_fbd.observe_many(sims, ["q", "t"])) == {"q", "t"}
    with pytest.raises(ValueError, match="no field"):
        _fbd.observe_many(sims, ["nonsense"])
    joints = len(sims[0].joint_names)
    targets = np.random.default_rng(2).uniform(-0.1, 0.1, size=(3, joints))
    _fbd.set_pd_targets_many(sims, targets, 100.0, 2.0, torque_limit=50.0)
    for i, sim in enumerate(sims):
        got = sim.pd_targets
        np.testing.assert_array_equal(got["targets"], targets[i])
        np.testing.assert_array_equal(got["kp"], np.full(joints, 100.0))
        assert got["torque_limit"] == 50.0
    with pytest.raises(ValueError, match="rows"):
        _fbd.set_pd_targets_many(sims, targets[:2], 100.0, 2.0)
    with pytest.raises(ValueError, match="kp"):
        _fbd.set_pd_targets_many(sims, targets, -1.0, 2.0)


def test_bad_actions_are_named_and_infinite_ones_clipped():
    env = gymnasium.make("fbd/PlanarStand-v0", episode_seconds=0.2).unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action of shape \(3,\), expected \(4,\)"):
        env.step(np.zeros(3))
    bad = np.zeros(4)
    bad[2] = np.nan
    with pytest.raises(ValueError, match=r"action is NaN at index \(2,\)"):
        env.step(bad)
    # ±inf is at the bounds of the Box: the same step as ±1.
    x = env.reset(seed=0)[0]
    a = env.step(np.array([np.inf, -np.inf, 1e300, 0.0]))[0]
    env.reset(seed=0)
    b = env.step(np.array([1.0, -1.0, 1.0, 0.0]))[0]
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, x)
    venv = gymnasium.make_vec("fbd/PlanarStand-v0", num_envs=2, vectorization_mode="vector_entry_point")
    venv.reset(seed=0)
    with pytest.raises(ValueError, match=r"action of shape \(4,\), expected \(2, 4\)"):
        venv.step(np.zeros(4))
    rows = np.zeros((2, 4))
    rows[1, 3] = np.nan
    with pytest.raises(ValueError, match=r"action is NaN at index \(1, 3\)"):
        venv.step(rows)


def test_vector_env_pickles():
    venv = gymnasium.make_vec("fbd/PlanarStand-v0", num_envs=2, vectorization_mode="vector_entry_point")
    venv.reset(seed=0)
    a = np.zeros(venv.action_space.shape)
    venv.step(a)
    twin = pickle.loads(pickle.dumps(venv.unwrapped))
    for _ in range(3):
        x = venv.step(a)[0]
        y = twin.step(a)[0]
        np.testing.assert_array_equal(x, y)


def test_vector_env_reports_a_failed_step_as_a_serial_env_would(monkeypatch):
    """A sub-environment whose physics fails (here: an error injected for
    sub-environment 1 after its period was stepped) ends its episode as a
    single environment's `_finish` does — reward 0, terminated, not
    truncated, `info["error"]` — while the others step on; the next step
    resets it."""
    import fbd.gym as fgym
    from fbd import SimulationError

    n = 3
    venv = gymnasium.make_vec("fbd/HexapodWalk-v0", num_envs=n, vectorization_mode="vector_entry_point")
    venv.reset(seed=5)
    actions = np.zeros((n, 18))
    venv.step(actions)
    real = fgym._fbd.step_many
    twin = pickle.loads(pickle.dumps(venv.unwrapped.envs[1]))
    twin_before = twin._apply(actions[1])
    twin.sim.step(steps=twin.frame_skip)
    error = SimulationError("injected failure")

    def failing(sims, torques, steps):
        out = real(sims, torques, steps)
        out[1] = error
        return out

    monkeypatch.setattr(fgym._fbd, "step_many", failing)
    obs, rewards, terminated, truncated, info = venv.step(actions)
    monkeypatch.setattr(fgym._fbd, "step_many", real)
    want = twin._finish(twin_before, error)
    np.testing.assert_array_equal(obs[1], want[0])
    assert (rewards[1], bool(terminated[1]), bool(truncated[1])) == want[1:4] == (0.0, True, False)
    assert info["error"][1] == want[4]["error"] == "injected failure"
    assert list(info["_error"]) == [False, True, False]
    assert list(info["_forward_speed"]) == [True, False, True]
    assert not terminated[0] and not terminated[2]
    # The next step resets sub-environment 1 (reward 0, its first observation).
    obs, rewards, terminated, truncated, info = venv.step(actions)
    assert rewards[1] == 0.0 and not terminated[1] and not truncated[1]
    assert "error" not in info
    venv.close()


def test_batched_rules_compute_each_row_on_its_own():
    """The helpers the batched task rules use give each row of a batch
    bit for bit what the row alone gives (so a vector environment of any
    N equals its single environments)."""
    from fbd import gym as fgym

    rng = np.random.default_rng(3)
    for n in (2, 5, 16, 33):
        rot = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
        v = rng.normal(size=(n, 3))
        x = rng.normal(size=(n, 18))
        batch = fgym._rotate_back(rot, v), fgym._sum_squares(x), fgym._quaternions(rot)
        for i in range(n):
            one = fgym._rotate_back(rot[i : i + 1], v[i : i + 1]), fgym._sum_squares(x[i : i + 1]), fgym._quaternions(rot[i : i + 1])
            for b, o in zip(batch, one):
                np.testing.assert_array_equal(b[i], o[0])
        np.testing.assert_allclose(batch[0], np.einsum("nji,nj->ni", rot, v), rtol=0, atol=1e-14)
