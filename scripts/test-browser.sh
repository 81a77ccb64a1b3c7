#!/usr/bin/env bash
# The browser test of viewer.html: runs the default experiment, the
# hexapod tripod gait, the dynamic hexapod walk and the lab hexapod
# imported from URDF in flight (its page from `fbd view`), opens each run's
# viewer.html in headless Chromium (Debian's package, driven by
# playwright-core from npm) and checks what it draws against
# trajectory.csv (tests/browser/viewer.test.mjs). Installs chromium with
# apt-get when it is missing (needs root), and the pinned playwright-core
# with `npm ci`. Saves the screenshots viewer.png, viewer_hexapod.png,
# viewer_hexapod_walk.png and viewer_robot.png in a temporary folder it names (or in
# $FBD_SCREENSHOT_DIR): the test leaves the checkout as it was.
# scripts/docs-figures.sh regenerates docs/*.png with FBD_SCREENSHOT_DIR=docs.
set -euo pipefail
cd "$(dirname "$0")/.."

chromium=${CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "installing Debian's chromium"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
  else
    echo "error: $chromium is missing: install Debian's chromium (apt-get install chromium) or set CHROMIUM" >&2
    exit 1
  fi
fi
command -v node >/dev/null || { echo "error: node is missing (apt-get install nodejs npm)" >&2; exit 1; }
(cd tests/browser && npm ci --no-audit --no-fund --loglevel=error)

# FBD_BIN: a prebuilt fbd (e.g. `--profile quick`'s) instead of the release build.
if [ -z "${FBD_BIN:-}" ]; then
  cargo build --release --bin fbd
fi
fbd="${FBD_BIN:-${CARGO_TARGET_DIR:-$PWD/target}/release/fbd}"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT
"$fbd" run --out "$runs/paper-fall" >/dev/null
"$fbd" run examples/hexapod_tripod.toml --out "$runs/hexapod-tripod" >/dev/null
"$fbd" run examples/hexapod_walk.toml --out "$runs/hexapod-walk" >/dev/null
"$fbd" run examples/robots/lab_hexapod_flight.toml --out "$runs/robot-flight" >/dev/null
"$fbd" view "$runs/robot-flight" >/dev/null

shots=${FBD_SCREENSHOT_DIR:-$(mktemp -d "${TMPDIR:-/tmp}/fbd-viewer-shots.XXXXXX")}
shots=$(cd "$shots" && pwd)
cd tests/browser
CHROMIUM="$chromium" FBD_PLANAR_DIR="$runs/paper-fall" FBD_HEXAPOD_DIR="$runs/hexapod-tripod" \
  FBD_DYNAMIC_DIR="$runs/hexapod-walk" FBD_ROBOT_DIR="$runs/robot-flight" \
  FBD_SCREENSHOT_DIR="$shots" node --test
echo "screenshots: $shots"
