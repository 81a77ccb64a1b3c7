"""fbd.Simulator for the 24-DOF hexapod: a Python PD loop reproduces
`[control] kind = "pd"` bit for bit, PD targets stepped inside Rust do too,
states restore bit for bit (also through pickle and copy()), and the
readouts obey the physics (the feet of a standing robot carry its weight,
a sticking foot does not slip)."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import fbd

KP, KD, LIMIT = 300.0, 8.0, 60.0
STAND = """
model = "hexapod"
[time]
dt = 0.001
duration = 0.2
[initial]
position = [0.0, 0.3566, 0.0]
phi_deg = [0.0, 0.0, 0.0]
[initial.leg1]
theta_deg = [0.0, -20.0, 290.0]
[initial.leg2]
theta_deg = [0.0, -20.0, 290.0]
[initial.leg3]
theta_deg = [0.0, -20.0, 290.0]
[initial.leg4]
theta_deg = [0.0, -20.0, 290.0]
[initial.leg5]
theta_deg = [0.0, -20.0, 290.0]
[initial.leg6]
theta_deg = [0.0, -20.0, 290.0]
[terrain]
kind = "flat"
mu_static = 0.8
mu_dynamic = 0.6
[control]
kind = "pd"
kp = 300.0
kd = 8.0
torque_limit = 60.0
"""
PASSIVE = STAND.replace('kind = "pd"', 'kind = "none"')
NAMES = ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"] + [
    f"theta{j}_{leg}" for leg in range(1, 7) for j in (1, 2, 3)
]


@pytest.fixture(scope="module")
def builtin():
    return fbd.run(STAND)


def test_layout_and_names():
    sim = fbd.Simulator(PASSIVE)
    assert sim.model == "hexapod"
    assert sim.coordinate_names == NAMES
    assert sim.joint_names == NAMES[6:]
    assert sim.q.shape == (24,) and sim.q0.shape == (24,) and sim.qdot.shape == (24,)
    # q is in the order of fbd.hexapod_fk: the tips from q are the
    # simulator's contact points.
    tips = fbd.hexapod_fk(sim.q)["tip"]
    pos = sim.contact_positions
    for leg in range(1, 7):
        np.testing.assert_allclose(pos[sim.contact_points.index(f"tip{leg}")], tips[leg - 1], atol=1e-12)
    with pytest.raises(ValueError, match="18"):
        sim.step(np.zeros(17))


def test_python_pd_loop_equals_builtin_pd(builtin):
    """τ = kp·(θ* − θ[k]) − kd·θ̇[k], clamped, computed in NumPy every step
    from sim.q and sim.qdot: the built-in PD's run, bit for bit."""
    sim = fbd.Simulator(PASSIVE)
    target = sim.q0[6:]
    rows = [sim.q]
    for _ in range(builtin.rows - 1):
        tau = np.clip(KP * (target - sim.q[6:]) + KD * (0.0 - sim.qdot[6:]), -LIMIT, LIMIT)
        sim.step(tau)
        rows.append(sim.q)
    want = np.column_stack([builtin[n] for n in NAMES])
    np.testing.assert_array_equal(np.array(rows), want)
    assert any(e["to"] == "ST2" for e in builtin.events), "the feet touched down"


def test_pd_targets_in_rust_equal_builtin_pd(builtin):
    sim = fbd.Simulator(PASSIVE)
    sim.set_pd_targets(sim.q0[6:], KP, KD, torque_limit=LIMIT)
    rows, ks = [sim.q], [0]
    while sim.k < builtin.rows - 1:
        sim.step(steps=min(20, builtin.rows - 1 - sim.k))
        rows.append(sim.q)
        ks.append(sim.k)
    want = np.column_stack([builtin[n] for n in NAMES])
    assert ks[-1] == builtin.rows - 1
    np.testing.assert_array_equal(np.array(rows), want[ks])
    # The forces of the step solved last are the run's last-but-one row.
    k = sim.k - 1
    f = sim.contact_forces
    for leg in range(1, 7):
        i = sim.contact_points.index(f"tip{leg}")
        assert f[i, 1] == builtin[f"foot{leg}_fy"][k]
    np.testing.assert_array_equal(sim.joint_torques[:3], [builtin[f"tau{j}_1"][k] for j in (1, 2, 3)])


