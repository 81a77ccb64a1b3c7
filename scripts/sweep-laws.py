#!/usr/bin/env python3
"""Checks the contact laws on every row of a 3D sweep on flat ground and
tabulates what the runs needed.

    python3 scripts/sweep-laws.py SWEEP_DIR [--tol 1e-6]

For every run `SWEEP_DIR/runs/<i>/` (its `trajectory.csv` or
`trajectory.parquet`, `summary.json` and complete `config.toml`; any
`[output] stride`), every contact point's columns are checked on every
written row, from the trajectory file alone: a free point (ST1) carries no
force; otherwise N ≥ 0, and with Ft the horizontal part of the force
(flat ground: the normal is +Y) |Ft| ≤ μS·N when sticking (ST2), |Ft| = μD·N
when sliding (ST3), and for a foot (whose position is a column) Ft opposes
the foot's slip to the next row, Ft = −μD·N·ŝ to the direction's
resolution 1e-12 m/|s| (docs/reference.md; not on the row of a step
solved in substeps, whose forces are its first substep's; stride 1 only:
with a stride the next row is several steps later). Tolerance: `tol` × the
robot's weight (default 1e-6). The run's own audit of every step, written
or not (`max_law_violation` of `summary.json`), is held to the same
tolerance. Prints one line per law-breaking run and the table of the
README: completed runs, exact rows, the audit's worst violation, steps per
second (median, slowest), Newton iterations per step, events per run,
retried steps. Exits 1 when a row or a step breaks a law. Standard
library only for CSV; Parquet files need pyarrow.
"""

import csv
import json
import math
import statistics
import sys
import tomllib
from pathlib import Path


# fbd_sim::spatial::step::SLIP_RESOLUTION (m).
SLIP_RESOLUTION = 1e-12


def weight(cfg):
    body = cfg.get("body", {})
    leg = cfg.get("leg", {})
    mass = body.get("mass", 6.0) + 6 * (leg.get("upper_mass", 0.8) + leg.get("lower_mass", 0.5))
    return mass * cfg.get("world", {}).get("gravity", 9.81)


def read_rows(run):
    """The written rows of a run as dicts (column -> value), from
    trajectory.parquet when the run wrote one, else trajectory.csv."""
    pq = run / "trajectory.parquet"
    if pq.exists():
        import pyarrow.parquet

        return pyarrow.parquet.read_table(pq).to_pylist()
    with open(run / "trajectory.csv", newline="") as f:
        return list(csv.DictReader(f))


def check_run(run, retried):
    cfg = tomllib.loads((run / "config.toml").read_text())
    mu_s = cfg["terrain"]["mu_static"]
    mu_d = cfg["terrain"]["mu_dynamic"]
    stride = cfg.get("output", {}).get("stride", 1)
    tol = TOL * weight(cfg)
    rows = read_rows(run)
    if not rows:
        return 0, 0, 0.0, []
    head = rows[0].keys()
    points = []
    for h in head:
        if h.startswith("state") and h[5:].isdigit():
            n = h[5:]
            points.append((f"foot{n}", h, f"foot{n}", True))
        elif h.endswith("_state"):
            p = h[: -len("_state")]
            points.append((p, h, p, False))
    bad, checked, worst, why = 0, 0, 0.0, []
    for i, r in enumerate(rows):
        row_bad = 0.0
        for name, scol, fcol, has_pos in points:
            st = r[scol]
            fx, fy, fz = (float(r[f"{fcol}_f{a}"]) for a in "xyz")
            n = float(r[f"{fcol}_n"])
            ftx, ftz = fx, fz
            ft = math.hypot(ftx, ftz)
            v = 0.0
            if st == "ST1":
                v = math.sqrt(fx * fx + fy * fy + fz * fz)
                law = "free point carries force"
            else:
                v = max(-n, 0.0)
                law = "N < 0"
                if st == "ST2":
                    e = ft - mu_s * n
                    if e > v:
                        v, law = e, "|Ft| > muS N"
                else:
                    e = abs(ft - mu_d * n)
                    if e > v:
                        v, law = e, "|Ft| != muD N"
                    if has_pos and stride == 1 and i + 1 < len(rows) and round(float(r["t"]), 9) not in retried:
                        nxt = rows[i + 1]
                        sx = float(nxt[f"{fcol}_x"]) - float(r[f"{fcol}_x"])
                        sz = float(nxt[f"{fcol}_z"]) - float(r[f"{fcol}_z"])
                        sl = math.hypot(sx, sz)
                        if sl > 1e-9 * DT:
                            e = math.hypot(ftx + mu_d * n * sx / sl, ftz + mu_d * n * sz / sl)
                            # The direction of a slip s is resolved to
                            # SLIP_RESOLUTION/|s| rad (docs/reference.md).
                            e = max(e - mu_d * abs(n) * SLIP_RESOLUTION / sl, 0.0)
                            if e > v:
                                v, law = e, "Ft not -muD N s^"
            if v > tol:
                why.append(f"t={r['t']} {name} {st}: {law} by {v:.3e} N")
            row_bad = max(row_bad, v)
        checked += 1
        bad += row_bad > tol
        worst = max(worst, row_bad)
    return checked, bad, worst, why


