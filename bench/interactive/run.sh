#!/usr/bin/env bash
# Interactive latency: request-to-pixels time of single 512x512 frames of the
# CT head in a Tk window (issue 6 target: 0.25 s). Starts pvrd on loopback
# with ../shared/data, runs bench/interactive/latency.tcl in pvrsh (under
# xvfb-run when there is no display), stops pvrd. Prints median and p90 and
# writes bench/results/interactive/NAME.csv and NAME.txt (NAME: latency).
#
#   bench/interactive/run.sh [BUILD_DIR]    (default: build)
# Environment: PVR_BENCH_FRAMES (50), PVR_BENCH_RANKS (2), PVR_BENCH_SHADING (1),
# PVR_BENCH_NAME (latency), PVR_BENCH_INTERACTIVE (0; 1: progressive renders,
# reporting request-to-first-pixels and request-to-full-quality),
# PVR_BENCH_REDUCTION (4: the coarse frame's pixels per axis), PVR_BENCH_EDIT
# (view: the view turns each request; tf: the transfer function moves; colour:
# its colours change), PVR_BENCH_EARLYTERM (the scene's early termination
# opacity; empty: the default).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
data=$(cd "${PVR_BENCH_DATA:-$root/../shared/data}" && pwd)  # a worktree elsewhere: PVR_BENCH_DATA
out=$root/bench/results/interactive
for exe in pvrsh/pvrsh pvrd/pvrd pvrd/pvr-node; do
  [ -x "$build/$exe" ] || { echo "run.sh: build $build/$exe first (cmake --build $build --target pvrsh pvrd pvr-node)" >&2; exit 1; }
done
[ -f "$data/ct_head_cranium/ct_head_cranium.json" ] || { echo "run.sh: $data/ct_head_cranium is missing" >&2; exit 1; }
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# pvrd on an ephemeral port; its first stdout line names it.
fifo=$(mktemp -u)
mkfifo "$fifo"
"$build/pvrd/pvrd" --listen 127.0.0.1:0 --data-dir "$data" --node "$build/pvrd/pvr-node" \
  --max-ranks 4 >"$fifo" 2>"$build/bench-interactive-pvrd.log" &
pvrd_pid=$!
trap 'kill -TERM $pvrd_pid 2>/dev/null; wait $pvrd_pid 2>/dev/null; rm -f "$fifo"' EXIT
exec 3<"$fifo"
read -r -t 10 line <&3 || { echo "run.sh: pvrd did not start (see $build/bench-interactive-pvrd.log)" >&2; exit 1; }
port=${line##*:}

run=()
[ -n "${DISPLAY:-}" ] || run=(xvfb-run -a)
"${run[@]}" "$build/pvrsh/pvrsh" "$here/latency.tcl" -host "127.0.0.1:$port" \
  -frames "${PVR_BENCH_FRAMES:-50}" -ranks "${PVR_BENCH_RANKS:-2}" -shading "${PVR_BENCH_SHADING:-1}" \
  -preset "$root/examples/presets/ct_bone.json" -out "$out" -tag "${PVR_BENCH_NAME:-latency}" \
  -interactive "${PVR_BENCH_INTERACTIVE:-0}" -reduction "${PVR_BENCH_REDUCTION:-4}" -edit "${PVR_BENCH_EDIT:-view}" \
  -earlyterm "${PVR_BENCH_EARLYTERM:-}" \
  | tee "$out/${PVR_BENCH_NAME:-latency}.txt"
