#!/usr/bin/env bash
# The dependency rules of ARCHITECTURE.md, checked by grep over the sources:
#   MPI only in the MPI communicator and the runtime (the MPI program);
#   Tcl/Tk only in pvrsh/; sockets only where a process talks TCP (protocol
#   I/O helpers, pvrd, pvrsh, the runtime master's link to its handler, tests).
set -u
root=${1:-$(dirname "$0")/..}
cd "$root" || exit 2
status=0

offenders() {  # pattern, allowed-path regex
  grep -rlE "$1" --include=*.cpp --include=*.h --include=*.hpp \
      renderer protocol pvrd pvrsh tools bench 2>/dev/null | grep -vE "$2" || true
}

check() {  # what, pattern, allowed
  local bad
  bad=$(offenders "$2" "$3")
  if [ -n "$bad" ]; then
    echo "FAIL: $1 outside its place:"; echo "$bad" | sed 's/^/  /'
    status=1
  else
    echo "ok: $1"
  fi
}

check "MPI" '#include *<mpi\.h>' '^renderer/(runtime/|composite/mpi_communicator)'
check "Tcl/Tk" '#include *<(tcl|tk)\.h>' '^pvrsh/'
check "sockets" '#include *<(sys/socket|netinet/in|arpa/inet)\.h>' '^(protocol/|pvrd/|pvrsh/|renderer/runtime/)'
check "the protocol codec's purity (no MPI, Tcl or sockets)" \
  '#include *<(mpi|tcl|tk|sys/socket|netinet/in)\.h>' '^(renderer/|pvrd/|pvrsh/|tools/|bench/)'
exit $status