def main():
    global TOL, DT
    args = sys.argv[1:]
    TOL = 1e-6
    if "--tol" in args:
        i = args.index("--tol")
        TOL = float(args[i + 1])
        del args[i : i + 2]
    root = Path(args[0])
    runs = sorted((p for p in (root / "runs").iterdir() if p.is_dir()), key=lambda p: int(p.name))
    ok, total_rows, bad_rows, worst, audit, audit_bad = 0, 0, 0, 0.0, 0.0, 0
    sps, ipm, events, retried, retried_runs, errors = [], [], [], [], 0, []
    for run in runs:
        s = json.loads((run / "summary.json").read_text())
        DT = s["dt"]
        if s["status"] == "ok":
            ok += 1
        else:
            errors.append(f"run {run.name}: {s['error']}")
        sub = {round(e["t"], 9) for e in s["events"] if e["point"] == "substeps"}
        checked, bad, w, why = check_run(run, sub)
        # The engine's audit of every step of the run, written or not.
        a = s.get("max_law_violation", 0.0)
        audit = max(audit, a)
        cfg = tomllib.loads((run / "config.toml").read_text())
        if a > TOL * weight(cfg):
            audit_bad += 1
            print(f"run {run.name}: the run's audit found a step breaking a law by {a:.3e} N")
        total_rows += checked
        bad_rows += bad
        worst = max(worst, w)
        if why:
            print(f"run {run.name}: {bad} rows break a law, e.g. {why[0]}")
        if s.get("steps_per_second"):
            sps.append(s["steps_per_second"])
        ipm.append(s["newton_iterations"] / max(s["steps"], 1))
        events.append(sum(1 for e in s["events"] if e["point"] in ("tip", "knee", "hip")))
        retried.append(s.get("retried_steps", 0))
        retried_runs += s.get("retried_steps", 0) > 0
    for e in errors[:10]:
        print(e)
    n = len(runs)
    print()
    print("| runs | completed | rows exact | every step (audit) | steps/s median | slowest | Newton it./step median (max run) | events/run median (max) | retried steps (runs) |")
    print("|---|---|---|---|---|---|---|---|---|")
    print(
        f"| {n} | {ok}/{n} | {total_rows - bad_rows}/{total_rows} (worst {worst:.1e} N) "
        f"| {n - audit_bad}/{n} runs exact (worst {audit:.1e} N) "
        f"| {statistics.median(sps):.0f} | {min(sps):.0f} "
        f"| {statistics.median(ipm):.2f} ({max(ipm):.1f}) "
        f"| {statistics.median(events):.0f} ({max(events)}) "
        f"| {sum(retried)} ({retried_runs}) |"
    )
    return 1 if bad_rows or audit_bad else 0


if __name__ == "__main__":
    sys.exit(main())
