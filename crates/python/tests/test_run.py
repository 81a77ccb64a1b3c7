"""fbd.run: every column equals the CLI's files bit for bit; dict, string
and path configurations agree; files are written only with `out`."""

from __future__ import annotations

import csv
import json
import math
import struct

import numpy as np
import pytest

import fbd
from conftest import run_cli

# A short paper fall with every contact point, and the PD stand (torques,
# knees and hips, ST3 events) shortened.
SHORT_PAPER = "[time]\nduration = 0.4\n"


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def bits(x: float) -> int:
    return struct.unpack("<q", struct.pack("<d", x))[0]


def assert_same_as_csv(result: fbd.Result, path) -> None:
    header, rows = read_csv(path)
    assert result.columns == header
    assert result.rows == len(rows)
    for j, name in enumerate(header):
        col = result[name]
        for i, row in enumerate(rows):
            cell = row[j]
            if col.dtype.kind == "U":
                assert col[i] == cell, (name, i)
            elif col.dtype.kind == "i":
                assert int(col[i]) == int(cell), (name, i)
            else:
                want = float(cell)
                got = float(col[i])
                if math.isnan(want):
                    assert math.isnan(got), (name, i, got)
                else:
                    assert bits(got) == bits(want), f"{name}[{i}]: {got!r} != {cell}"


@pytest.mark.parametrize("example", ["paper.toml", "pd_stand.toml", "slope_slide.toml"])
def test_run_equals_cli_csv_bit_for_bit(cli, examples, tmp, example):
    out = tmp / "cli"
    p = run_cli(cli, "run", str(examples / example), "--out", str(out))
    assert p.returncode == 0, p.stderr
    result = fbd.run(examples / example)
    assert_same_as_csv(result, out / "trajectory.csv")
    # Events as events.csv.
    header, rows = read_csv(out / "events.csv")
    assert header == ["t", "leg", "from", "to", "point"]
    assert len(result.events) == len(rows) > 0
    for e, row in zip(result.events, rows):
        assert bits(e["t"]) == bits(float(row[0]))
        leg = "" if e["leg"] is None else str(e["leg"])
        assert [leg, e["from"], e["to"], e["point"]] == row[1:]
    # Summary as summary.json, apart from the timings.
    want = json.loads((out / "summary.json").read_text())
    got = dict(result.summary)
    for k in ("wall_seconds", "steps_per_second"):
        want.pop(k)
        got.pop(k)
    assert got == want


def test_out_writes_the_cli_files_byte_identical(cli, examples, tmp):
    cfg = examples / "pd_stand.toml"
    p = run_cli(cli, "run", str(cfg), "--out", str(tmp / "cli"))
    assert p.returncode == 0, p.stderr
    r = fbd.run(cfg, out=tmp / "py")
    for name in ("trajectory.csv", "events.csv", "config.toml", "tips.svg", "forces.svg", "stance.svg"):
        assert (tmp / "py" / name).read_bytes() == (tmp / "cli" / name).read_bytes(), name
    assert_same_as_csv(r, tmp / "py" / "trajectory.csv")


def test_no_files_without_out(tmp, monkeypatch):
    monkeypatch.chdir(tmp)
    fbd.run(SHORT_PAPER)
    assert list(tmp.iterdir()) == []


def test_dict_string_and_path_agree(examples, tmp):
    text = (examples / "pd_stand.toml").read_text()
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11 (the package needs none)

    as_dict = tomllib.loads(text)
    a = fbd.run(examples / "pd_stand.toml")
    b = fbd.run(text)
    c = fbd.run(as_dict)
    d = fbd.run(str(examples / "pd_stand.toml"))
    for name in a.columns:
        for other in (b, c, d):
            np.testing.assert_array_equal(a[name], other[name], err_msg=name)
    assert a.source.endswith("pd_stand.toml") and b.source == "<string>" and c.source == "<dict>"


def test_default_config_is_the_paper_fall():
    r = fbd.run()
    # The paper's events: leg 4 touches down at step 0.19, leg 3 at 0.21,
    # both start slipping at 0.24 (README).
    tips = [(e["t"], e["leg"], e["from"], e["to"]) for e in r.events if e["point"] == "tip"]
    assert (0.19, 4, "ST1", "ST2") in tips
    assert (0.21, 3, "ST1", "ST2") in tips
    assert (0.24, 4, "ST2", "ST3") in tips and (0.24, 3, "ST2", "ST3") in tips
    assert r.rows == 101 and r["t"][-1] == 1.0
    assert r.summary["status"] == "ok"


def test_result_columns_and_types():
    r = fbd.run({"time": {"duration": 0.3}, "output": {"stride": 2}})
    assert r.columns[:8] == ["t", "rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4"]
    assert r.columns[: len(fbd._fbd.TRAJECTORY_SPEC_COLUMNS)] == fbd._fbd.TRAJECTORY_SPEC_COLUMNS
    assert r.rows == 16  # 31 steps, every second one
    np.testing.assert_allclose(r["t"], np.arange(16) * 0.02, rtol=0, atol=1e-15)
    assert r["rx"].dtype == np.float64 and r["state3"].dtype.kind == "U"
    assert r["newton_iterations"].dtype == np.int64
    assert set(r["state4"]) <= {"ST1", "ST2", "ST3"}
    assert len(r) == len(r.columns) and list(r) == r.columns
    with pytest.raises(KeyError, match="no such column"):
        r["nope"]
    # Free fall until touchdown: Ry[k] = 0.6 − g·t²/2 exactly (discrete).
    free = r["t"] < 0.18
    np.testing.assert_allclose(r["ry"][free], 0.6 - 9.81 * r["t"][free] ** 2 / 2, rtol=0, atol=1e-12)
    assert "rows" in repr(r)


def test_to_pandas():
    pd = pytest.importorskip("pandas")
    r = fbd.run(SHORT_PAPER)
    df = r.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == r.columns and len(df) == r.rows
    np.testing.assert_array_equal(df["ry"].to_numpy(), r["ry"])


def test_config_toml_round_trips(tmp):
    text = fbd.config_toml({"time": {"duration": 0.25}})
    assert "duration = 0.25" in text
    a = fbd.run(text)
    b = fbd.run({"time": {"duration": 0.25}})
    np.testing.assert_array_equal(a["ry"], b["ry"])


def test_module_docstring_examples():
    import doctest

    failures, tried = doctest.testmod(fbd, verbose=False)
    assert tried >= 3 and failures == 0
