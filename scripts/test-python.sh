#!/usr/bin/env bash
# The Python package's tests, in a fresh virtual environment: installs
# maturin, NumPy, pytest, pandas (Result.to_pandas), pyarrow (reading
# trajectory.parquet), matplotlib (the Fig. 7 example), gymnasium (fbd.gym),
# dask[distributed] (the Dask LocalCluster example), pin (Pinocchio),
# example-robot-data and mujoco (the imported-robot cross-checks) from PyPI, installs
# the package with the README's command
# (`pip install ./crates/python`, which builds the abi3 wheel with maturin),
# lints the binding's Rust code, runs the pytest suite against the `fbd`
# binary built from the same tree, and runs the examples, writing the Fig. 7
# plot. Needs the Rust toolchain and python3 (≥ 3.9) with venv.
#
#   bash scripts/test-python.sh            # KEEP_VENV=1 keeps the venv
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target}"
PYTHON="${PYTHON:-python3}"

WORK=$(mktemp -d "${TMPDIR:-/tmp}/fbd-python.XXXXXX")
cleanup() {
  if [ "${KEEP_VENV:-0}" = 1 ]; then echo "venv kept: $WORK/venv"; else rm -rf "$WORK"; fi
}
trap cleanup EXIT

echo "== python: fresh virtual environment ($("$PYTHON" --version))"
"$PYTHON" -m venv "$WORK/venv"
VPY="$WORK/venv/bin/python"
"$VPY" -m pip install --quiet --disable-pip-version-check --upgrade pip
"$VPY" -m pip install --quiet --disable-pip-version-check maturin numpy pytest pandas pyarrow matplotlib \
  gymnasium "dask[distributed]"
# Imported robots are checked against Pinocchio on real descriptions
# (tests/test_robot_import.py) and against MuJoCo on MJCF files
# (tests/test_robot_mujoco.py), pinned to the versions measured.
"$VPY" -m pip install --quiet --disable-pip-version-check pin==4.1.0 example-robot-data==6.0.0 \
  mujoco==4.0.0

echo "== python: pip install ./crates/python"
"$VPY" -m pip install --quiet --disable-pip-version-check ./crates/python

echo "== python: rustfmt and clippy of crates/python (warnings denied)"
cargo fmt --manifest-path crates/python/Cargo.toml -- --check
PYO3_PYTHON="$VPY" cargo clippy --quiet --release --manifest-path crates/python/Cargo.toml --all-targets -- -D warnings

echo "== python: the fbd binary the tests compare with"
cargo build --quiet --release -p fbd-cli --bin fbd
export FBD_BIN="$CARGO_TARGET_DIR/release/fbd"

echo "== python: pytest crates/python/tests"
# From a neutral directory, so that `import fbd` is the installed package.
(cd "$WORK" && "$VPY" -m pytest -q -p no:cacheprovider "$ROOT/crates/python/tests")

echo "== python: examples"
export MPLBACKEND=Agg
"$VPY" examples/python/paper_fall.py --out "$WORK/fig7.png"
test -s "$WORK/fig7.png"
"$VPY" examples/python/pd_loop.py --check
"$VPY" examples/python/threads.py
"$VPY" examples/python/hexapod_level.py
# ARS on the vector environment, CI-sized (the full run: README, "Python").
"$VPY" examples/python/train_ars.py --iterations 2 --directions 2 --eval-envs 1 \
  --episode-seconds 0.2 --plot "$WORK/ars.png"
test -s "$WORK/ars.png"
echo "== python: all passed"
