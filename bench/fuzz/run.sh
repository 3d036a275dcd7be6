#!/usr/bin/env bash
# Fuzzing at length: every fuzz target (fuzz/run_fuzz.sh's list) for
# 10 M executions, one after another, from its seed corpus; a table of
# executions, seconds, exec/s, corpus size and findings into
# bench/results/fuzz/: fuzz.csv (one row per target, with the date and
# commit of its run; a run replaces the rows of the targets it ran and keeps
# the others), fuzz.txt (the same for people) and run.log (run_fuzz.sh's
# output, a failing run's last log lines too, appended). A finding is a
# crashing input, kept under BUILD_DIR/artifacts/NAME/; the table is written
# either way and the script exits non-zero. 10-30 minutes per target on 2 cores.
#
#   bench/fuzz/run.sh [NAME...]      (default: every target in the tree)
# Environment: PVR_FUZZ_RUNS (default 10000000), PVR_FUZZ_MAX_LEN (default
# 8192, recorded per row), PVR_FUZZ_BUILD_DIR.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=$root/bench/results/fuzz
runs=${PVR_FUZZ_RUNS:-10000000}
max_len=${PVR_FUZZ_MAX_LEN:-8192}
mkdir -p "$out"
csv=$out/fuzz.csv
header="date,commit,target,executions,seconds,exec_per_s,seed_inputs,corpus_inputs,findings,max_len"

lines=$(mktemp)
trap 'rm -f "$lines"' EXIT
status=0
echo "# $(date -u +%Y-%m-%dT%H:%MZ) bench/fuzz/run.sh $*: -runs=$runs -max_len=$max_len" >"$lines"
PVR_FUZZ_RUNS=$runs PVR_FUZZ_MAX_LEN=$max_len "$root/fuzz/run_fuzz.sh" 1 "$@" >>"$lines" 2>&1 || status=$?
cat "$lines"
cat "$lines" >>"$out/run.log"

# New rows from run_fuzz.sh's line per target:
#   fuzz NAME: executions E, seconds S, exec/s R, corpus A -> B, findings F
stamp="$(date -u +%Y-%m-%dT%H:%MZ),$(git -C "$root" rev-parse --short HEAD)"
new=$(sed -nE "s/^fuzz ([a-z_]+): executions ([0-9]+), seconds ([0-9.]+), exec\/s ([0-9]+), corpus ([0-9]+) -> ([0-9]+), findings ([0-9]+)$/$stamp,\1,\2,\3,\4,\5,\6,\7,$max_len/p" "$lines")
ran=$(printf '%s\n' "$new" | cut -d, -f3)
{
  echo "$header"
  if [[ -f $csv ]]; then
    tail -n +2 "$csv" | while IFS= read -r row; do
      # Rows from before the max_len column ran with the default.
      [[ $(tr -cd , <<<"$row" | wc -c) -eq 8 ]] && row="$row,8192"
      printf '%s\n' "$ran" | grep -qx "$(cut -d, -f3 <<<"$row")" || printf '%s\n' "$row"
    done
  fi
  [[ -n $new ]] && printf '%s\n' "$new"
} >"$csv.new"
mv "$csv.new" "$csv"

{
  echo "# fuzz targets, $(nproc) cores shared with other builds, $(clang --version | head -1)"
  echo "# libFuzzer with ASan and UBSan, -runs=$runs, -max_len per row, from fuzz/corpus/NAME/ with fuzz/NAME.dict"
  echo "# corpus: seed inputs -> inputs after the run; findings: crashing inputs (0 = none)"
  printf '%-10s %12s %10s %10s %14s %9s %8s  %s\n' target executions seconds exec/s corpus findings max_len "run (UTC, commit)"
  tail -n +2 "$csv" | while IFS=, read -r date commit name e s r a b f m; do
    printf '%-10s %12s %10s %10s %14s %9s %8s  %s\n' "$name" "$e" "$s" "$r" "$a -> $b" "$f" "$m" "$date $commit"
  done
} >"$out/fuzz.txt"
cat "$out/fuzz.txt"
echo "wrote $out/fuzz.txt, fuzz.csv and run.log"
exit "$status"
