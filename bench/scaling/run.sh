#!/usr/bin/env bash
# Scaling benchmark of pvr-node --server (docs/runtime.md): 1..8 ranks
# (oversubscribed on this machine) on the CT head and a generated 512^3
# uint8 volume, 72-frame rotations at 256x256, layouts with groups and a
# compositing cluster; the distributed pipeline against pvr-render with
# both cores (CT head, 512x512); a generated 1024^3 uint8 volume on 8
# ranks with the bytes each rank holds. CSV + gnuplot PNG into
# bench/results/scaling/. A few minutes on 2 cores.
#
#   bench/scaling/run.sh [BUILD_DIR]      (default: build)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${1:-$root/build}
out=$root/bench/results/scaling
bench=$build/bench/scaling/pvr-bench-scaling
render=$build/tools/pvr-render
gen=$build/bench/scaling/data
ct=(--data-dir "$root/../shared/data" --dataset ct_head_cranium/ct_head_cranium.json --scene "$root/examples/scenes/ct_head_bone.json")
[ -x "$bench" ] || { echo "run.sh: build $bench first (cmake --build $build --target pvr-bench-scaling pvr-render)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out" "$gen"
[ -f "$gen/cube512.raw" ] || "$bench" --generate "$gen/cube512" 512
[ -f "$gen/cube1024.raw" ] || "$bench" --generate "$gen/cube1024" 1024
cat > "$gen/cube_scene.json" <<'JSON'
{"transfer_function": {"points": [[0, 0, 0, 0, 0], [50, 0.2, 0.3, 0.8, 0.0], [120, 0.9, 0.6, 0.3, 0.05], [230, 1, 1, 1, 0.6], [255, 1, 1, 1, 0.8]]},
 "image": {"background": [0, 0, 0, 1]}}
JSON
cube=(--data-dir "$gen" --scene "$gen/cube_scene.json")

csv=$out/scaling.csv
echo "label,ranks,layout,frames,size,wall_per_frame,dist,rend,comp,comm,send,max_rank_bytes,rank_bytes" > "$csv"
run() { "$bench" "$@" | tee -a "$csv"; }
for n in 1 2 4 8; do run --np $n "${ct[@]}" --label ct --frames 72; done
run --np 4 "${ct[@]}" --label ct-2clusters-1group --layout r2:0,r2:0 --frames 72
run --np 4 "${ct[@]}" --label ct-2groups --layout r2:0,r2:1 --frames 72
run --np 4 "${ct[@]}" --label ct-compositing-cluster --layout r3:0,c1:0 --frames 72
run --np 8 "${ct[@]}" --label ct-2groups --layout r4:0,r4:1 --frames 72
for n in 1 2 4 8; do run --np $n "${cube[@]}" --dataset cube512.json --label cube512 --frames 72; done
run --np 8 "${cube[@]}" --dataset cube1024.json --label cube1024 --frames 2

# Distributed pipeline vs pvr-render, both using the two cores, CT head 512x512.
run --np 1 "${ct[@]}" --label ct512-1rank-2threads --size 512 --threads 2 --frames 12
run --np 2 "${ct[@]}" --label ct512-2ranks --size 512 --frames 12
python3 - "$root/examples/scenes/ct_head_bone.json" "$gen/ct512_rotation" <<'PY'
import json, math, sys
scene = json.load(open(sys.argv[1]))
scene["volume"]["file"] = "/work/shared/data/ct_head_cranium/ct_head_cranium.json"
json.dump(scene, open(sys.argv[2] + ".json", "w"))
PY
start=$(date +%s.%N)
for i in 1 2 3; do "$render" "$gen/ct512_rotation.json" -o "$gen/ct512.png" --threads 2 > /dev/null; done
end=$(date +%s.%N)
echo "pvr-render-2threads,1,single process,3,512,$(echo "($end - $start) / 3" | bc -l),,,,,,," | tee -a "$csv"

# Plots: per-frame time and speedup against the 1-rank run of each dataset.
gnuplot <<GP
set datafile separator ","
set terminal pngcairo size 900,500
set output "$out/scaling.png"
set multiplot layout 1,2
set title "wall time per frame (72-frame rotation, 256x256)"
set xlabel "ranks"; set ylabel "seconds"; set logscale x 2; set key top right
plot "< grep '^ct,' $csv" using 2:6 with linespoints title "CT head", \
     "< grep '^cube512,' $csv" using 2:6 with linespoints title "512^3 uint8"
set title "breakdown per frame (max over ranks), CT head"
set ylabel "seconds"; set style data histograms; set style histogram rowstacked; set style fill solid; unset logscale x
plot "< grep '^ct' $csv | grep ',256,'" using 8:xtic(sprintf("%s/%d",strcol(1),column(2))) title "rend", '' using 9 title "comp", '' using 10 title "comm", '' using 11 title "send"
unset multiplot
GP
echo "wrote $csv and $out/scaling.png"
