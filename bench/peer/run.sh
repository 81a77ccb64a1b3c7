#!/usr/bin/env bash
# fbd vs MuJoCo on the same planar model, one core, dt = 1 ms (issue 5).
#
#   bench/peer/run.sh            # from anywhere; needs cargo and python3
#   REPEAT=5 bench/peer/run.sh   # best of 5 runs per case (default 3)
#
# fbd: `fbd run` on bench/peer/<case>.toml, steps_per_second from
# summary.json (wall time of the stepping loop alone, output excluded).
# MuJoCo: mujoco_planar.py (mujoco.rollout, one thread, same model, same
# initial state, same number of steps). Prints: case, fbd steps/s, MuJoCo
# steps/s, ratio fbd/MuJoCo. Pin both to one core with taskset if present.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
repeat="${REPEAT:-3}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

pin=()
if command -v taskset > /dev/null; then pin=(taskset -c 0); fi

python3 -c 'import mujoco' 2> /dev/null || {
    echo "installing MuJoCo: pip install -r $here/requirements.txt" >&2
    python3 -m pip install -q -r "$here/requirements.txt"
}

(cd "$root" && cargo build --release -q --bin fbd)
fbd="${CARGO_TARGET_DIR:-$root/target}/release/fbd"

# case  fbd config              MuJoCo case
cases=(
    "flight flight.toml flight"
    "contact_stand contact_stand.toml stand"
    "contact_hang contact_hang.toml hang"
)

printf '%-14s %8s %14s %14s %8s\n' case steps "fbd steps/s" "MuJoCo steps/s" ratio
for row in "${cases[@]}"; do
    read -r name config mj <<< "$row"
    best=0
    steps=0
    for _ in $(seq "$repeat"); do
        "${pin[@]}" "$fbd" run "$here/$config" --out "$out/$name" > /dev/null
        read -r s sps < <(python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert d["status"] == "ok", d["error"]
print(d["steps"], d["steps_per_second"])' "$out/$name/summary.json")
        steps=$s
        best=$(python3 -c "print(max($best, $sps))")
    done
    mujoco=$("${pin[@]}" python3 "$here/mujoco_planar.py" "$mj" --steps "$steps" --repeat "$repeat" |
        python3 -c 'import json, sys; print(json.loads(sys.stdin.readline())["steps_per_second"])')
    printf '%-14s %8d %14.0f %14.0f %8.2f\n' "$name" "$steps" "$best" "$mujoco" \
        "$(python3 -c "print($best / $mujoco)")"
done
