#!/usr/bin/env bash
# Liveness: Status and Cancel answered during a long frame, and a
# rotation's frame rate (issue 15 finding 8; target 200 ms). Runs
# pvr-bench-liveness on the CT head from ../shared/data and writes
# bench/results/liveness/NAME.txt (the CSV lines and the table).
#
#   bench/liveness/run.sh [BUILD_DIR] [PVR_NODE]   (default: build, its pvr-node)
# PVR_NODE: another build's pvr-node, for a before/after comparison.
# Environment: PVR_BENCH_NAME (liveness), PVR_BENCH_TRIALS (5),
# PVR_BENCH_SIZE (512), PVR_BENCH_STEP (0.05), PVR_BENCH_ROTATION (36), PVR_BENCH_RANKS (2).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
node=${2:-$build/pvrd/pvr-node}
data=$(cd "$root/../shared/data" && pwd)
out=$root/bench/results/liveness
exe=$build/bench/liveness/pvr-bench-liveness
[ -x "$exe" ] || { echo "run.sh: build $exe first (cmake --build $build --target pvr-bench-liveness)" >&2; exit 1; }
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
{
  echo "# $(date -u +%FT%TZ) $(git -C "$root" rev-parse --short HEAD) node $node; load $(cut -d' ' -f1-3 /proc/loadavg)"
  "$exe" --data-dir "$data" --dataset ct_head_cranium/ct_head_cranium.json --node "$node" \
    --np "${PVR_BENCH_RANKS:-2}" --trials "${PVR_BENCH_TRIALS:-5}" --size "${PVR_BENCH_SIZE:-512}" \
    --step "${PVR_BENCH_STEP:-0.05}" --rotation "${PVR_BENCH_ROTATION:-36}"
} | tee "$out/${PVR_BENCH_NAME:-liveness}.txt"
