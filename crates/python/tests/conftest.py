"""Shared fixtures: the repository, the `fbd` CLI binary, temporary dirs."""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"


def _find_cli() -> pathlib.Path:
    """The `fbd` binary: $FBD_BIN, else built with cargo (release)."""
    env = os.environ.get("FBD_BIN")
    if env:
        return pathlib.Path(env)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "fbd-cli", "--bin", "fbd"],
        cwd=ROOT,
        check=True,
    )
    return target / "release" / "fbd"


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    path = _find_cli()
    assert path.is_file(), f"the fbd binary is missing: {path}"
    return path


@pytest.fixture(scope="session")
def examples() -> pathlib.Path:
    return EXAMPLES


def run_cli(cli: pathlib.Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli), *args], capture_output=True, text=True)


@pytest.fixture
def tmp(tmp_path: pathlib.Path) -> pathlib.Path:
    yield tmp_path
    shutil.rmtree(tmp_path, ignore_errors=True)


@pytest.fixture
def sigint_raises():
    """Python's own SIGINT handler for the test: a shell that starts the
    suite in the background makes SIGINT ignored, and an ignored signal is
    never raised (not even by `_thread.interrupt_main`)."""
    import signal

    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


@pytest.fixture
def ctrl_c(sigint_raises):
    """`with ctrl_c():` — Ctrl-C (a KeyboardInterrupt in the main thread)
    `seconds` (default 0.3) after entering the block."""
    import _thread
    import contextlib
    import threading

    @contextlib.contextmanager
    def after(seconds: float = 0.3):
        timer = threading.Timer(seconds, _thread.interrupt_main)
        timer.start()
        try:
            yield
        finally:
            timer.cancel()
            timer.join()

    return after
