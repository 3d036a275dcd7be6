#!/usr/bin/env bash
# Early ray termination: what stopping a ray at opacity A saves and what it
# costs in error, per scene.
#
# Builds speed_vs_error (Release, assertions off) in build-bench/, writes the
# peer benchmark's volume to build/bench-data/, and runs speed_vs_error
# --quick on every scene at its own settings with --early-termination A for
# each A in BENCH_THRESHOLDS, the thresholds by turns in each of
# BENCH_ROUNDS rounds (this host's noise moves a frame by tens of percent
# within minutes; samples and errors do not move). Prints one row a scene
# and threshold: median time over the rounds' medians, samples a frame and
# the error against the exact rendering. Writes
# bench/results/early_termination.txt.
#
# Knobs: BENCH_BUILD (build dir, default build-bench), BENCH_THRESHOLDS
# (1,0.99999,0.9999,0.999), BENCH_ROUNDS (3), BENCH_SCENES (scene files),
# BENCH_THREADS (2).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/prepare.sh"
ROUNDS=${BENCH_ROUNDS:-3}
IFS=, read -r -a THRESHOLDS <<< "${BENCH_THRESHOLDS:-1,0.99999,0.9999,0.999}"
read -r -a SCENES <<< "${BENCH_SCENES:-$PVR_ROOT/bench/scenes/peer_blobs.json \
  $PVR_ROOT/examples/scenes/ct_head_bone.json $PVR_ROOT/examples/scenes/mri_head.json \
  $PVR_ROOT/examples/scenes/mri_brain_pd.json $PVR_ROOT/examples/scenes/orbital_oxirane.json \
  $PVR_ROOT/examples/scenes/water_density.json $PVR_ROOT/examples/scenes/default.json}"

# The figures of one --quick run: seconds a frame, M samples a frame, RMSE, PSNR, max abs.
figures() {
  "$SVE" --quick "$1" --early-termination "$2" --threads "${BENCH_THREADS:-2}" | awk '
    /time per frame/     { t = $4 }
    /samples per second/ { for (i = 1; i <= NF; ++i) if ($i == "a" && $(i + 1) == "frame") m = $(i - 2) }
    /error vs reference/ { gsub(",", ""); r = $5; p = $7; x = $11 }
    /skipped/            { print "skipped"; exit }
    END                  { if (t != "") print t, m, r, p, x }'
}

source "$HERE/../lib/median.sh"  # median_of

{
  echo "# early ray termination, $(date -u '+%Y-%m-%d %H:%M UTC'), $(git -C "$PVR_ROOT" rev-parse --short HEAD 2>/dev/null || echo 'no git')"
  echo "# speed_vs_error --quick, each scene at its own settings, ${BENCH_THREADS:-2} threads; time: median of $ROUNDS rounds' medians"
  echo "# (thresholds by turns); error: linear RGBA against the exact rendering at 256 px (unchanged by the rounds)"
  echo "# load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
  printf '%-18s %-8s %9s %8s %10s %8s %10s %8s\n' scene a_max "s/frame" "x off" "M samples" "x off" RMSE "PSNR dB"
  for scene in "${SCENES[@]}"; do
    name=$(basename "$scene" .json)
    declare -A times=() rest=()
    for ((round = 0; round < ROUNDS; ++round)); do
      for a in "${THRESHOLDS[@]}"; do
        out=$(figures "$scene" "$a")
        if [[ $out == skipped || -z $out ]]; then echo "$name: skipped (volume missing)"; continue 3; fi
        read -r t m r p x <<< "$out"
        times[$a]="${times[$a]:-} $t"
        rest[$a]="$m $r $p $x"
      done
    done
    base_t="" base_m=""
    for a in "${THRESHOLDS[@]}"; do
      t=$(echo ${times[$a]} | median_of)
      read -r m r p x <<< "${rest[$a]}"
      [[ -z $base_t ]] && base_t=$t base_m=$m
      printf '%-18s %-8s %9.4f %8.2f %10.2f %8.2f %10.3e %8.2f\n' "$name" "$a" "$t" \
        "$(awk -v a="$t" -v b="$base_t" 'BEGIN { print a / b }')" "$m" \
        "$(awk -v a="$m" -v b="$base_m" 'BEGIN { print a / b }')" "$r" "$p"
    done
    unset times rest
  done
  echo "# load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
} 2>&1 | tee "$RESULTS/early_termination.txt"
