#!/usr/bin/env bash
# bench/lib/median.sh's median_of, as the bench scripts call it: under
# set -euo pipefail, odd and even counts, unsorted input, and no numbers at
# all (run.sh without VTK), which must print nothing and not stop the script.
set -euo pipefail
source "$1/bench/lib/median.sh"
check() {  # input expected
  local got
  got=$(echo "$1" | median_of) || { echo "FAIL: median_of '$1' failed (exit $?)"; exit 1; }
  [ "$got" = "$2" ] || { echo "FAIL: median_of '$1' gave '$got', expected '$2'"; exit 1; }
  echo "ok: median_of '$1' = '$got'"
}
check "3 1 2" 2
check "4 1 3 2" 2.5
check "0.0651 0.0723 0.0731" 0.0723
check "" ""
check "   " ""
