#!/usr/bin/env bash
# Compositing benchmark: 2..16 ranks (oversubscribed on this machine),
# 512^2 and 1024^2 frames of the CT head with a bone transfer function,
# every strategy with RLE and RLE+zlib; CSV and gnuplot PNGs into
# bench/results/compositing/. A few minutes on 2 cores.
#
#   bench/compositing/run.sh [BUILD_DIR]     (default: build)
#   bench/compositing/run.sh --plot-only     (redraw from the CSV)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
plot_only=0
if [ "${1:-}" = --plot-only ]; then plot_only=1; shift; fi
build=${1:-$root/build}
out=$root/bench/results/compositing
scene=$root/examples/scenes/ct_head_bone.json
bench=$build/bench/compositing/pvr-bench-compositing
ranks_list=${PVR_BENCH_RANKS:-"2 3 4 6 8 12 16"}

[ $plot_only = 1 ] || [ -x "$bench" ] || { echo "run.sh: build $bench first (cmake --build $build --target pvr-bench-compositing)" >&2; exit 1; }
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpirun=(mpirun --oversubscribe --bind-to none)

if [ $plot_only = 0 ]; then
rm -f "$out/compositing.csv" "$out/memory.csv"
{
  echo "# $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $(mpirun --version | head -1)"
  for n in $ranks_list; do
    "${mpirun[@]}" -np "$n" "$bench" --scene "$scene" --size 512 --size 1024 --repeat 3 --radix 4 \
      --csv "$out/compositing.csv" --memory-csv "$out/memory.csv"
  done
  # The CT head at 8 ranks, more repetitions: compositing's share of the
  # frame, and binary swap / radix-k against the tree.
  rm -f "$out/ct_head_8ranks.csv"
  "${mpirun[@]}" -np 8 "$bench" --scene "$scene" --size 512 --size 1024 --repeat 7 --radix 4 \
    --csv "$out/ct_head_8ranks.csv"
} | tee "$out/run.log"
fi

# Plots: one data file per (size, strategy, codec), ranks ascending.
data=$(mktemp -d)
trap 'rm -rf "$data"' EXIT
awk -F, -v dir="$data" 'NR > 1 { f = dir "/" $2 "-" $4 "-" $5 ".dat"; print > f }' "$out/compositing.csv"
strategies="binary-swap radix-k-4 direct-send tree"

plot_lines() {  # size codec column
  local sep="" cmd=""
  for s in $strategies; do
    cmd+="$sep'$data/$1-$s-$2.dat' using 1:$3 with linespoints title '$s'"
    sep=", "
  done
  echo "$cmd"
}

breakdown_lines() {  # strategy: dist, rend, comp, comm, send of 512 x 512 RLE
  echo "'$data/512-$1-rle.dat' using 1:10 with linespoints title 'dist', '' using 1:11 with linespoints title 'rend'," \
       "'' using 1:7 with linespoints title 'comp', '' using 1:8 with linespoints title 'comm'," \
       "'' using 1:9 with linespoints title 'send'"
}

gnuplot <<GNUPLOT
set datafile separator ','
set terminal pngcairo size 1100,450 font ',10'
set key top left
set xlabel 'ranks (oversubscribed on $(nproc) cores)'
set grid

set output '$out/composite_time.png'
set multiplot layout 1,2 title 'CT head, bone TF: composite time, max over ranks (comp + comm + send), RLE'
set ylabel 'seconds'
set title '512 x 512'
plot $(plot_lines 512 rle 6)
set title '1024 x 1024'
plot $(plot_lines 1024 rle 6)
unset multiplot

set output '$out/bytes_messages.png'
set multiplot layout 1,2 title '1024 x 1024: what compositing sends (all ranks, RLE)'
set ylabel 'MB sent'
set title 'bytes on the wire'
plot $(plot_lines 1024 rle '($17/1e6)')
set ylabel 'messages'
set title 'messages'
set logscale y
plot $(plot_lines 1024 rle 14)
unset logscale y
unset multiplot

set output '$out/compression.png'
set title 'compression ratio (float RGBA bytes / bytes sent), 1024 x 1024'
set ylabel 'ratio'
plot '$data/1024-binary-swap-rle.dat' using 1:18 with linespoints title 'binary-swap RLE', \
     '$data/1024-binary-swap-rle-zlib.dat' using 1:18 with linespoints title 'binary-swap RLE+zlib', \
     '$data/1024-direct-send-rle.dat' using 1:18 with linespoints title 'direct-send RLE', \
     '$data/1024-direct-send-rle-zlib.dat' using 1:18 with linespoints title 'direct-send RLE+zlib'

set output '$out/breakdown.png'
set multiplot layout 1,2 title 'time breakdown, max over ranks (Table 1 of Ma et al.), 512 x 512, RLE'
set ylabel 'seconds (log scale)'
set logscale y
set key bottom right
set title 'binary-swap'
plot $(breakdown_lines binary-swap)
set title 'tree'
plot $(breakdown_lines tree)
unset multiplot
GNUPLOT
echo "wrote $out/compositing.csv, memory.csv and PNGs"
