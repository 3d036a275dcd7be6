#!/usr/bin/env bash
# bench/scale: from disk to first frame (issue 11). Writes the N^3 uint8
# test volume by streaming (pvr-bench-scale-volume: the CT head resampled,
# air around it), measures a cold and a warm sequential read of its file,
# then renders it with pvr-node --batch and through pvrd + pvrsh on 1, 2, 4
# and 8 ranks, cold and warm: wall time to the first frame, its phases,
# per-rank peak RSS and the frame rate after the first frame. The series
# part writes a K-step series of M^3 steps and times `render time` without
# read-ahead (-cachemem 0) and with a budget, cold, beside the static frame
# rate of one step. CSV, table and gnuplot plot into bench/results/scale/;
# the columns are in bench/scale/README.md.
#
#   bench/scale/run.sh [--size N] [--ranks "1 2 4 8"] [--frames F] [--no-series] [--series-only]
#                      [--decomposition kd|balanced|slabs] [--summaries] [BUILD_DIR]   (default: build, kd)
# --summaries adds, per rank count, runs with persistent brick summaries
# (PVR_SUMMARY_CACHE=DATA/summaries, emptied first; io/brick_summary.h):
# one that writes them (cache "sumfill"), then one that reads them (cache
# "summaries": page cache and summaries warm). The cold and warm rows
# never see a summary.
# Environment: PVR_SCALE_DATA (data directory, outside the repository;
# default /work/scale-data), PVR_SCALE_SERIES_SIZE (256), PVR_SCALE_STEPS
# (50), PVR_SCALE_CACHEMEM (read-ahead budget in MB, 4096), PVR_SCALE_DROP
# (drop_caches or fadvise: how to empty the page cache; default drop_caches
# where /proc/sys/vm/drop_caches is writable), PVR_SCALE_TAG (output name,
# scale).
#
# Run the full size (2048) alone on the machine: other processes' CPU and
# I/O change every figure.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
size=2048 ranks="1 2 4 8" frames=20 static=1 series=1 build=$root/build decomposition=kd summaries=0
while [ $# -gt 0 ]; do
  case $1 in
    --size) size=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --no-series) series=0; shift ;;
    --series-only) static=0; shift ;;
    --decomposition) decomposition=$2; shift 2 ;;
    --summaries) summaries=1; shift ;;
    -*) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    *) build=$1; shift ;;
  esac
done
build=$(cd "$build" && pwd)
data=${PVR_SCALE_DATA:-/work/scale-data}
series_size=${PVR_SCALE_SERIES_SIZE:-256}
steps=${PVR_SCALE_STEPS:-50}
cachemem=${PVR_SCALE_CACHEMEM:-4096}
tag=${PVR_SCALE_TAG:-scale}
out=$root/bench/results/scale
head_json=$root/../shared/data/ct_head_cranium/ct_head_cranium.json  # read only when a volume is written
node=$build/pvrd/pvr-node pvrd=$build/pvrd/pvrd pvrsh=$build/pvrsh/pvrsh gen=$build/bench/scale/pvr-bench-scale-volume
for exe in "$node" "$pvrd" "$pvrsh" "$gen"; do
  [ -x "$exe" ] || { echo "run.sh: build $exe first (cmake --build $build --target pvr-node pvrd pvrsh pvr-bench-scale-volume)" >&2; exit 1; }
