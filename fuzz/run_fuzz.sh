#!/usr/bin/env bash
# Builds the fuzz targets with clang in their own build directory and runs
# each, one after another, for a bounded time (or a number of executions)
# on a copy of its seed corpus, fuzz/corpus/NAME/, with fuzz/NAME.dict when
# there is one.
#
# Usage: fuzz/run_fuzz.sh [SECONDS] [NAME...]   (default 60 seconds per target, every target)
# Environment:
#   PVR_FUZZ_BUILD_DIR  build directory (default build-fuzz at the repository root)
#   PVR_FUZZ_RUNS       run each target for exactly this many executions
#                       instead of SECONDS (bench/fuzz/run.sh: 10000000)
#   PVR_FUZZ_MAX_LEN    the longest input in bytes (default 8192); a shorter
#                       one makes a long run faster where large inputs cost
#                       more than they find (the pvrsh target's 10 M run)
# Prints one line per target:
#   fuzz NAME: executions E, seconds S, exec/s R, corpus A -> B, findings F
# Exit status: 0 when every run ended without a crash or sanitizer report,
# non-zero otherwise; a crashing input is kept under BUILD_DIR/artifacts/NAME/.
set -euo pipefail

# The targets: name, executable, source. A target whose source is not in
# the tree yet is skipped, so adding one is one line here (and its block in
# fuzz/CMakeLists.txt).
targets=(
  "protocol pvr_protocol_decoder_fuzz protocol_decoder_fuzz.cpp"
  "scene pvr_scene_parser_fuzz scene_parser_fuzz.cpp"
  "pvrsh pvr_pvrsh_messages_fuzz pvrsh_messages_fuzz.cpp"
)

seconds=${1:-60}
if ! [[ $seconds =~ ^[0-9]+$ ]] || [[ $seconds -eq 0 ]]; then
  echo "usage: $0 [SECONDS] [NAME...]  (SECONDS a positive whole number)" >&2
  exit 2
fi
shift $(( $# > 0 ? 1 : 0 ))
runs=${PVR_FUZZ_RUNS:-}
if [[ -n $runs ]] && ! [[ $runs =~ ^[0-9]+$ && $runs -gt 0 ]]; then
  echo "$0: PVR_FUZZ_RUNS must be a positive whole number, got '$runs'" >&2
  exit 2
fi
max_len=${PVR_FUZZ_MAX_LEN:-8192}
if ! [[ $max_len =~ ^[0-9]+$ && $max_len -gt 0 ]]; then
  echo "$0: PVR_FUZZ_MAX_LEN must be a positive whole number, got '$max_len'" >&2
  exit 2
fi

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PVR_FUZZ_BUILD_DIR:-$root/build-fuzz}

# The targets asked for (all by default) whose source exists.
selected=()
for entry in "${targets[@]}"; do
  read -r name exe source <<<"$entry"
  if [[ $# -gt 0 ]] && ! printf '%s\n' "$@" | grep -qx "$name"; then continue; fi
  if [[ ! -f $root/fuzz/$source ]]; then
    echo "fuzz $name: skipped (fuzz/$source is not in this tree)" >&2
    continue
  fi
  selected+=("$entry")
done
for want in "$@"; do
  printf '%s\n' "${targets[@]}" | grep -q "^$want " || { echo "$0: no fuzz target '$want'" >&2; exit 2; }
done
[[ ${#selected[@]} -gt 0 ]] || { echo "$0: no fuzz target to run" >&2; exit 2; }

# Standalone configure: only the fuzz directory, so none of the renderer's
# other packages are needed and only the fuzz targets are built.
executables=()
for entry in "${selected[@]}"; do read -r _ exe _ <<<"$entry"; executables+=("$exe"); done
CC=clang CXX=clang++ cmake -S "$root/fuzz" -B "$build" >/dev/null
cmake --build "$build" --target "${executables[@]}" -j2 >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
overall=0

# run_one NAME EXE: one bounded run and its line; returns its status.
run_one() {
  local name=$1 exe=$2
  local corpus=$work/$name/corpus log=$work/$name/fuzz.log artifacts=$build/artifacts/$name
  mkdir -p "$corpus" "$artifacts"
  if compgen -G "$root/fuzz/corpus/$name/*" >/dev/null; then cp "$root/fuzz/corpus/$name/"* "$corpus/"; fi
  local seeds before_artifacts
  seeds=$(ls "$corpus" | wc -l)
  before_artifacts=$(ls "$artifacts" | wc -l)

  local args=(-max_len="$max_len" -timeout=10 -print_final_stats=1 -artifact_prefix="$artifacts/")
  [[ -f $root/fuzz/$name.dict ]] && args+=(-dict="$root/fuzz/$name.dict")
  if [[ -n $runs ]]; then args+=(-runs="$runs"); else args+=(-max_total_time="$seconds"); fi

  local status=0 start end
  start=$(date +%s.%N)
  "$build/$exe" "${args[@]}" "$corpus" >"$log" 2>&1 || status=$?
  end=$(date +%s.%N)

  # A sanitizer report fails the run even if the process exited 0.
  if grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|^[a-z_]+ fuzz: ' "$log"; then
    [[ $status -eq 0 ]] && status=1
  fi

  local executions findings elapsed rate
  executions=$(grep -oE 'stat::number_of_executed_units: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$' || echo 0)
  findings=$(( $(ls "$artifacts" | wc -l) - before_artifacts ))
  [[ $status -ne 0 && $findings -eq 0 ]] && findings=1
  elapsed=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
  rate=$(awk -v n="$executions" -v s="$elapsed" 'BEGIN { printf "%.0f", (s > 0 ? n / s : 0) }')
  if [[ $status -ne 0 ]]; then
    echo "fuzz $name FAILED (exit $status); last lines of the log:" >&2
    tail -n 40 "$log" >&2
    ls "$artifacts" >&2 || true
  fi
  echo "fuzz $name: executions $executions, seconds $elapsed, exec/s $rate, corpus $seeds -> $(ls "$corpus" | wc -l), findings $findings"
  return "$status"
}

for entry in "${selected[@]}"; do
  read -r name exe _ <<<"$entry"
  run_one "$name" "$exe" || overall=$?
done
exit "$overall"
