"""fbd.sweep runs a sweep file like `fbd sweep`; each run equals fbd.run
of its configuration."""

from __future__ import annotations

import numpy as np
import pytest

import fbd


def test_sweep_runs_equal_single_runs(examples, tmp):
    sweep_file = tmp / "sweep.toml"
    sweep_file.write_text(
        f'base = "{examples / "paper.toml"}"\nmode = "grid"\n\n[vary]\n"terrain.mu_static" = [0.35, 0.6]\n"time.duration" = [0.3]\n'
    )
    res = fbd.sweep(sweep_file, tmp / "out", jobs=2)
    assert res.failed is None, res.failed
    assert res.runs == 2
    assert "terrain.mu_static" in res.index
    np.testing.assert_array_equal(res.index["terrain.mu_static"], [0.35, 0.6])
    assert (tmp / "out" / "runs" / "1" / "trajectory.csv").is_file()
    for i, mu in enumerate((0.35, 0.6)):
        single = fbd.run({"time": {"duration": 0.3}, "terrain": {"mu_static": mu}}, out=tmp / f"single{i}")
        assert (tmp / "out" / "runs" / str(i) / "trajectory.csv").read_bytes() == (
            tmp / f"single{i}" / "trajectory.csv"
        ).read_bytes()
        assert single.summary["status"] == "ok"
    assert "runs" in repr(res)


def test_sweep_with_failing_runs_reports_them(tmp):
    from test_errors import FAILING

    (tmp / "base.toml").write_text(FAILING)
    sweep_file = tmp / "sweep.toml"
    # The base fails at t = 0.26 s; stopped at 0.2 s it does not.
    sweep_file.write_text('base = "base.toml"\nmode = "zip"\n\n[vary]\n"time.duration" = [1.0, 0.2]\n')
    res = fbd.sweep(sweep_file, tmp / "out")
    assert res.failed is not None and "1 of 2 runs failed" in res.failed
    assert list(res.index["status"]) == ["error", "ok"]


def test_bad_sweep_file_is_a_config_error(tmp):
    sweep_file = tmp / "sweep.toml"
    sweep_file.write_text('mode = "grid"\n[vary]\n"time.dt" = [-1.0]\n')
    with pytest.raises((fbd.ConfigError, fbd.SimulationError)):
        res = fbd.sweep(sweep_file, tmp / "out")
        assert res.failed is None  # pragma: no cover
    missing = tmp / "missing.toml"
    with pytest.raises(fbd.ConfigError):
        fbd.sweep(missing, tmp / "out2")
