"""Runs in threads give the same results as serial runs (the GIL is
released while simulating), and sweeps from Python equal single runs."""

from __future__ import annotations

import concurrent.futures
import threading
import time

import numpy as np

import fbd

CONFIGS = [
    {"time": {"duration": 0.5}, "terrain": {"mu_static": mu, "mu_dynamic": 0.3 * mu / 0.4}}
    for mu in (0.3, 0.4, 0.6, 0.8)
] + [{"time": {"duration": 0.5}, "initial": {"position": [0.0, h]}} for h in (0.65, 0.7)]


def test_threads_equal_serial():
    serial = [fbd.run(c) for c in CONFIGS]
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        threaded = list(pool.map(fbd.run, CONFIGS))
    for a, b in zip(serial, threaded):
        assert a.columns == b.columns
        for name in a.columns:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)
        assert a.events == b.events


def test_simulators_in_threads_equal_serial():
    def drive(cfg):
        sim = fbd.Simulator(cfg)
        out = []
        for _ in range(sim.steps):
            out.append(sim.q)
            sim.step()
        return np.array(out)

    serial = [drive(c) for c in CONFIGS[:3]]
    with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
        threaded = list(pool.map(drive, CONFIGS[:3]))
    for a, b in zip(serial, threaded):
        np.testing.assert_array_equal(a, b)


def test_the_gil_is_released_during_a_run():
    # While a long run is in progress, another Python thread keeps running:
    # it counts far more than the few switches a held GIL would allow.
    done = threading.Event()
    ticks = [0]

    def count():
        while not done.is_set():
            ticks[0] += 1

    t = threading.Thread(target=count)
    t.start()
    try:
        start = time.perf_counter()
        # 200,000 steps in flight (no terrain), every 100th kept.
        fbd.run({"time": {"dt": 1e-4, "duration": 20.0}, "terrain": {"kind": "none"}, "output": {"stride": 100}})
        elapsed = time.perf_counter() - start
    finally:
        done.set()
        t.join()
    assert elapsed > 0.05
    assert ticks[0] > 1000, ticks[0]
