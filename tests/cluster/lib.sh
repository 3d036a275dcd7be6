# shellcheck shell=bash
# Shared by the mini-cluster tests (sourced): brings the cluster up for the
# test and down at its exit whatever happens, starts pvrd and pvrsh on h0,
# and the checks the tests share. Programs come from the environment that
# tests/cluster/CMakeLists.txt sets (PVRD, PVR_NODE, PVRSH, PVR_MAKE_VOLUME,
# TCLLIBPATH); run by hand, the build tree next to the sources is used.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build=${PVR_BUILD:-$here/../../build}
PVRD=${PVRD:-$build/pvrd/pvrd}
PVR_NODE=${PVR_NODE:-$build/pvrd/pvr-node}
PVRSH=${PVRSH:-$build/pvrsh/pvrsh}
PVR_MAKE_VOLUME=${PVR_MAKE_VOLUME:-$build/tools/pvr-make-volume}
export TCLLIBPATH=${TCLLIBPATH:-$build/lib}
CLUSTER=$here/cluster.sh
export PVR_CLUSTER_SH=$CLUSTER  # rotation.tcl counts bytes with it
readonly SKIP=77

fail() { echo "FAIL: $*" >&2; exit 1; }
note() { echo "-- $*" >&2; }

# cluster_up: a fresh PVR_CLUSTER_DIR, the cluster up, down at exit (also
# on SIGINT and SIGTERM, which would skip the EXIT trap). A machine that
# cannot host it skips the test (exit 77, cluster.sh says why). A cluster
# that was up before (cluster.sh refuses a second) is left alone.
cluster_ours=0
cluster_up() {
  local p
  for p in "$PVRD" "$PVR_NODE" "$PVRSH" "$PVR_MAKE_VOLUME"; do
    [ -x "$p" ] || fail "$p is not built"
  done
  command -v idiff >/dev/null || fail "idiff (package openimageio-tools) compares the frames; it is not installed"
  PVR_CLUSTER_DIR=$(mktemp -d "${TMPDIR:-/tmp}/pvr-cluster.XXXXXX")
  export PVR_CLUSTER_DIR
  trap cluster_down EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
  local status=0
  "$CLUSTER" up || status=$?
  [ $status -eq 0 ] || exit $status
  cluster_ours=1
}

cluster_down() {
  local status=$?
  stop_pvrds
  [ $cluster_ours -eq 0 ] || "$CLUSTER" down || true
  # cluster.sh down removed the directory; if `up` never made it, we do.
  [ -n "${PVR_CLUSTER_DIR:-}" ] && rm -rf "$PVR_CLUSTER_DIR"
  exit $status
}

on() { "$CLUSTER" exec "$@"; }

# wait_until SECONDS WHAT CMD...: retries CMD until it succeeds; fails with
# WHAT after SECONDS.
wait_until() {
  local seconds=$1 what=$2 i
  shift 2
  for ((i = 0; i < seconds * 5; i++)); do
    "$@" && return 0
    sleep 0.2
  done
  fail "$what (waited ${seconds}s)"
}

# needs_slurm: skips the test with cluster.sh's reason when Slurm is not up.
needs_slurm() {
  if [ -f "$PVR_CLUSTER_DIR/slurm.unavailable" ]; then
    echo "SKIP: Slurm does not run in this mini-cluster: $(cat "$PVR_CLUSTER_DIR/slurm.unavailable")" >&2
    exit $SKIP
  fi
}

# make_data: a small float volume in $PVR_CLUSTER_DIR/data (every host sees
# the same path); prints the directory.
make_data() {
  "$PVR_MAKE_VOLUME" marschner-lobb 41 "$PVR_CLUSTER_DIR/data" >/dev/null
  echo "$PVR_CLUSTER_DIR/data"
}

compute_bytes() { "$CLUSTER" compute-bytes; }

# job_processes: "host pid command" of every job process (mpirun, Open MPI's
# daemon, pvr-node, srun, salloc, slurmstepd) left on any host.
job_processes() {
  local h pid comm
  for h in h0 h1 h2 h3; do
    for pid in $(ip netns pids "pvr-$h" 2>/dev/null); do
      comm=$(cat "/proc/$pid/comm" 2>/dev/null) || continue
      case "$comm" in
        mpirun | orterun | orted | pvr-node | srun | salloc | slurmstepd) echo "$h $pid $comm" ;;
      esac
    done
  done
}

# no_job_processes_within SECONDS: waits for every job process to go; fails
# naming those left. (Teardown takes a moment: mpirun hears of a lost
# daemon, the daemons kill their ranks.)
no_job_processes_within() {
  local i left
  for ((i = 0; i < $1 * 5; i++)); do
    left=$(job_processes)
    [ -z "$left" ] && return 0
    sleep 0.2
  done
  fail "job processes left after $1 s: $(echo "$left" | paste -sd';')"
}

# start_pvrd NAME ARGS...: pvrd on h0 listening on 127.0.0.1:0 of h0 with
# the data in $PVRD_DATA (default: the cluster's, make_data); sets
# PORT_<NAME>. Its log: $PVR_CLUSTER_DIR/pvrd.NAME.log.
pvrd_pids=()
start_pvrd() {
  local name=$1
  shift
  local out=$PVR_CLUSTER_DIR/pvrd.$name.out log=$PVR_CLUSTER_DIR/pvrd.$name.log
  : >"$out"
  "$CLUSTER" exec h0 "$PVRD" --listen 127.0.0.1:0 --data-dir "${PVRD_DATA:-$PVR_CLUSTER_DIR/data}" --node "$PVR_NODE" --max-ranks 4 "$@" \
    >"$out" 2>"$log" &
  pvrd_pids+=($!)
  local i port=""
  for ((i = 0; i < 50; i++)); do
    port=$(sed -n 's/^pvrd listening on .*:\([0-9][0-9]*\)$/\1/p' "$out")
    [ -n "$port" ] && break
    kill -0 "$!" 2>/dev/null || fail "pvrd $* did not start: $(cat "$log")"
    sleep 0.1
  done
  [ -n "$port" ] || fail "pvrd $* printed no port in 5 s: $(cat "$log")"
  printf -v "PORT_$name" %s "$port"
}

stop_pvrds() {
  local pid
  for pid in "${pvrd_pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pvrd_pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  pvrd_pids=()
}

# pvrsh_on_h0 SCRIPT ARGS...: runs the Tcl file SCRIPT with pvrsh -nogui on
# h0; its stderr goes to $PVR_CLUSTER_DIR/pvrsh.err (and to ours).
pvrsh_on_h0() {
  on h0 "$PVRSH" -nogui "$@" 2> >(tee -a "$PVR_CLUSTER_DIR/pvrsh.err" >&2)
}

# same_frames DIR_A DIR_B COUNT PREFIX: frames PREFIX_00000.png ... of both
# directories agree within 1/255 in every channel (idiff, values in [0,1]).
same_frames() {
  local k a b
  for ((k = 0; k < $3; k++)); do
    a=$(printf '%s/%s_%05d.png' "$1" "$4" "$k")
    b=$(printf '%s/%s_%05d.png' "$2" "$4" "$k")
    [ -f "$a" ] && [ -f "$b" ] || fail "frame $k missing: $a or $b"
    idiff -q -fail 0.004 -warn 0.004 "$a" "$b" >/dev/null || fail "frame $k differs by more than 1/255: $(idiff "$a" "$b" | tail -n 3 | paste -sd' ')"
  done
}
