"""The README's ARS figure that is cheap to check (Python, "fbd/HexapodWalk-v0"
and examples/python/train_ars.py): the evaluation return of the initial,
zero policy — "rises from −0.09 (standing still)". The rest of the curve
(60 iterations: 10–40 within 10 iterations, the final policy's 1.54 m) is
the README's measured training run, 10–25 minutes on 2 cores."""

from __future__ import annotations

import pathlib
import re
import subprocess
import sys

import pytest

pytest.importorskip("gymnasium")

ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_the_zero_policy_returns_what_the_readme_quotes(tmp):
    # Iteration 0 evaluates the zero policy on the evaluation seeds (the
    # defaults: 2 seeds, 2 s episodes); the directions do not matter to it.
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "python" / "train_ars.py"), "--iterations", "0", "--directions", "1"],
        capture_output=True,
        text=True,
        cwd=tmp,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    m = re.search(r"iteration\s+0\s+eval return\s+(-?\d+\.\d+)", r.stdout)
    assert m, r.stdout
    got = float(m.group(1))
    flat = " ".join((ROOT / "README.md").read_text().split())
    q = re.search(r"The evaluation return rises from ([−-]?\d+\.\d+) \(standing still\)", flat)
    assert q, "README.md no longer quotes the zero policy's return"
    decimals = len(q.group(1).split(".")[1])
    quoted = float(q.group(1).replace("−", "-"))
    assert f"{got:.{decimals}f}" == f"{quoted:.{decimals}f}", (
        f"README.md is stale: the zero policy's evaluation return is {got}, the README quotes {q.group(1)}"
    )
