"""Outputs that scale: `[output] format = "parquet"` read by pandas (with
pyarrow) equals the CSV and the in-memory result; the module's namespace is
the API; a sweep writes per-run viewers and plots only when asked."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd
import pytest

import fbd

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "..", "examples")


@pytest.mark.parametrize(
    "config",
    [
        {"time": {"duration": 0.4}},
        os.path.join(EXAMPLES, "hexapod_walk.toml"),
        os.path.join(EXAMPLES, "hexapod_tripod.toml"),
    ],
    ids=["planar", "hexapod-dynamics", "hexapod-gait"],
)
def test_parquet_loads_in_pandas_equal_to_the_csv(tmp_path, config):
    if isinstance(config, str):
        text = open(config).read()
        # Short runs: a 0.3 s walk.
        text = text.replace("duration = 3.0", "duration = 0.3").replace(
            "duration = 11.5", "duration = 0.3"
        )
        csv_cfg = text + '\n[output]\nformat = "csv"\n'
        pq_cfg = text + '\n[output]\nformat = "parquet"\n'
    else:
        csv_cfg = {**config, "output": {"format": "csv"}}
        pq_cfg = {**config, "output": {"format": "parquet"}}
    r_csv = fbd.run(csv_cfg, out=tmp_path / "csv")
    r_pq = fbd.run(pq_cfg, out=tmp_path / "pq")
    assert not (tmp_path / "pq" / "trajectory.csv").exists()
    a = pd.read_csv(tmp_path / "csv" / "trajectory.csv")
    b = pd.read_parquet(tmp_path / "pq" / "trajectory.parquet")
    assert list(b.columns) == r_pq.columns == list(a.columns)
    # Same names, dtypes and values, exactly.
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    # And the in-memory result of the same run, bit for bit.
    for c in r_pq.columns:
        col = b[c].to_numpy()
        if col.dtype.kind == "f":
            assert np.array_equal(col, r_pq[c], equal_nan=True), c
        else:
            assert list(col) == list(r_pq[c]), c
    assert r_csv.rows == len(b)


def test_attitude_columns_of_the_walk():
    r = fbd.run(
        open(os.path.join(EXAMPLES, "hexapod_walk.toml"))
        .read()
        .replace("duration = 3.0", "duration = 0.01")
    )
    # Faces +X pitched up with the 3.5° slope.
    assert r["pitch"][0] == pytest.approx(np.radians(3.5), abs=1e-12)
    assert r["heading"][0] == pytest.approx(-np.pi / 2, abs=1e-12)
    assert abs(r["roll"][0]) < 1e-12


def test_dir_shows_only_the_api():
    names = set(dir(fbd))
    assert set(fbd.__all__) <= names
    for helper in ("np", "os", "csv", "json", "Mapping", "Any", "Dict"):
        assert helper not in names, helper


def test_sweep_writes_viewers_and_plots_only_when_asked(tmp_path):
    sweep = tmp_path / "s.toml"
    base = tmp_path / "base.toml"
    base.write_text("[time]\nduration = 0.1\n")
    sweep.write_text('base = "base.toml"\n[vary]\n"terrain.mu_static" = [0.4, 0.6]\n')
    plain = fbd.sweep(sweep, tmp_path / "plain", jobs=1)
    assert not (tmp_path / "plain" / "runs" / "0" / "viewer.html").exists()
    assert not (tmp_path / "plain" / "runs" / "0" / "forces.svg").exists()
    assert "MB" in plain.message or "kB" in plain.message
    fbd.sweep(sweep, tmp_path / "full", jobs=1, viewer=True, plots=True)
    assert (tmp_path / "full" / "runs" / "0" / "viewer.html").exists()
    assert (tmp_path / "full" / "runs" / "0" / "forces.svg").exists()


def test_simulator_says_when_it_is_past_its_duration():
    s = fbd.Simulator({"time": {"duration": 0.02}})
    assert not s.past_duration
    s.step(steps=2)
    assert s.past_duration
    s.step()  # goes on, as documented
    assert s.k == 3