def test_restore_copy_and_pickle_are_bit_identical():
    sim = fbd.Simulator(PASSIVE)
    sim.set_pd_targets(sim.q0[6:], KP, KD)
    sim.step(steps=30)
    sim.step(np.full(18, 0.5), steps=3)
    state = sim.get_state()
    twin = sim.copy()
    pickled = pickle.loads(pickle.dumps(state))
    clone = pickle.loads(pickle.dumps(sim))
    deep = copy.deepcopy(sim)

    def go(s):
        out = []
        for i in range(20):
            s.step(np.full(18, -0.2) if i % 3 == 0 else None, steps=2)
            o = s.observe()
            out.append(np.concatenate([o["q"], o["contact_force"].ravel(), o["contact_slip_velocity"].ravel()]))
        return np.array(out)

    first = go(sim)
    assert sim.contact_states.max() >= 2, "in contact in the compared steps"
    sim.set_state(state)
    np.testing.assert_array_equal(go(sim), first)
    np.testing.assert_array_equal(go(twin), first)
    np.testing.assert_array_equal(go(clone), first)
    np.testing.assert_array_equal(go(deep), first)
    other = fbd.Simulator(PASSIVE)
    other.set_pd_targets(sim.q0[6:], KP, KD)
    other.set_state(pickled)
    assert other.k == state.k == 33
    np.testing.assert_array_equal(go(other), first)
    with pytest.raises(ValueError, match="another configuration"):
        fbd.Simulator(STAND).set_state(state)


def test_readouts_standing():
    sim = fbd.Simulator(PASSIVE)
    sim.set_pd_targets(sim.q0[6:], KP, KD)
    sim.step(steps=200)
    o = sim.observe()
    tips = [sim.contact_points.index(f"tip{leg}") for leg in range(1, 7)]
    assert list(o["contact_state"][tips]) == [2] * 6
    weight = (10.0 + 6 * (0.3 + 1.1)) * 9.81
    assert o["contact_force"][tips, 1].sum() == pytest.approx(weight, rel=0.02)
    np.testing.assert_allclose(o["contact_slip_velocity"][tips], 0.0, atol=1e-9)
    np.testing.assert_array_equal(o["contact_normal"][tips], [[0.0, 1.0, 0.0]] * 6)
    assert o["body_position"].shape == (13, 3) and o["body_rotation"].shape == (13, 3, 3)
    # The body's centre of mass is R: its velocity is q̇'s first three.
    np.testing.assert_allclose(o["body_velocity"][0], o["qdot"][:3], atol=1e-9)
    assert o["hip_force"].shape == (6, 3) and o["knee_moment"].shape == (6, 3)
    assert sim.joint_forces.shape == (6, 2, 3)
    assert o["kinetic"] >= 0.0


def test_kinematic_hexapod_is_a_config_error(examples):
    with pytest.raises(fbd.ConfigError, match="kinematic"):
        fbd.Simulator(examples / "hexapod_tripod.toml")


def test_step_many_equals_serial():
    sims = [fbd.Simulator(PASSIVE) for _ in range(3)]
    serial = [s.copy() for s in sims]
    tau = np.stack([np.full(18, 0.3 * i) for i in range(3)])
    for _ in range(4):
        errors = fbd.step_many(sims, tau, 10)
        assert errors == [None, None, None]
        for s, t in zip(serial, tau):
            s.step(t, steps=10)
    for a, b in zip(sims, serial):
        np.testing.assert_array_equal(a.q, b.q)


def test_simulators_many_equals_one_by_one(examples):
    """`_fbd.simulators_many` (the vector environments' resets) builds each
    simulator as `Simulator(config)` does, from dicts, text and paths, a
    robot's too; the first bad configuration raises its own error."""
    from fbd import _fbd

    configs = [
        {"model": "hexapod", "time": {"dt": 0.001, "duration": 0.05}, "terrain": {"mu_static": 0.7 + 0.1 * i}}
        for i in range(3)
    ] + [STAND, {"time": {"dt": 0.002}}, str(examples / "robots" / "lab_hexapod_pd.toml")]
    many = _fbd.simulators_many(configs)
    for config, sim in zip(configs, many):
        one = fbd.Simulator(config)
        assert sim.model == one.model and sim.contact_points == one.contact_points
        for _ in range(3):
            sim.step(steps=5)
            one.step(steps=5)
        np.testing.assert_array_equal(sim.q, one.q)
        a, b = sim.observe(), one.observe()
        for key in a:
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    with pytest.raises(fbd.ConfigError, match="mu_static"):
        _fbd.simulators_many([configs[0], {"model": "hexapod", "terrain": {"mu_static": -1.0}}])
    with pytest.raises(fbd.ConfigError, match="kinematic"):
        _fbd.simulators_many([examples / "hexapod_tripod.toml"])
