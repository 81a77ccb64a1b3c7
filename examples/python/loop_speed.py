"""How fast a 1 kHz hexapod control loop runs from Python, against `fbd
run` of the same motion, and the vector environment for N = 1, 2, 8.

    python examples/python/loop_speed.py [--fbd target/release/fbd] [--repeat 3]
    python examples/python/loop_speed.py --vector 1,2,4,8,16   # other N

The motion: examples/hexapod_stand.toml (the hexapod dropped 5 cm onto
flat ground, PD-held joints, 1 s = 1001 steps at Δt = 1 ms), run four ways
that give the same trajectory bit for bit (the script checks it):

* ``fbd run`` (the CLI, when ``--fbd`` is given) and ``fbd.run``: the
  built-in ``[control] kind = "pd"``; steps/s of ``summary.json`` (the
  stepping loop alone);
* torques every step: a Python loop computing the PD law in NumPy from
  ``sim.q``, ``sim.qdot`` and calling ``sim.step(tau)`` 1000 times;
* PD targets every 20 steps: ``sim.set_pd_targets(...)`` then
  ``sim.step(steps=20)``, 50 times (a 50 Hz policy over 1 kHz physics).

Then ``fbd/HexapodWalk-v0``'s vector entry point with N = 1, 2, 8
(``--vector``) sub-environments (zero actions, 50 steps of 20 physics steps each), and N
serial environments for comparison: environment steps per second,
physics steps per second, and the vector environment's Python work per
control period (its time less the physics inside ``step_many``) and of
a reset of all N (the fastest). Prints the best of ``--repeat`` runs of
each.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import fbd

ROOT = pathlib.Path(__file__).resolve().parents[2]
STAND = ROOT / "examples" / "hexapod_stand.toml"
KP, KD = 300.0, 8.0


def passive_text() -> str:
    return STAND.read_text().replace('kind = "pd"', 'kind = "none"')


def torques_every_step():
    sim = fbd.Simulator(passive_text())
    target = sim.q0[6:]
    n = sim.steps - 1
    t = time.perf_counter()
    for _ in range(n):
        sim.step(KP * (target - sim.q[6:]) + KD * (0.0 - sim.qdot[6:]))
    return n / (time.perf_counter() - t), sim.q


def targets_every_20():
    sim = fbd.Simulator(passive_text())
    target = sim.q0[6:]
    n = sim.steps - 1
    t = time.perf_counter()
    for _ in range(n // 20):
        sim.set_pd_targets(target, KP, KD)
        sim.step(steps=20)
    return n / (time.perf_counter() - t), sim.q


def builtin():
    r = fbd.run(STAND)
    names = sim_names()
    return r.summary["steps_per_second"], np.array([r[c][-1] for c in names])


def sim_names():
    return fbd.Simulator(passive_text()).coordinate_names


def cli(binary: str):
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([binary, "run", str(STAND), "--out", d], check=True, capture_output=True)
        return json.loads(pathlib.Path(d, "summary.json").read_text())["steps_per_second"]


def vector(n: int, serial: bool, steps: int = 50):
    """Environment steps per second of N sub-environments, and the Python
    work of a control period (µs: its time less the physics in
    `step_many`; the vector environment only)."""
    import gymnasium

    import fbd.gym

    if serial:
        envs = [gymnasium.make("fbd/HexapodWalk-v0").unwrapped for _ in range(n)]
        for i, e in enumerate(envs):
            e.reset(seed=i)
        a = np.zeros(18)
        t = time.perf_counter()
        for _ in range(steps):
            for e in envs:
                e.step(a)
        return n * steps / (time.perf_counter() - t), float("nan"), float("nan")
    v = gymnasium.make_vec("fbd/HexapodWalk-v0", num_envs=n, vectorization_mode="vector_entry_point")
    v.reset(seed=0)
    a = np.zeros((n, 18))
    step_many = fbd.gym._fbd.step_many
    physics = [0.0]

    def timed(*args):
        t0 = time.perf_counter()
        out = step_many(*args)
        physics[0] += time.perf_counter() - t0
        return out

    fbd.gym._fbd.step_many = timed
    try:
        t = time.perf_counter()
        for _ in range(steps):
            v.step(a)
        dt = time.perf_counter() - t
    finally:
        fbd.gym._fbd.step_many = step_many
    t = time.perf_counter()
    v.reset(seed=1)
    reset = time.perf_counter() - t
    return n * steps / dt, (dt - physics[0]) / steps * 1e6, reset * 1e3


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fbd", help="the fbd binary (for `fbd run`)")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--skip-vector", action="store_true")
    p.add_argument("--skip-loop", action="store_true", help="only the vector environment")
    p.add_argument("--vector", default="1,2,8", help="the vector environment's N, comma-separated (default 1,2,8)")
    args = p.parse_args()
    best = lambda f: max((f() for _ in range(args.repeat)), key=lambda x: x[0])  # noqa: E731
    print(f"load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if not args.skip_loop:
        loop(args, best)
    if args.skip_vector:
        return
    print()
    print(
        "| HexapodWalk-v0, N sub-environments | vector env: env steps/s (physics steps/s) "
        "| its Python work a period (µs) | a reset of all N (ms) | N serial envs: env steps/s |"
    )
    print("|---|---|---|---|---|")
    for n in (int(x) for x in args.vector.split(",")):
        runs = [vector(n, False) for _ in range(args.repeat)]
        v, py, _ = max(runs)
        reset = min(r[2] for r in runs)
        s, _, _ = max(vector(n, True) for _ in range(args.repeat))
        print(f"| N = {n} | {v:,.0f} ({20 * v:,.0f}) | {py:,.0f} | {reset:.2f} | {s:,.0f} ({20 * s:,.0f}) |")


def loop(args, best) -> None:
    s_run, q_run = best(builtin)
    s_tau, q_tau = best(torques_every_step)
    s_pd, q_pd = best(targets_every_20)
    same = np.array_equal(q_run, q_tau) and np.array_equal(q_run, q_pd)
    print("| 1 kHz hexapod loop (examples/hexapod_stand.toml, 1000 steps) | steps/s |")
    print("|---|---|")
    if args.fbd:
        print(f"| `fbd run` (built-in PD) | {max(cli(args.fbd) for _ in range(args.repeat)):,.0f} |")
    print(f"| `fbd.run` (built-in PD) | {s_run:,.0f} |")
    print(f"| Python: torques every step (NumPy PD, `sim.step(tau)`) | {s_tau:,.0f} |")
    print(f"| Python: PD targets every 20 steps (`sim.step(steps=20)`) | {s_pd:,.0f} |")
    print(f"final states of the three equal bit for bit: {same}")


if __name__ == "__main__":
    main()
