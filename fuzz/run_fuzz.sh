#!/usr/bin/env bash
# Builds the protocol fuzzer (decoder, relay, pixel codec) with clang in its
# own build directory and runs it for a bounded time on a copy of the seed
# corpus.
#
# Usage: fuzz/run_fuzz.sh [SECONDS]      (default 60)
# Environment: PVR_FUZZ_BUILD_DIR (default build-fuzz at the repository root).
# Exit status: 0 when the run ended without a crash or sanitizer report,
# non-zero otherwise; a crashing input is kept under BUILD_DIR/artifacts/.
set -euo pipefail

seconds=${1:-60}
if ! [[ $seconds =~ ^[0-9]+$ ]] || [[ $seconds -eq 0 ]]; then
  echo "usage: $0 [SECONDS]  (a positive whole number)" >&2
  exit 2
fi

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PVR_FUZZ_BUILD_DIR:-$root/build-fuzz}

# Standalone configure: only the fuzz directory, so none of the renderer's
# packages are needed and only the fuzz target is built.
CC=clang CXX=clang++ cmake -S "$root/fuzz" -B "$build" >/dev/null
cmake --build "$build" --target pvr_protocol_decoder_fuzz -j2 >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/corpus" "$build/artifacts"
cp "$root"/fuzz/corpus/protocol/* "$work/corpus/"

log=$work/fuzz.log
status=0
"$build/pvr_protocol_decoder_fuzz" \
  -max_total_time="$seconds" -max_len=8192 -timeout=10 -print_final_stats=1 \
  -dict="$root/fuzz/protocol.dict" -artifact_prefix="$build/artifacts/" \
  "$work/corpus" >"$log" 2>&1 || status=$?

# A sanitizer report fails the run even if the process exited 0.
if grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|protocol fuzz:' "$log"; then
  [[ $status -eq 0 ]] && status=1
fi

runs=$(grep -oE 'stat::number_of_executed_units: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+$' || true)
done_line=$(grep -E '^Done [0-9]+ runs in [0-9]+ second' "$log" | tail -1 || true)
if [[ $status -ne 0 ]]; then
  echo "fuzzing FAILED (exit $status); last lines of the log:" >&2
  tail -n 40 "$log" >&2
  ls "$build/artifacts" >&2 || true
fi
echo "executions: ${runs:-unknown}; ${done_line:-no final line}; corpus grew to $(ls "$work/corpus" | wc -l) inputs"
exit "$status"
