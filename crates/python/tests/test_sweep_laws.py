"""scripts/sweep-laws.py re-checks the contact laws on every written row of
a 3D sweep, from strided CSV and from Parquet trajectories, and the runs'
own audit of every step; it fails on a row that breaks a law."""

from __future__ import annotations

import csv
import json
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
SCRIPT = ROOT / "scripts" / "sweep-laws.py"


def sweep(cli, examples, tmp, name, stride, fmt):
    """Two short 3D landings (examples/hexapod_drop.toml, 0.5 s at 2 ms:
    the feet land at about 0.3 s) written with `stride` and `fmt`."""
    f = tmp / f"{name}.toml"
    f.write_text(
        f'base = "{examples / "hexapod_drop.toml"}"\nmode = "grid"\n'
        '[vary]\n"terrain.mu_static" = [0.3, 0.9]\n'
        '[derive]\n"terrain.mu_dynamic" = { from = "terrain.mu_static", scale = 0.75 }\n'
        f'[set]\n"time.dt" = 0.002\n"time.duration" = 0.5\n"output.stride" = {stride}\n"output.format" = "{fmt}"\n'
    )
    out = tmp / name
    subprocess.run([str(cli), "sweep", str(f), "--out", str(out), "--jobs", "2"], check=True, capture_output=True)
    return out


def laws(out):
    return subprocess.run([sys.executable, str(SCRIPT), str(out)], capture_output=True, text=True)


def table_row(stdout):
    return [c.strip() for c in stdout.strip().splitlines()[-1].strip("|").split("|")]


@pytest.mark.parametrize("stride,fmt", [(1, "csv"), (7, "csv"), (1, "parquet"), (7, "parquet")])
def test_sweep_laws_reads_strided_csv_and_parquet(cli, examples, tmp, stride, fmt):
    out = sweep(cli, examples, tmp, f"{fmt}{stride}", stride, fmt)
    ext = "parquet" if fmt == "parquet" else "csv"
    written = 0
    for i in range(2):
        run = out / "runs" / str(i)
        assert (run / f"trajectory.{ext}").is_file()
        s = json.loads((run / "summary.json").read_text())
        assert s["status"] == "ok" and s["stride"] == stride
        written += s["rows_written"]
    # 251 states at stride 1, every 7th (0, 7, …, 245) at stride 7.
    assert written == 2 * (251 if stride == 1 else 36)
    r = laws(out)
    assert r.returncode == 0, r.stdout + r.stderr
    row = table_row(r.stdout)
    assert row[0] == "2" and row[1] == "2/2", r.stdout
    assert row[2].startswith(f"{written}/{written} "), r.stdout
    assert row[3].startswith("2/2 runs exact"), r.stdout
    # index.csv shows the audit per run, whatever the stride, and its
    # numbers are summary.json's to the last bit.
    with open(out / "index.csv", newline="") as fh:
        index = list(csv.DictReader(fh))
    for i, rec in enumerate(index):
        s = json.loads((out / "runs" / str(i) / "summary.json").read_text())
        for key in ["max_law_violation", "distance", "final_height", "wall_seconds", "steps_per_second"]:
            assert float(rec[key]) == s[key], key
        assert int(rec["retried_steps"]) == s["retried_steps"]
        assert int(rec["substeps"]) == s["substeps"]


def test_sweep_laws_fails_on_a_row_that_breaks_a_law(cli, examples, tmp):
    out = sweep(cli, examples, tmp, "tampered", 7, "csv")
    path = out / "runs" / "1" / "trajectory.csv"
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    state, fx, n = head.index("state1"), head.index("foot1_fx"), head.index("foot1_n")
    # A sticking foot 1 whose friction exceeds μS·N (μS = 0.9).
    k = next(i for i, r in enumerate(rows[1:], 1) if r[state] == "ST2" and float(r[n]) > 1.0)
    rows[k][fx] = repr(float(rows[k][fx]) + 2.0 * float(rows[k][n]))
    with open(path, "w", newline="") as fh:
        csv.writer(fh).writerows(rows)
    r = laws(out)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "run 1: 1 rows break a law" in r.stdout and "|Ft| > muS N" in r.stdout, r.stdout
