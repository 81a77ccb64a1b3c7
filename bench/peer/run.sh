#!/usr/bin/env bash
# fbd vs MuJoCo on the same models, one core, dt = 1 ms (issues 5, 11, 14,
# 24: hexapod_rough stands on a random height map, MuJoCo on its hfield).
#
#   bench/peer/run.sh            # from anywhere; needs cargo and python3
#   REPEAT=5 bench/peer/run.sh   # best of 5 rounds per case (default 3)
#   CASES="moving_flight hexapod_stand" bench/peer/run.sh   # some cases
#   FBD=path/to/fbd bench/peer/run.sh   # a prebuilt fbd, no build
#
# fbd: `fbd run` on bench/peer/<case>.toml, steps_per_second from
# summary.json (wall time of the stepping loop alone, output excluded), and
# its Newton iterations per step (mean, max) and the split of the
# iterations into chord steps (a factorisation reused) and full Newton
# steps (the Jacobian factored at the iterate).
# MuJoCo: the planar cases by mujoco_planar.py, the hexapod cases by
# mujoco_hexapod.py on the model `fbd export mjcf` writes of the same
# configuration (mujoco.rollout, one thread, same initial state, same
# number of steps). Prints one table: case, steps, fbd steps/s, MuJoCo
# steps/s, ratio fbd/MuJoCo, Newton iterations per step, chord/full; then
# the standing hexapod's normal forces in both and the walk's distance.
# The two alternate, one run each per round, and each reports its best
# round (both meet the same machine as its speed drifts). Pins both to
# one core with taskset if present. The binary is built in
# CARGO_TARGET_DIR (default: the tree's target/).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
repeat="${REPEAT:-3}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

pin=()
if command -v taskset > /dev/null; then pin=(taskset -c 0); fi

# MuJoCo: python3's own if it imports, else a virtual environment
# (PEER_VENV, default ~/.cache/fbd-peer-venv) with requirements.txt.
py=python3
if ! python3 -c 'import mujoco' 2> /dev/null; then
    venv="${PEER_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/fbd-peer-venv}"
    if ! "$venv/bin/python" -c 'import mujoco' 2> /dev/null; then
        echo "installing MuJoCo in $venv: pip install -r $here/requirements.txt" >&2
        python3 -m venv "$venv"
        "$venv/bin/python" -m pip install -q --disable-pip-version-check -r "$here/requirements.txt"
    fi
    py="$venv/bin/python"
fi
want=$(sed -n 's/^mujoco==//p' "$here/requirements.txt")
have=$("$py" -c 'import mujoco; print(mujoco.__version__)')
if [ "$have" != "$want" ]; then
    echo "note: MuJoCo $have, the table in README.md was measured with $want" >&2
fi

if [ -n "${FBD:-}" ]; then
    fbd=$FBD # a prebuilt binary (e.g. on a machine without the toolchain)
else
    (cd "$root" && cargo build --release -q --bin fbd)
    fbd="${CARGO_TARGET_DIR:-$root/target}/release/fbd"
fi

# case           model    MuJoCo case
all=(
    "flight planar flight"
    "contact_stand planar stand"
    "contact_hang planar hang"
    "moving_flight planar moving_flight"
    "passive_fall planar passive_fall"
    "hexapod_stand hexapod stand"
    "hexapod_walk hexapod walk"
    "hexapod_rough hexapod stand"
    "hexapod_drop hexapod drop"
)
wanted="${CASES:-}"

# One fbd run of $1 into $2: "steps sps mean max chord/full" (iterations
# per step, mean and max; chord/full Newton iterations), or "FAILED ...".
fbd_once() {
    local config=$1 dir=$2
    if ! "${pin[@]}" "$fbd" run "$config" --out "$dir" > "$dir.log" 2>&1; then
        if [ ! -f "$dir/summary.json" ]; then
            echo "FAILED $(tail -n 1 "$dir.log")"
            return
        fi
    fi
    python3 - "$dir/summary.json" << 'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
if d["status"] != "ok":
    print("FAILED", d["error"])
    sys.exit()
if d.get("model") == "hexapod" and not d.get("newton_iterations"):
    print("FAILED this fbd ran the kinematic gait, not the 3D dynamics")
    sys.exit()
per = d.get("newton_iterations_per_step")
mean = per["mean"] if per else d["newton_iterations"] / max(d["steps"], 1)
mx = per["max"] if per else "-"
split = f'{d["chord_iterations"]}/{d["full_newton_iterations"]}' if "chord_iterations" in d else "-"
print(d["steps"], d["steps_per_second"], f"{mean:.2f}", mx, split)
EOF
}

# The larger of two numbers.
larger() { python3 -c "print(max($1, $2))"; }

