#!/usr/bin/env bash
# The dependency rules of ../shared/ARCHITECTURE.md, checked over the sources
# (ctest: "architecture: dependency rules hold"):
#   - mpi.h in exactly one file, renderer/comm/mpi_communicator.cpp;
#   - Tcl/Tk only in pvrsh/;
#   - sockets only where a process talks TCP: pvrd/, pvrsh/, the node's
#     bridge to pvrd (node/pvrd_link*), and the scaling and liveness
#     benches, which play the session handler;
#   - renderer/ includes nothing of protocol/, node/, pvrd/ or pvrsh/, and
#     protocol/ nothing of the others;
#   - pvrsh/ and pvrd/ include nothing of renderer/ or node/;
#   - OpenImageIO only in renderer/image_io.cpp: pvr-node loads the image
#     writer module instead of carrying its libraries on every rank.
set -u
root=${1:-$(dirname "$0")/..}
cd "$root" || exit 2
status=0
sources="renderer protocol node pvrd pvrsh tools bench fuzz"

offenders() {  # pattern, allowed-path regex, dirs
  grep -rlE "$1" --include=*.cpp --include=*.h --include=*.hpp $3 2>/dev/null | grep -vE "$2" || true
}

check() {  # what, pattern, allowed, dirs
  local bad
  bad=$(offenders "$2" "$3" "${4:-$sources}")
  if [ -n "$bad" ]; then
    echo "FAIL: $1:"; echo "$bad" | sed 's/^/  /'
    status=1
  else
    echo "ok: $1"
  fi
}

# Headers of a folder, by name, for the include checks below.
headers_of() { (cd "$1" && find . -name '*.h' | sed 's|^\./||' | sort -u | sed 's/\./\\./g' | paste -sd'|'); }

check "mpi.h only in renderer/comm/mpi_communicator.cpp" '#include *<mpi\.h>' '^renderer/comm/mpi_communicator\.cpp$'
check "Tcl/Tk only in pvrsh/" '#include *<(tcl|tk)\.h>' '^pvrsh/'
check "sockets only in pvrd/, pvrsh/, the node's link to pvrd and the scaling and liveness benches" \
  '#include *<(sys/socket|netinet/in|netinet/tcp|arpa/inet|netdb)\.h>' '^(pvrd/|pvrsh/|node/pvrd_link|bench/scaling/|bench/liveness/)'
check "renderer/ includes nothing of protocol/ or node/" \
  "#include *\"($(headers_of protocol)|$(headers_of node))\"" '^$' renderer
check "protocol/ includes nothing of renderer/ or node/" \
  "#include *\"($(headers_of renderer | sed 's/|comm[^|]*//g')|$(headers_of node))\"" '^$' protocol
check "pvrd/ and pvrsh/ include nothing of renderer/ or node/" \
  "#include *\"($(headers_of node)|raycast/[^\"]*|scene\\.h|brick\\.h|communicator\\.h|strategy\\.h)\"" '^$' "pvrd pvrsh"
check "OpenImageIO only in renderer/image_io.cpp" '#include *<OpenImageIO/' '^renderer/image_io\.cpp$'
check "node/ includes no image file code (node/image_output.h loads it)" '#include *"image_io\.h"' '^$' node
# ctest splits a discovered Catch2 name at ';' and then runs no test at all,
# which passes: a name with ';' is a test that can never fail.
bad=$(grep -rnE 'TEST_CASE(_METHOD)?\(([A-Za-z_:]+, *)?"[^"]*;' tests 2>/dev/null || true)
if [ -n "$bad" ]; then
  echo "FAIL: Catch2 test names with ';' (ctest runs nothing for them):"; echo "$bad" | sed 's/^/  /'
  status=1
else
  echo "ok: no Catch2 test name holds ';'"
fi
exit $status
