"""A PD controller closed in Python around `fbd.Simulator`, one Δt at a
time: the robot held 5 cm above the ground lands and stands, with its
joints regulated to target angles.

The law is the built-in `[control] kind = "pd"` one — τ = kp·(θ* − θ[k]) −
kd·θ̇[k], θ̇[k] the backward difference (θ[k] − θ[k−1])/Δt that
`Simulator.qdot` returns, clamped to ±limit — so `--check` compares the loop
with the built-in controller's run (equal to 1e-12).

    python examples/python/pd_loop.py [--check]
"""

from __future__ import annotations

import argparse

import numpy as np

import fbd

KP, KD, LIMIT = 3000.0, 10.0, 200.0
TARGET_DEG = [0.0, 250.0, 0.0, 250.0]  # hip3, knee3, hip4, knee4 (θ2, θ3)

CONFIG = {
    "time": {"dt": 0.002, "duration": 1.0},
    "initial": {
        "position": [0.0, 0.4446709007300815],  # tips 5 cm above the ground
        "leg3": {"theta_deg": [0.0, 250.0]},
        "leg4": {"theta_deg": [0.0, 250.0]},
    },
    "terrain": {"kind": "flat", "mu_static": 0.4, "mu_dynamic": 0.3},
}


def pd_torques(sim: fbd.Simulator, target: np.ndarray) -> np.ndarray:
    """The PD law on the joints q[3:7] = (θ2₃, θ3₃, θ2₄, θ3₄)."""
    tau = KP * (target - sim.q[3:7]) - KD * sim.qdot[3:7]
    return np.clip(tau, -LIMIT, LIMIT)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the built-in PD run")
    a = ap.parse_args()

    sim = fbd.Simulator(CONFIG)  # passive joints: the torques come from here
    target = np.radians(TARGET_DEG)
    q = []
    for _ in range(sim.steps):
        q.append(sim.q)
        sim.step(pd_torques(sim, target))
    q = np.array(q)
    n = sim.contact_forces[:, 1]
    weight = sum(
        m * 9.81 for m in (10.0, 2 * 0.3, 2 * 1.1)  # body, upper and lower links
    )
    print(f"{sim.steps} steps of {sim.dt} s; final body height {q[-1, 1]:.4f} m")
    print(f"normal forces at the end: {dict(zip(sim.contact_points, np.round(n, 2)))}")
    print(f"sum of normal forces {n.sum():.3f} N, weight {weight:.3f} N")
    print("events:", [(e["t"], e["leg"], e["point"], e["to"]) for e in sim.events][:6], "...")

    if a.check:
        builtin = dict(CONFIG)
        builtin["control"] = {
            "kind": "pd",
            "kp": KP,
            "kd": KD,
            "torque_limit": LIMIT,
            "leg3": {"target_deg": TARGET_DEG[:2]},
            "leg4": {"target_deg": TARGET_DEG[2:]},
        }
        r = fbd.run(builtin)
        cols = ["rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4"]
        want = np.column_stack([r[c] for c in cols])
        diff = np.max(np.abs(q - want))
        print(f"largest difference from the built-in PD run: {diff:.3e}")
        if not diff <= 1e-12:
            raise SystemExit("the Python PD loop differs from the built-in PD controller")
        if abs(n.sum() - weight) > 1e-6 * weight:
            raise SystemExit("the robot is not at rest on its feet")


if __name__ == "__main__":
    main()
