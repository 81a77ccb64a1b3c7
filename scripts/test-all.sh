#!/usr/bin/env bash
# Every test of the project: formatting and lints (warnings denied), the Rust
# tests, a build of the benchmarks, the Python package's tests and the
# browser test of the viewer. Installs what those need itself (a Python
# virtual environment, Debian's chromium, an npm package); needs the Rust
# toolchain, python3 and, for the browser test, apt-get (as root) or an
# installed chromium. `.ci/run` calls exactly this script.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy (warnings denied)"
cargo clippy --workspace --all-targets -- -D warnings
echo "== cargo test"
cargo test --workspace
# The benchmarks compiled and linked with the test build's dependencies
# (`cargo bench` itself builds them optimised, in a profile of its own).
echo "== cargo build --benches"
cargo build --workspace --benches

for part in scripts/test-python.sh scripts/test-browser.sh; do
  if [ -f "$part" ]; then
    echo "== $part"
    bash "$part"
  fi
done
echo "== all tests passed"