done
case "$data" in "$root"/*) echo "run.sh: PVR_SCALE_DATA must be outside the repository" >&2; exit 1 ;; esac
mkdir -p "$data" "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
unset PVR_SUMMARY_CACHE
summary_dir=$data/summaries
[ "$summaries" = 1 ] && rm -rf "$summary_dir"
csv=$out/$tag.csv log=$out/$tag.log
echo "kind,ranks,cache,voxels,wall_s,read_file_s,start,read,prep,dist,rend,comp,comm,send,write,frames,fps,rss_max_mb,rss_mb_per_rank,cpu_s_frame" > "$csv"
: > "$log"
say() { echo "$*" | tee -a "$log"; }
now() { date +%s.%N; }

# The page cache: drop_caches empties it for every file (root only);
# fadvise(DONTNEED) drops the pages of the given files alone.
drop=${PVR_SCALE_DROP:-}
if [ -z "$drop" ]; then
  if [ -w /proc/sys/vm/drop_caches ]; then drop=drop_caches; else drop=fadvise; fi
fi
dropCache() {
  sync
  if [ "$drop" = drop_caches ]; then
    echo 3 > /proc/sys/vm/drop_caches
  else
    /usr/bin/python3 - "$@" <<'PY'
import os, sys
for path in sys.argv[1:]:
    fd = os.open(path, os.O_RDONLY)
    os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
    os.close(fd)
PY
  fi
}
say "page cache emptied before each cold measurement by: $drop"
# Other jobs' load changes every figure: it is written beside them.
load_before=$(cut -d' ' -f1-3 /proc/loadavg)

# Seconds to read FILES sequentially (16 MiB blocks).
readSeconds() {
  local start; start=$(now)
  for f in "$@"; do dd if="$f" of=/dev/null bs=16M status=none; done
  echo "$(now) - $start" | bc -l
}

# scene.json as pvrsh settings (-tf, -unitdist, -shading ...), so both
# paths render the same scene.
settings=$(/usr/bin/python3 - "$here/scene.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
tf, shading = s["transfer_function"], s.get("shading", {})
out = ["-tf", "{%s}" % " ".join(str(v) for p in tf["points"] for v in p), "-unitdist", str(tf["unit_distance"]),
       "-shading", "1" if shading.get("enabled") else "0"]
for key in ("ambient", "diffuse", "specular", "shininess"):
    if key in shading:
        out += ["-" + key, str(shading[key])]
print(" ".join(out))
PY
)
settings="$settings -decomposition $decomposition"

# pvrd on an ephemeral port over the data directory; its first stdout
# line names the port. Stopped on exit.
pvrd_pid=
startPvrd() {
  fifo=$(mktemp -u)
  mkfifo "$fifo"
  "$pvrd" --listen 127.0.0.1:0 --data-dir "$data" --node "$node" --max-ranks 8 >"$fifo" 2>>"$log" &
  pvrd_pid=$!
  exec 3<"$fifo"
  read -r -t 30 line <&3 || { echo "run.sh: pvrd did not start (see $log)" >&2; exit 1; }
  rm -f "$fifo"
  port=${line##*:}
}
stopPvrd() {
  [ -n "$pvrd_pid" ] || return 0
  kill -TERM "$pvrd_pid" 2>/dev/null || true
  wait "$pvrd_pid" 2>/dev/null || true
  pvrd_pid=
}
trap stopPvrd EXIT

# One pvrsh session (session.tcl) appending a row to the CSV.
session() {
  "$pvrsh" -nogui "$here/session.tcl" -host "127.0.0.1:$port" -pvrd "$pvrd_pid" -csv "$csv" \
    -settings "$settings" "$@" | tee -a "$log"
}

# One pvr-node --batch run: wall time from mpirun to the written image
# (measured here), and from its --stats CSV the phases (max over ranks) and
# every rank's peak RSS.
batch() {
  local n=$1 cache=$2 readfile=$3 voxels=$4 scene=$5 stats=$data/batch-stats.csv
  local start end
  start=$(now)
  mpirun --oversubscribe --bind-to none -np "$n" "$node" --decomposition "$decomposition" --batch "$scene" -o "$data/batch.png" \
    --stats "$stats" >> "$log"
  end=$(now)
  /usr/bin/python3 - "$stats" "$n" "$cache" "$voxels" "$(echo "$end - $start" | bc -l)" "$readfile" >> "$csv" <<'PY'
import csv, sys
stats, n, cache, voxels, wall, readfile = sys.argv[1:]
rows = list(csv.DictReader(open(stats)))
top = lambda k: max(float(r[k]) for r in rows)
rss = [float(r["peak_rss_bytes"]) / 2**20 for r in rows]
print(",".join(["batch", n, cache, voxels, "%.4f" % float(wall), readfile] +
               ["%.4f" % top(k) for k in ("start", "read", "prep", "dist", "rend", "comp", "comm", "send", "write")] +
               ["1", "", "%.1f" % max(rss), " ".join("%.1f" % v for v in rss), ""]))
PY
  tail -n 1 "$csv" | tee -a "$log"
}

if [ "$static" = 1 ]; then
  # The volume, once: streamed, at the lowest priority.
  stem=head$size raw=$data/head$size.raw
  if [ ! -f "$data/$stem.json" ]; then
    start=$(now)
    nice -n 19 "$gen" "$head_json" "$data" "$stem" "$size" > /dev/null
    say "wrote $raw ($(stat -c %s "$raw") bytes) in $(echo "$(now) - $start" | bc -l) s"
  fi
  voxels=$((size * size * size))
  /usr/bin/python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); s["volume"]["file"]=sys.argv[2]; json.dump(s, open(sys.argv[3], "w"))' \
    "$here/scene.json" "$data/$stem.json" "$data/$stem.scene.json"

  # Sequential reads of the file: cold, then warm (the cold read warmed it).
  dropCache "$raw"
  cold_read=$(readSeconds "$raw")
  warm_read=$(readSeconds "$raw")
  echo "read,1,cold,$voxels,$cold_read,$cold_read,,,,,,,,,,,,,," >> "$csv"
  echo "read,1,warm,$voxels,$warm_read,$warm_read,,,,,,,,,,,,,," >> "$csv"
  say "sequential read of $raw: cold $cold_read s, warm $warm_read s"

  for n in $ranks; do
    dropCache "$raw"
    batch "$n" cold "$cold_read" "$voxels" "$data/$stem.scene.json"
    batch "$n" warm "$warm_read" "$voxels" "$data/$stem.scene.json"
    if [ "$summaries" = 1 ]; then
      export PVR_SUMMARY_CACHE=$summary_dir
      batch "$n" sumfill "$warm_read" "$voxels" "$data/$stem.scene.json"
      batch "$n" summaries "$warm_read" "$voxels" "$data/$stem.scene.json"
      unset PVR_SUMMARY_CACHE
      rm -rf "$summary_dir"
    fi
  done

  startPvrd
  for n in $ranks; do
    dropCache "$raw"
    session -kind pvrsh -cache cold -ranks "$n" -dataset "$stem.json" -frames "$frames" -readfile "$cold_read" -voxels "$voxels"
    session -kind pvrsh -cache warm -ranks "$n" -dataset "$stem.json" -frames "$frames" -readfile "$warm_read" -voxels "$voxels"
  done
  stopPvrd
  if [ "$summaries" = 1 ]; then
    export PVR_SUMMARY_CACHE=$summary_dir  # pvrd's mpirun and its ranks inherit it
    startPvrd
    for n in $ranks; do
      session -kind pvrsh -cache sumfill -ranks "$n" -dataset "$stem.json" -frames "$frames" -readfile "$warm_read" -voxels "$voxels"
      session -kind pvrsh -cache summaries -ranks "$n" -dataset "$stem.json" -frames "$frames" -readfile "$warm_read" -voxels "$voxels"
      rm -rf "$summary_dir"
    done
    stopPvrd
    unset PVR_SUMMARY_CACHE
  fi
fi

if [ "$series" = 1 ]; then
  # The series, once, then without read-ahead and with it, cold; the
  # static frame rate of one step beside them.
  sstem=series${series_size}x$steps
  if [ ! -f "$data/$sstem.series.json" ]; then
    nice -n 19 "$gen" "$head_json" "$data" "$sstem" "$series_size" --series "$steps" > /dev/null
    say "wrote $data/$sstem.series.json: $steps steps of $series_size^3"
  fi
  svoxels=$((series_size * series_size * series_size))
  n=${ranks##* }
  files=("$data/$sstem"/step_*.raw)
  startPvrd
  dropCache "${files[@]}"
  session -kind series-static -cache cold -ranks "$n" -dataset "$sstem/step_0000.json" -frames "$steps" -voxels "$svoxels"
  dropCache "${files[@]}"
  session -kind series-nocache -cache cold -ranks "$n" -dataset "$sstem.series.json" -series "$steps" -cachemem 0 -voxels "$svoxels"
  dropCache "${files[@]}"
  session -kind series-cache -cache cold -ranks "$n" -dataset "$sstem.series.json" -series "$steps" -cachemem "$cachemem" -voxels "$svoxels"
  stopPvrd
fi

# The table and the plot.
/usr/bin/python3 "$here/table.py" "$csv" > "$out/$tag.txt"
{ echo "page cache emptied before each cold measurement by: $drop"
  echo "load average (1, 5, 15 min) before: $load_before, after: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) hardware threads"
  cat "$out/$tag.txt"; } | tee "$out/$tag.txt.new"
mv "$out/$tag.txt.new" "$out/$tag.txt"
if [ "$static" = 1 ]; then
  gnuplot -e "csv='$csv'; png='$out/$tag.png'" "$here/plot.gp"
  echo "wrote $csv, $out/$tag.txt and $out/$tag.png"
else
  echo "wrote $csv and $out/$tag.txt"
fi
