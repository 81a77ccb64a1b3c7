#!/usr/bin/env bash
# Regenerates the plots the README shows, in docs/: forces.svg, joints.svg
# and energy.svg of the default experiment, the gait diagram and footprints
# of examples/hexapod_tripod.toml, the feet's normal forces and the joint
# torques of examples/hexapod_walk.toml, the feet of
# examples/hexapod_rough.toml, and the sweep plot of
# examples/sweep_friction_height.toml; then the viewer screenshots
# docs/viewer.png, docs/viewer_hexapod.png and docs/viewer_hexapod_walk.png
# (scripts/test-browser.sh with FBD_SCREENSHOT_DIR=docs) and
# docs/hexapod_rough_viewer.png (tests/browser/shot.mjs); SKIP_SHOTS=1 skips
# them. The test command never writes docs/. FBD_BIN=path/to/fbd uses a
# prebuilt binary (e.g. `cargo build --profile quick -p fbd-cli`'s).
set -euo pipefail
cd "$(dirname "$0")/.."

# FBD_BIN: a prebuilt fbd (e.g. `--profile quick`'s) instead of the release build.
if [ -z "${FBD_BIN:-}" ]; then
  cargo build --release --bin fbd
fi
fbd="${FBD_BIN:-${CARGO_TARGET_DIR:-$PWD/target}/release/fbd}"
runs=$(mktemp -d)
trap 'rm -rf "$runs"' EXIT

"$fbd" run --out "$runs/paper" >/dev/null
for f in forces joints energy; do
  cp "$runs/paper/$f.svg" "docs/$f.svg"
done
"$fbd" run examples/hexapod_tripod.toml --out "$runs/tripod" >/dev/null
for f in gait footprints; do
  cp "$runs/tripod/$f.svg" "docs/hexapod_tripod_$f.svg"
done
"$fbd" run examples/hexapod_walk.toml --out "$runs/walk" >/dev/null
for f in feet torques; do
  cp "$runs/walk/$f.svg" "docs/hexapod_walk_$f.svg"
done
"$fbd" run examples/hexapod_rough.toml --out "$runs/rough" >/dev/null
cp "$runs/rough/feet.svg" docs/hexapod_rough_feet.svg
"$fbd" sweep examples/sweep_friction_height.toml --out "$runs/sweep" --plot slip4 \
  >/dev/null 2>&1
cp "$runs/sweep/sweep.svg" docs/sweep_friction_height.svg
echo "docs/: forces.svg joints.svg energy.svg hexapod_tripod_gait.svg hexapod_tripod_footprints.svg hexapod_walk_feet.svg hexapod_walk_torques.svg hexapod_rough_feet.svg sweep_friction_height.svg"
if [ "${SKIP_SHOTS:-0}" != 1 ]; then
  FBD_SCREENSHOT_DIR="$PWD/docs" bash scripts/test-browser.sh
  # The rough walk's viewer at mid-run (tests/browser/shot.mjs; the browser
  # test installed playwright-core).
  (cd tests/browser && node shot.mjs "$runs/rough" "$OLDPWD/docs/hexapod_rough_viewer.png" 0.5)
fi
