#!/usr/bin/env bash
# Throughput of fbd across cores: one fixed batch of hexapod walks
# (bench/scaling_walk.toml: 32 runs × 2001 steps, Δt = 1 ms) run
#
#   * by `fbd sweep --jobs J` (threads of one process), and
#   * as J independent `fbd run` processes, each taking every J-th run,
#
# for J = 1, 2, 4, … up to the cores (or THREADS="1 2 16"). Prints, per J,
# the batch's wall time, its steps per second (all steps / wall time, every
# output file written) and the speed-up and parallel efficiency against
# J = 1. Needs cargo and python3; builds fbd in CARGO_TARGET_DIR.
#
#   bash bench/scaling.sh                  # 1, 2, 4, … nproc
#   THREADS="1 2 8 16" bash bench/scaling.sh
#   PROFILE=quick bash bench/scaling.sh    # the quick profile's binary
#   FBD=path/to/fbd bash bench/scaling.sh  # a binary built elsewhere (no cargo)
#   SWEEP=big.toml bash bench/scaling.sh   # another batch (a sweep file)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
profile="${PROFILE:-release}"
if [ -n "${FBD:-}" ]; then
    fbd=$(cd "$(dirname "$FBD")" && pwd)/$(basename "$FBD")
else
    (cd "$root" && cargo build -q --profile "$profile" --bin fbd)
    fbd="${CARGO_TARGET_DIR:-$root/target}/$profile/fbd"
fi
sweep="$(cd "$(dirname "${SWEEP:-$here/scaling_walk.toml}")" && pwd)/$(basename "${SWEEP:-scaling_walk.toml}")"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

cores=$(nproc)
if [ -n "${THREADS:-}" ]; then
    threads=($THREADS)
else
    threads=()
    j=1
    while [ "$j" -lt "$cores" ]; do threads+=("$j"); j=$((j * 2)); done
    threads+=("$cores")
fi

# The batch's configurations, once: `fbd sweep` writes each run's
# config.toml (one job, so the setup is not timed twice).
"$fbd" sweep "$sweep" --out "$out/plan" --jobs "$cores" > /dev/null 2>&1
runs=("$out"/plan/runs/*/config.toml)
steps=$(python3 - "$out/plan/runs" << 'EOF2'
import json, pathlib, sys
print(sum(json.load(open(p))["steps"] for p in pathlib.Path(sys.argv[1]).glob("*/summary.json")))
EOF2
)
echo "batch: ${#runs[@]} runs, $steps steps; $cores cores; $($fbd --version 2> /dev/null || echo fbd)"
printf '%-8s %6s %10s %12s %8s %6s\n' how J wall_s steps/s speedup eff

now() { python3 -c 'import time; print(time.monotonic())'; }
report() {
    local how=$1 j=$2 t0=$3 t1=$4
    python3 - "$how" "$j" "$t0" "$t1" "$steps" "${base[$how]:-}" << 'EOF2'
import sys
how, j, t0, t1, steps, base = sys.argv[1:]
wall = float(t1) - float(t0)
sps = int(steps) / wall
b = float(base) if base else sps
print(f"{how:<8} {j:>6} {wall:>10.2f} {sps:>12.0f} {sps / b:>8.2f} {sps / b / int(j):>6.2f}")
print(sps, file=open("/dev/fd/3", "w"))
EOF2
}
declare -A base
for j in "${threads[@]}"; do
    t0=$(now)
    "$fbd" sweep "$sweep" --out "$out/sweep$j" --jobs "$j" > /dev/null 2>&1
    t1=$(now)
    sps=$(report sweep "$j" "$t0" "$t1" 3>&1 1>&2)
    [ -n "${base[sweep]:-}" ] || base[sweep]=$sps

    t0=$(now)
    for ((p = 0; p < j; p++)); do
        (
            for ((i = p; i < ${#runs[@]}; i += j)); do
                "$fbd" run "${runs[$i]}" --out "$out/proc$j/$i" > /dev/null 2>&1
            done
        ) &
    done
    wait
    t1=$(now)
    sps=$(report procs "$j" "$t0" "$t1" 3>&1 1>&2)
    [ -n "${base[procs]:-}" ] || base[procs]=$sps
done 2>&1
