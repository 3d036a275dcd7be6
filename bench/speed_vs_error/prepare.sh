# Sourced by the speed_vs_error scripts that run one sweep (quality.sh,
# early_termination.sh): names the build and results, builds speed_vs_error
# (Release, assertions off) and writes the peer benchmark's volume to
# build/bench-data/. Knob: BENCH_BUILD (build dir, default build-bench).
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
source "$HERE/../../scripts/lib/common.sh"
BUILD=${BENCH_BUILD:-$PVR_ROOT/build-bench}
RESULTS=$PVR_ROOT/bench/results
SVE=$BUILD/bench/speed_vs_error/speed_vs_error

mkdir -p "$RESULTS"
cmake -S "$PVR_ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DPVR_ASSERTIONS=OFF >/dev/null
cmake --build "$BUILD" --target speed_vs_error -j2 | grep -E "error|warning" || true
/usr/bin/python3 "$PVR_ROOT/bench/scenes/peer_blobs.py" volume "$PVR_ROOT/build/bench-data" >/dev/null
