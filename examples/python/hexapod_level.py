"""A closed-loop hexapod controller in Python: the robot of
examples/hexapod_slope.toml stands on a 10° slope and levels its body from
what it reads every 20 ms — the body's orientation and the six feet's
contact forces — by setting PD targets that Rust tracks at 1 kHz.

    python examples/python/hexapod_level.py

Each 20 ms the controller integrates the body's roll (once the feet carry
the weight) and moves every leg's θ2 down and θ3 up by the same angle on
the downhill side (the foot goes down, the lower link stays vertical),
the opposite uphill: the roll goes from 10° to below 0.5° in 1.5 s while
the normal forces still add up to the weight. The Rust version of the same
loop is `cargo run -p fbd-suite --example level_on_slope`.
"""

from __future__ import annotations

import pathlib

import numpy as np

import fbd

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main() -> float:
    text = (ROOT / "examples" / "hexapod_slope.toml").read_text()
    sim = fbd.Simulator(text.replace('kind = "pd"', 'kind = "none"'))  # our controller, not [control]
    stance = sim.q0[6:].copy()
    side = np.cos(np.radians([120, 60, 180, 0, 240, 300]))  # +1 right (uphill), −1 left, SPEC γ
    integral, roll = 0.0, 0.0
    for k in range(75):  # 75 × 20 ms: 50 Hz control over 1 kHz physics
        o = sim.observe()
        roll = float(np.arcsin(o["body_rotation"][0][1, 0]))  # the body's x axis out of the horizontal
        tips = slice(0, 6)
        load = o["contact_force"][tips, 1].sum()
        if load > 100.0:  # standing on its feet
            integral += roll * 0.02
        d = 10.0 * integral * side
        targets = stance.copy()
        targets[1::3] -= d  # θ2: bend uphill, stretch downhill
        targets[2::3] += d  # θ3: keep the lower links vertical
        sim.set_pd_targets(targets, kp=300.0, kd=8.0)
        sim.step(steps=20)
        if k % 15 == 0:
            states = "".join(str(s) for s in o["contact_state"][tips])
            print(f"t = {o['t']:.2f} s  roll = {np.degrees(roll):6.2f}°  Σ foot fy = {load:6.1f} N  feet {states}")
    o = sim.observe()
    roll = float(np.arcsin(o["body_rotation"][0][1, 0]))
    print(f"t = {o['t']:.2f} s  roll = {np.degrees(roll):6.2f}°  Σ foot fy = {o['contact_force'][:6, 1].sum():6.1f} N")
    assert abs(np.degrees(roll)) < 0.5, "the body is level"
    return roll


if __name__ == "__main__":
    main()
