#!/usr/bin/env bash
# Fuzzing at length: every fuzz target (fuzz/run_fuzz.sh's list) for
# 10 M executions, one after another, from its seed corpus; a table of
# executions, seconds, exec/s, corpus size and findings into
# bench/results/fuzz/ (fuzz.txt for people, fuzz.csv for tools), and
# run_fuzz.sh's output (a failing run's last log lines too) in run.log. A finding is a crashing input (kept under
# BUILD_DIR/artifacts/NAME/); the table is written either way and the
# script exits non-zero. About 10-40 minutes per target on 2 cores.
#
#   bench/fuzz/run.sh [NAME...]      (default: every target in the tree)
# Environment: PVR_FUZZ_RUNS (default 10000000), PVR_FUZZ_BUILD_DIR.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=$root/bench/results/fuzz
runs=${PVR_FUZZ_RUNS:-10000000}
mkdir -p "$out"

status=0
PVR_FUZZ_RUNS=$runs "$root/fuzz/run_fuzz.sh" 1 "$@" 2>&1 | tee "$out/run.log" || status=$?

# The table, from run_fuzz.sh's line per target:
#   fuzz NAME: executions E, seconds S, exec/s R, corpus A -> B, findings F
{
  echo "# $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, $(clang --version | head -1), commit $(git -C "$root" rev-parse --short HEAD)"
  echo "# libFuzzer with ASan and UBSan, -runs=$runs, -max_len=8192, from fuzz/corpus/NAME/ with fuzz/NAME.dict"
  printf '%-10s %12s %10s %10s %14s %9s\n' target executions seconds exec/s corpus findings
  sed -nE 's/^fuzz ([a-z_]+): executions ([0-9]+), seconds ([0-9.]+), exec\/s ([0-9]+), corpus ([0-9]+) -> ([0-9]+), findings ([0-9]+)$/\1 \2 \3 \4 \5 \6 \7/p' "$out/run.log" |
    while read -r name e s r a b f; do
      printf '%-10s %12s %10s %10s %14s %9s\n' "$name" "$e" "$s" "$r" "$a -> $b" "$f"
    done
} >"$out/fuzz.txt"
{
  echo "target,executions,seconds,exec_per_s,seed_inputs,corpus_inputs,findings"
  sed -nE 's/^fuzz ([a-z_]+): executions ([0-9]+), seconds ([0-9.]+), exec\/s ([0-9]+), corpus ([0-9]+) -> ([0-9]+), findings ([0-9]+)$/\1,\2,\3,\4,\5,\6,\7/p' "$out/run.log"
} >"$out/fuzz.csv"
cat "$out/fuzz.txt"
echo "wrote $out/fuzz.txt, fuzz.csv and run.log"
exit "$status"
