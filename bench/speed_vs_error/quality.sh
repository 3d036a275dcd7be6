#!/usr/bin/env bash
# Quality chosen by error (sampling.target_psnr) against uniform steps.
#
# Builds speed_vs_error (Release, assertions off) in build-bench/, writes the
# peer benchmark's volume to build/bench-data/, and runs speed_vs_error
# --quality on every scene: the uniform steps 2..1/16 voxel (plain,
# skipping on) and, per target, the achieved PSNR, time and samples beside
# a uniform step of the same error interpolated from them. Writes
# bench/results/quality.txt and quality.csv, with the load average.
#
# Knobs: BENCH_BUILD (build dir, default build-bench), BENCH_TARGETS
# (40,50,60), BENCH_ARGS (extra speed_vs_error options or scene files).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/prepare.sh"

{
  echo "# quality chosen by error, $(date -u '+%Y-%m-%d %H:%M UTC'), $(git -C "$PVR_ROOT" rev-parse --short HEAD 2>/dev/null || echo 'no git')"
  echo "# load average at start: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores shared with other sessions: times are noisy, samples are not"
  # shellcheck disable=SC2086  # BENCH_ARGS is a list of options
  "$SVE" --threads 2 --frames 3 --case-seconds 2 --steps 2,1,0.5,0.25,0.125,0.0625 \
    --quality "${BENCH_TARGETS:-40,50,60}" --csv "$RESULTS/quality.csv" ${BENCH_ARGS:-}
  echo "# load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
} 2>&1 | tee "$RESULTS/quality.txt"
