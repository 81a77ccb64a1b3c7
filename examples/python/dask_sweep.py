"""20 hexapod configurations on a Dask cluster of processes, checked
against the same runs done serially: fbd's results are picklable, runs
are deterministic, so where a run is computed does not change a bit.

    pip install "dask[distributed]"
    python examples/python/dask_sweep.py [--workers 2] [--duration 0.1]

Each configuration is the standing hexapod (PD-held joints, dropped 5 mm
onto flat ground) with its own soil friction and PD stiffness; each task
is ``fbd.run(config)`` (the GIL released inside) on a worker process of a
``distributed.LocalCluster``, and returns the whole ``fbd.Result``. A
second kind of task steps a pickled ``fbd.Simulator`` state 50 steps
further on a worker. The script prints the runs' final heights and
asserts that every column of every result equals the serial run's.

The same on a real cluster: ``dask_jobqueue.SLURMCluster(...)`` in place of
``LocalCluster`` (README, "Python"), or Ray's ``ray.remote(fbd.run)``.
"""

from __future__ import annotations

import argparse
from typing import Any, Dict, List

import numpy as np

import fbd

STAND = {
    "model": "hexapod",
    "time": {"dt": 0.001, "duration": 0.1},
    "initial": {
        "position": [0.0, 0.3566, 0.0],
        "phi_deg": [0.0, 0.0, 0.0],
        **{f"leg{leg}": {"theta_deg": [0.0, -20.0, 290.0]} for leg in range(1, 7)},
    },
    "terrain": {"kind": "flat", "mu_static": 0.8, "mu_dynamic": 0.6},
    "control": {"kind": "pd", "kp": 300.0, "kd": 8.0},
}


def configurations(n: int = 20, duration: float = 0.1) -> List[Dict[str, Any]]:
    """``n`` variations of the stand: friction and stiffness."""
    out = []
    for i in range(n):
        mu = 0.3 + 0.05 * (i % 10)
        c = {k: (dict(v) if isinstance(v, dict) else v) for k, v in STAND.items()}
        c["time"] = {"dt": 0.001, "duration": duration}
        c["terrain"] = {"kind": "flat", "mu_static": mu, "mu_dynamic": 0.75 * mu}
        c["control"] = {"kind": "pd", "kp": 250.0 + 25.0 * (i // 10), "kd": 8.0}
        out.append(c)
    return out


def step_state(state: "fbd.SimulatorState", config: Dict[str, Any], steps: int) -> np.ndarray:
    """Restores a (pickled) state in a new simulator and steps it on."""
    sim = fbd.Simulator(config)
    sim.set_state(state)
    sim.step(steps=steps)
    return sim.q


def same(a: "fbd.Result", b: "fbd.Result") -> bool:
    """Every column equal, bit for bit."""
    return a.columns == b.columns and all(np.array_equal(a[c], b[c]) for c in a.columns)


def main(workers: int = 2, duration: float = 0.1) -> int:
    from distributed import Client, LocalCluster

    configs = configurations(20, duration)
    serial = [fbd.run(c) for c in configs]
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
        futures = client.map(fbd.run, configs, pure=False)
        results = client.gather(futures)
        # A simulator's state travels to a worker and goes on there.
        sim = fbd.Simulator(configs[0])
        sim.step(steps=30)
        state = sim.get_state()
        remote = client.submit(step_state, state, configs[0], 50).result()
    sim.step(steps=50)
    assert np.array_equal(remote, sim.q), "a state stepped on a worker = stepped here"
    bad = [i for i, (a, b) in enumerate(zip(results, serial)) if not same(a, b)]
    for i, r in enumerate(results):
        print(f"run {i:2d}: μS = {configs[i]['terrain']['mu_static']:.2f}, final ry = {r['ry'][-1]:.6f} m")
    assert not bad, f"runs {bad} differ from the serial runs"
    print(f"{len(results)} runs on {workers} worker processes = the serial runs, bit for bit")
    return len(results)


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--duration", type=float, default=0.1)
    a = p.parse_args()
    main(a.workers, a.duration)
