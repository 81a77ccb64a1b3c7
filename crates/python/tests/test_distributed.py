"""Distributed runs: fbd.Result, Simulator states and environments
pickle; examples/python/dask_sweep.py runs 20 configurations on a real Dask
LocalCluster of worker processes and finds them equal to the serial runs,
bit for bit (and a Simulator state stepped on a worker)."""

from __future__ import annotations

import os
import pickle

import numpy as np
import pytest

import fbd

from conftest import ROOT


def test_result_pickles():
    r = fbd.run({"time": {"duration": 0.05}})
    back = pickle.loads(pickle.dumps(r))
    assert back.columns == r.columns and back.events == r.events and back.summary == r.summary
    for c in r.columns:
        np.testing.assert_array_equal(back[c], r[c])


def test_dask_local_cluster_equals_serial(monkeypatch):
    pytest.importorskip("distributed")
    # The example's module on the path of this process and of the worker
    # processes the cluster starts (tasks name its functions).
    here = str(ROOT / "examples" / "python")
    monkeypatch.syspath_prepend(here)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")])))
    import dask_sweep

    assert dask_sweep.main(workers=2, duration=0.05) == 20
