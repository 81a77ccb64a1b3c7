#!/usr/bin/env python3
"""The figures README.md quotes of a landing sweep ("The method, as
implemented": how robust this is), from a finished `fbd sweep` directory:

    fbd sweep examples/sweep_landing_1000.toml --out landing
    python3 scripts/landing-figures.py landing

prints the runs that completed, the runs (and steps) solved in substeps,
the runs (and steps) that closed a cycling state search by its least
inconsistent combination, the runs still moving at the end (kinetic energy
above 1 µJ) and the most and the median events of a run. Reads only each
run's summary.json (standard library only). tests/readme_figures.rs
(landing_sweeps_of_1000_runs) computes the same figures from both sweeps
and checks the README's paragraph.
"""

import json
import os
import statistics
import sys


def main(directory: str) -> None:
    runs = os.path.join(directory, "runs")
    summaries = []
    for name in sorted(os.listdir(runs), key=lambda n: int(n) if n.isdigit() else -1):
        path = os.path.join(runs, name, "summary.json")
        if name.isdigit() and os.path.exists(path):
            with open(path) as f:
                summaries.append((int(name), json.load(f)))
    n = len(summaries)
    ok = sum(s["status"] == "ok" for _, s in summaries)
    retried = [s["retried_steps"] for _, s in summaries if s["retried_steps"]]
    cycles = [s["resolved_cycles"] for _, s in summaries if s["resolved_cycles"]]
    moving = [i for i, s in summaries if s["final_energy"]["kinetic"] > 1e-6]
    events = [len(s["events"]) for _, s in summaries]
    worst = max(range(n), key=lambda k: events[k])
    print(f"{ok} of {n} runs completed")
    print(f"{len(retried)} runs needed substeps ({sum(retried)} steps in all)")
    print(f"{len(cycles)} runs closed a cycling state search ({sum(cycles)} steps)")
    print(f"{len(moving)} runs still move at the end (kinetic energy above 1 µJ)")
    print(
        f"most events of a run: {events[worst]} (run {summaries[worst][0]}),"
        f" median {statistics.median(events):g}"
    )


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python3 scripts/landing-figures.py SWEEP_DIR")
    main(sys.argv[1])
