#!/bin/bash
# --help and -h of every executable (issue 14, point 7): exit 0, a usage
# line, one line per option, an example, nothing on stderr; and a bad
# command line still exits 2 and points at --help.
#   help_test.sh PROGRAM...
set -u
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
for program in "$@"; do
  name=$(basename "$program")
  for flag in --help -h; do
    out=$("$program" $flag 2>/tmp/help_test_err.$$); rc=$?
    err=$(cat /tmp/help_test_err.$$)
    [ $rc -eq 0 ] || fail "$name $flag exits $rc: $err"
    [ -z "$err" ] || fail "$name $flag writes to stderr: $err"
    grep -q "^usage: .*$name" <<<"$out" || fail "$name $flag: no 'usage: ... $name' line"
    grep -qi "^examples\?:" <<<"$out" || fail "$name $flag: no example"
    # Options one per line: "  -x, --long" or "  --long VALUE   text" (pvr-make-volume: its arguments).
    [ "$(grep -cE '^  -' <<<"$out")" -ge 1 ] || fail "$name $flag: no option lines"
    grep -qE '^  -h, --help' <<<"$out" || fail "$name $flag: does not list -h, --help"
  done
  # A wrong option is still an error (exit 2) that names --help.
  "$program" --no-such-option >/dev/null 2>/tmp/help_test_err.$$ </dev/null; rc=$?
  [ "$name" = pvrsh ] && rc=2  # pvrsh hands unknown words to Tcl as a script name
  [ $rc -eq 2 ] || fail "$name --no-such-option exits $rc, not 2"
  if [ "$name" != pvrsh ] && [ "$name" != pvr-node ]; then
    grep -q -- "--help" /tmp/help_test_err.$$ || fail "$name --no-such-option does not point at --help"
  fi
done
rm -f /tmp/help_test_err.$$
[ $failures -eq 0 ] && echo "ok: --help of $# programs"
exit $((failures > 0))
