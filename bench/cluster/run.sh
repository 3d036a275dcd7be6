#!/usr/bin/env bash
# Ranks on one host or on two: a rotation of the CT head (512x512, bone
# preset) with 2 ranks, once with both ranks on one host of the mini-cluster
# (shared memory between them) and once with one rank on each of two hosts
# (TCP between network namespaces, over veths and a bridge), on the same
# 2 cores. Per layout: seconds per frame and the mean of each phase (dist
# rend comp comm send), and the bytes per frame through h1's veth (those
# between the two hosts).
#
#   bench/cluster/run.sh [BUILD_DIR]     (default: build; needs root)
# Environment: PVR_BENCH_FRAMES (36), PVR_BENCH_SIZE (512), PVR_BENCH_RUNS
# (5), PVR_BENCH_NAME (rotation). The layouts alternate, run after run, so
# that the load other work puts on the machine falls on both alike; the
# summary gives each layout's median over the runs. Writes
# bench/results/cluster/NAME.csv (one row per frame and run) and NAME.txt
# (one line per run, the medians, the load average before and after).
#
# The layouts put rank 0 on h0, where pvrd and pvrsh run too:
#   1 host x 2 ranks:  hostfile "h0 slots=2"
#   2 hosts x 1 rank:  hostfile "h0 slots=1", "h1 slots=1"
# so the master's connect-back stays on h0 and both layouts load h0's share
# of the cores alike with pvrd and pvrsh.
set -euo pipefail
bench_dir=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$bench_dir/../.." && pwd)
PVR_BUILD=$(cd "${1:-$root/build}" && pwd)
export PVR_BUILD
data=$(cd "$root/../shared/data" && pwd)
out=$root/bench/results/cluster
name=${PVR_BENCH_NAME:-rotation}
frames=${PVR_BENCH_FRAMES:-36}
size=${PVR_BENCH_SIZE:-512}
runs=${PVR_BENCH_RUNS:-5}
[ "$(id -u)" -eq 0 ] || { echo "run.sh: the mini-cluster needs root" >&2; exit 1; }
[ -f "$data/ct_head_cranium/ct_head_cranium.json" ] || { echo "run.sh: $data/ct_head_cranium is missing" >&2; exit 1; }

source "$root/tests/cluster/lib.sh"
cluster_up
export PVRD_DATA=$data
mkdir -p "$out"
csv=$out/$name.csv
txt=$out/$name.txt
echo "layout,run,frame,dist,rend,comp,comm,send,arrival" >"$csv"
{
  echo "# bench/cluster/run.sh: CT head ${size}x${size}, bone preset, $frames frames of a rotation, 2 ranks, $runs runs"
  echo "# load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
} >"$txt"

# layout TAG RUN HOSTFILE-LINES...: one pvrd with that hostfile, one rotation.
layout() {
  local tag=$1 run=$2
  shift 2
  printf '%s\n' "$@" >"$PVR_CLUSTER_DIR/hostfile.$tag"
  start_pvrd "$tag" --hostfile "$PVR_CLUSTER_DIR/hostfile.$tag"
  local port_var=PORT_$tag
  pvrsh_on_h0 "$bench_dir/rotation.tcl" -host "127.0.0.1:${!port_var}" -tag "$tag" -run "$run" -csv "$csv" \
    -ranks 2 -frames "$frames" -size "$size" -preset "$root/examples/presets/ct_bone.json" -veth pvr-v1 | tee -a "$txt"
  stop_pvrds
}

for ((run = 1; run <= runs; run++)); do
  layout 1host_x_2ranks $run "h0 slots=2"
  layout 2hosts_x_1rank $run "h0 slots=1" "h1 slots=1"
done
# The median run of each layout by seconds per frame (field 6 of its lines).
for tag in 1host_x_2ranks 2hosts_x_1rank; do
  grep "^$tag " "$txt" | sort -g -k6,6 | sed -n "$(((runs + 1) / 2))p" | sed 's/^/median: /'
done | tee -a "$txt"
echo "# load average after: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$txt"
echo "run.sh: wrote $csv and $txt" >&2
