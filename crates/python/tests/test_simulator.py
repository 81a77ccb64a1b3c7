"""fbd.Simulator: stepping reproduces fbd.run; a PD loop written in Python
reproduces the built-in PD controller; the state and forces it exposes
obey the physics (force balance of the whole robot in flight and at rest)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import fbd

PD = """
[time]
dt = 0.002
duration = 0.4
[initial]
position = [0.0, 0.4446709007300815]
[initial.leg3]
theta_deg = [0.0, 250.0]
[initial.leg4]
theta_deg = [0.0, 250.0]
[control]
kind = "pd"
kp = 3000.0
kd = 10.0
torque_limit = 150.0
[control.leg3]
target_deg = [0.0, 250.0]
[control.leg4]
target_deg = [5.0, 245.0]
"""


def python_pd(sim: fbd.Simulator, kp: float, kd: float, limit: float, target) -> np.ndarray:
    """The built-in PD law: τ = kp·(θ* − θ[k]) − kd·(θ[k] − θ[k−1])/Δt,
    clamped to ±limit; joints hip3, knee3, hip4, knee4 are q[3:7]."""
    q, qdot = sim.q, sim.qdot
    tau = kp * (target - q[3:7]) - kd * qdot[3:7]
    return np.clip(tau, -limit, limit)


def test_python_pd_loop_equals_builtin_pd():
    builtin = fbd.run(PD)
    passive = PD.replace('kind = "pd"', 'kind = "none"')
    sim = fbd.Simulator(passive)
    target = np.radians([0.0, 250.0, 5.0, 245.0])
    rows = []
    for _ in range(sim.steps):
        rows.append(sim.q)
        sim.step(python_pd(sim, 3000.0, 10.0, 150.0, target))
    q = np.array(rows)
    names = ["rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4"]
    want = np.column_stack([builtin[n] for n in names])
    assert q.shape == want.shape
    np.testing.assert_allclose(q, want, rtol=0, atol=1e-12)
    # The loop actually used the torques (they saturate at landing).
    assert np.max(np.abs(builtin["tau_knee4"])) == pytest.approx(150.0)
    assert any(e["to"] != "ST1" for e in builtin.events)


def test_stepping_with_the_configured_controller_equals_run(examples):
    cfg = examples / "pd_stand.toml"
    r = fbd.run(cfg)
    sim = fbd.Simulator(cfg)
    assert sim.steps == r.rows and sim.dt == 0.002
    for k in range(sim.steps):
        assert sim.k == k and sim.t == k * sim.dt
        np.testing.assert_array_equal(sim.q, [r[n][k] for n in ("rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4")])
        sim.step()
        # The forces of the step just solved are row k.
        names = sim.contact_points
        fa = sim.contact_forces[:, 0]
        n = sim.contact_forces[:, 1]
        assert fa[names.index("tip4")] == r["fa4"][k] and n[names.index("tip3")] == r["n3"][k]
        np.testing.assert_array_equal(sim.joint_forces[1], [r["knee3_fx"][k], r["knee3_fy"][k]])
        np.testing.assert_array_equal(sim.joint_torques, [r[c][k] for c in ("tau_hip3", "tau_knee3", "tau_hip4", "tau_knee4")])
    assert sim.events == r.events


def test_steps_argument_and_reset():
    sim = fbd.Simulator({"time": {"duration": 0.3}})
    sim.step(steps=25)
    assert sim.k == 25 and sim.t == pytest.approx(0.25)
    q25 = sim.q
    events = sim.events
    assert [e["leg"] for e in events if e["point"] == "tip"][:2] == [4, 3]
    sim.reset()
    assert sim.k == 0 and sim.events == []
    np.testing.assert_array_equal(sim.q, sim.q0)
    for _ in range(25):
        sim.step()
    np.testing.assert_array_equal(sim.q, q25)


def test_state_and_shapes():
    sim = fbd.Simulator()
    assert sim.contact_points == ["tip3", "tip4", "knee3", "knee4", "hip3", "hip4"]
    assert sim.contact_states.tolist() == [1] * 6  # ST1: in the air
    assert sim.contact_forces.shape == (6, 2) and not sim.contact_forces.any()
    assert sim.joint_forces.shape == (4, 2)
    assert sim.q.shape == (7,) and sim.qdot.shape == (7,)
    np.testing.assert_array_equal(sim.qdot, np.zeros(7))  # initial velocity
    assert sim.energy is None
    sim.step(steps=30)
    states = dict(zip(sim.contact_points, sim.contact_states.tolist()))
    assert states["tip4"] in (2, 3) and states["tip3"] in (2, 3)
    kin, pot = sim.energy
    assert kin > 0 and math.isfinite(pot)
    assert "Simulator(" in repr(sim)


def test_qdot_is_the_backward_difference():
    sim = fbd.Simulator({"initial": {"velocity": [0.5, 1.0]}})
    np.testing.assert_array_equal(sim.qdot[:2], [0.5, 1.0])
    q0 = sim.q
    sim.step()
    np.testing.assert_array_equal(sim.qdot, (sim.q - q0) / sim.dt)


def link_coms(q: np.ndarray) -> dict:
    """Centres of mass (N, 2) of the body and each link of legs 3 and 4, for
    the built-in geometry: upper links at ½ a from the hip, lower links at
    ¾ c from the knee (README)."""
    p = fbd.planar_fk(q)
    hip, knee, tip = p["hip"], p["knee"], p["tip"]
    return {
        "body": q[:, :2],
        "upper": hip + 0.5 * (knee - hip),  # (N, leg, 2)
        "lower": knee + 0.75 * (tip - knee),
    }


def test_flight_force_balance_with_external_torques():
    # In flight, with joint torques from Python, each body's discrete
    # Newton equation m·(p[k+1] − 2p[k] + p[k−1])/Δt² = ΣF[k] holds for the
    # joint forces the simulator reports; the torques are internal, so the
    # centre of mass of the whole robot falls exactly g·t²/2.
    sim = fbd.Simulator({"time": {"duration": 0.2}, "terrain": {"kind": "none"}})
    g, dt = 9.81, sim.dt
    m_body, m_up, m_low = 10.0, 0.3, 1.1
    qs, forces = [sim.q], []
    for k in range(20):
        sim.step([1.5 * math.sin(k), -2.0, 0.7, 3.0 * math.cos(k)])
        qs.append(sim.q)
        forces.append(sim.joint_forces)  # hip3, knee3, hip4, knee4 at step k
    q = np.array(qs)
    c = link_coms(q)
    acc = {n: (v[2:] - 2 * v[1:-1] + v[:-2]) / dt**2 for n, v in c.items()}  # k = 1 …
    f = np.array(forces)[1:]  # forces at k = 1 …
    grav = np.array([0.0, -g])
    hip, knee = f[:, [0, 2]], f[:, [1, 3]]  # (K, leg, 2)
    tol = 1e-7 * m_body * g
    np.testing.assert_allclose(m_low * acc["lower"], knee + m_low * grav, rtol=0, atol=tol)
    np.testing.assert_allclose(m_up * acc["upper"], hip - knee + m_up * grav, rtol=0, atol=tol)
    np.testing.assert_allclose(m_body * acc["body"], -hip.sum(axis=1) + m_body * grav, rtol=0, atol=tol)
    assert np.abs(knee).max() > 1.0  # the torques load the joints
    # The whole robot's centre of mass: a free fall, from rest.
    total = m_body + 2 * (m_up + m_low)
    com = (m_body * c["body"] + m_up * c["upper"].sum(axis=1) + m_low * c["lower"].sum(axis=1)) / total
    t = np.arange(len(q)) * dt
    np.testing.assert_allclose(com[:, 1], com[0, 1] - g * t**2 / 2, rtol=0, atol=1e-10)
    np.testing.assert_allclose(com[:, 0], com[0, 0], rtol=0, atol=1e-10)
    # and the joints moved differently from a passive fall.
    passive = fbd.Simulator({"time": {"duration": 0.2}, "terrain": {"kind": "none"}})
    passive.step(steps=20)
    assert np.abs(sim.q[3:] - passive.q[3:]).max() > 1e-3


def test_bad_torques():
    sim = fbd.Simulator()
    with pytest.raises(ValueError, match="expected 4 joint torques"):
        sim.step([1.0, 2.0])
    with pytest.raises(ValueError):
        sim.step("abc")
    # A NaN or an infinity is named before the step (it used to fail the
    # step as a non-finite residual, with advice about feedback gains).
    with pytest.raises(ValueError, match=r"torques: must be finite \(got NaN at index 2\)"):
        sim.step([0.0, 0.0, np.nan, 0.0])
    with pytest.raises(ValueError, match=r"torques: must be finite \(got -inf at index 0\)"):
        sim.step([-np.inf, 0.0, 0.0, 0.0])
    twins = [fbd.Simulator(), fbd.Simulator()]
    rows = np.zeros((2, 4))
    rows[1, 3] = np.nan
    with pytest.raises(ValueError, match=r"row 1: torques: must be finite \(got NaN at index 3\)"):
        fbd.step_many(twins, rows)
    assert [t.k for t in twins] == [0, 0]
    assert sim.k == 0
    sim.step(np.zeros(4))
    sim.step((0, 0, 0, 0))
    assert sim.k == 2


def test_failing_step_raises_and_refuses_until_reset():
    from test_errors import FAILING

    with pytest.raises(fbd.SimulationError) as ref:
        fbd.run(FAILING)
    sim = fbd.Simulator(FAILING)
    with pytest.raises(fbd.SimulationError) as info:
        sim.step(steps=100)
    assert info.value.step == ref.value.step and info.value.time == ref.value.time
    assert sim.k == ref.value.step
    # The state stays at the last solved step: row k − 1 of the partial run.
    last = ref.value.result
    taus = [last[c][-1] for c in ("tau_hip3", "tau_knee3", "tau_hip4", "tau_knee4")]
    np.testing.assert_array_equal(sim.joint_torques, taus)
    with pytest.raises(fbd.SimulationError, match="reset"):
        sim.step()
    sim.reset()
    sim.step()
    assert sim.k == 1