printf '%-14s %7s %12s %12s %7s %9s %7s %16s\n' \
    case steps "fbd steps/s" "MuJoCo st/s" ratio "it/step" "it max" "chord/full"
notes=()
for row in "${all[@]}"; do
    read -r name model mj <<< "$row"
    if [ -n "$wanted" ] && [[ " $wanted " != *" $name "* ]]; then continue; fi
    config="$here/$name.toml"
    if [ "$model" = planar ]; then
        mujoco_cmd=("$py" "$here/mujoco_planar.py" "$mj")
    else
        "$fbd" export mjcf "$config" --out "$out/$name.xml"
        extra=()
        if [ "$mj" = walk ]; then
            "$py" "$here/mujoco_hexapod.py" twin "$config" "$out/${name}_kinematic.toml"
            "$fbd" run "$out/${name}_kinematic.toml" --out "$out/${name}_kinematic" > /dev/null
            extra=(--targets "$out/${name}_kinematic/trajectory.csv")
        fi
        mujoco_cmd=("$py" "$here/mujoco_hexapod.py" "$mj" "$out/$name.xml" "${extra[@]}")
    fi
    # fbd and MuJoCo alternate, one run each per round, so that both meet
    # the same machine (a VM's speed drifts over minutes); the best of
    # $repeat rounds of each is reported.
    best=0
    msps=0
    failed=""
    for _ in $(seq "$repeat"); do
        result=$(fbd_once "$config" "$out/$name")
        case $result in FAILED*) failed=${result#FAILED }; break ;; esac
        read -r steps sps mean mx split <<< "$result"
        best=$(larger "$best" "$sps")
        mujoco=$("${pin[@]}" "${mujoco_cmd[@]}" --steps "$steps" --repeat 1)
        m=$(python3 -c 'import json, sys; print(json.loads(sys.argv[1])["steps_per_second"])' "$mujoco")
        msps=$(larger "$msps" "$m")
    done
    if [ -n "$failed" ]; then
        printf '%-14s fbd failed: %s\n' "$name" "$failed"
        continue
    fi
    if [ "$model" != planar ]; then notes+=("$name|$mj|$mujoco"); fi
    printf '%-14s %7d %12.0f %12.0f %7.2f %9s %7s %16s\n' "$name" "$steps" "$best" "$msps" \
        "$(python3 -c "print($best / $msps)")" "$mean" "$mx" "$split"
done

# The hexapod cases' physics side by side (fbd: the last row of
# trajectory.csv, t = the run's end).
for note in "${notes[@]}"; do
    IFS='|' read -r name mj mujoco <<< "$note"
    python3 - "$out/$name/trajectory.csv" "$mj" "$mujoco" "$name" << 'EOF'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
case, mj = sys.argv[2], json.loads(sys.argv[3])
first, last = rows[0], rows[-1]
print()
if case in ("stand", "drop"):
    print(f"{sys.argv[4]} at t = {float(last['t']):g} s: normal force of the ground on each foot (N)")
    print(f"{'foot':>6} {'fbd':>10} {'MuJoCo':>10}")
    total = 0.0
    for n in range(1, 7):
        # foot{n}_n: the normal component (= foot{n}_fy on flat ground).
        f = float(last.get(f"foot{n}_n", last.get(f"foot{n}_fy", "nan")))
        total += f
        m = mj["normal"].get(f"tip{n}", 0.0)
        print(f"{n:>6} {f:>10.3f} {m:>10.3f}")
    # Every contact point's normal force (knees and hips too, when they
    # touch: the drop comes to rest on its hips).
    for kind, col in (("knee", "kneepoint{}_n"), ("hip", "hippoint{}_n")):
        f = sum(float(last.get(col.format(n)) or 0.0) for n in range(1, 7))
        m = sum(mj["normal"].get(f"{kind}{n}", 0.0) for n in range(1, 7))
        if f or m:
            print(f"{kind + 's':>6} {f:>10.3f} {m:>10.3f}")
            total += f
    print(f"{'sum':>6} {total:>10.3f} {mj['normal_sum']:>10.3f}   weight {mj['weight']:.3f} N")
else:
    d = [float(last[k]) - float(first[k]) for k in ("rx", "ry", "rz")]
    m = [b - a for a, b in zip(mj["body_start"], mj["body_end"])]
    print(f"hexapod_walk: body displacement over {float(last['t']):g} s (m)")
    print(f"  fbd    ({d[0]:+.4f}, {d[1]:+.4f}, {d[2]:+.4f})")
    print(f"  MuJoCo ({m[0]:+.4f}, {m[1]:+.4f}, {m[2]:+.4f})")
EOF
done
