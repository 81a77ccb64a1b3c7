"""Many simulations in parallel from Python threads: `fbd.run` releases the
GIL, so a `concurrent.futures.ThreadPoolExecutor` runs them on every core.
A drop-height study of the paper's fall: the first touchdown of leg 4.

    python examples/python/threads.py
"""

from __future__ import annotations

import concurrent.futures
import os
import time

import fbd

HEIGHTS = [0.55 + 0.025 * i for i in range(12)]


def first_touchdown(height: float) -> float:
    r = fbd.run({"initial": {"position": [0.0, height]}, "time": {"dt": 0.001, "duration": 1.0}})
    return r.summary["first_touchdown"]["leg4"]


def main() -> None:
    start = time.perf_counter()
    serial = [first_touchdown(h) for h in HEIGHTS]
    t_serial = time.perf_counter() - start

    start = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
        parallel = list(pool.map(first_touchdown, HEIGHTS))
    t_parallel = time.perf_counter() - start

    for h, t in zip(HEIGHTS, parallel):
        print(f"drop from Ry = {h:.3f} m: leg 4 touches down at t = {t:.4f} s")
    print(f"serial {t_serial:.3f} s, {os.cpu_count()} threads {t_parallel:.3f} s")
    if parallel != serial:
        raise SystemExit("threaded runs differ from serial runs")


if __name__ == "__main__":
    main()
