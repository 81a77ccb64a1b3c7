"""The binding's own cost per step: `Simulator.step()` called from Python
minus the time of the Rust step itself, and measured directly as the cost
of `sim.step(steps=0)` — the whole call (arguments, torques, releasing and
re-taking the GIL) without the physics.

The robot flies (no terrain), so a step is the cheapest the simulator has
(≈ 0.5 µs) and the binding's share is as large as it gets. The Rust time
is `summary["wall_seconds"] / steps` of `fbd.run` on the same model (the
time inside the stepping function alone); best of `--repeat` runs each.

    python examples/python/step_cost.py [--steps 200000] [--repeat 5]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import fbd


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    dt = 1e-3
    cfg = {"time": {"dt": dt, "duration": (a.steps - 1) * dt}, "terrain": {"kind": "none"}}

    rust = min(
        fbd.run(cfg).summary["wall_seconds"] / a.steps for _ in range(a.repeat)
    )

    def loop(body) -> float:
        best = float("inf")
        for _ in range(a.repeat):
            sim = fbd.Simulator(cfg)
            n = sim.steps
            start = time.perf_counter()
            body(sim, n)
            best = min(best, (time.perf_counter() - start) / n)
        return best

    def plain(sim, n):
        step = sim.step
        for _ in range(n):
            step()

    tau = np.zeros(4)

    def with_torques(sim, n):
        step = sim.step
        for _ in range(n):
            step(tau)

    def pd(sim, n):
        target = sim.q0[3:7]
        for _ in range(n):
            sim.step(np.clip(30.0 * (target - sim.q[3:7]) - 0.5 * sim.qdot[3:7], -5.0, 5.0))

    def batched(sim, n):
        sim.step(steps=n)

    def empty(sim, n):
        step = sim.step
        for _ in range(n):
            step(steps=0)

    def empty_tau(sim, n):
        step = sim.step
        for _ in range(n):
            step(tau, steps=0)

    def read_state(sim, n):
        for _ in range(n):
            sim.q
            sim.qdot

    rows = [
        ("sim.step()", loop(plain)),
        ("sim.step(tau)  (NumPy array of 4)", loop(with_torques)),
        ("PD loop: q, qdot, NumPy arithmetic, sim.step(tau)", loop(pd)),
        ("sim.step(steps=n)  (one call)", loop(batched)),
    ]
    direct = [
        ("sim.step(steps=0)  (the call without physics)", loop(empty)),
        ("sim.step(tau, steps=0)", loop(empty_tau)),
        ("sim.q and sim.qdot  (two new arrays)", loop(read_state)),
    ]
    print(f"Rust step alone (fbd.run wall_seconds/steps): {rust * 1e6:.3f} µs")
    for name, per in rows:
        print(f"{name:52s} {per * 1e6:7.3f} µs/step, minus Rust {(per - rust) * 1e6:7.3f} µs")
    for name, per in direct:
        print(f"{name:52s} {per * 1e6:7.3f} µs/call")


if __name__ == "__main__":
    main()
