#!/usr/bin/env bash
# A host lost in the middle of a rotation (every process in h2's namespace
# killed with SIGKILL, as a power cut would): the client's wait raises a
# RANK_FAILED error naming h2 within 10 s, no job process is left on any
# host, and pvrd, still running, serves the next session on all three hosts
# once h2 is back.
#
# pvrd runs without --advertise: its default, the local address of the
# route towards the hostfile's first host (h1), is h0's 10.213.7.10.
# Needs that default and the node's `hosts` status entry (issue 10).
source "$(dirname "$0")/lib.sh"
cluster_up
make_data >/dev/null
dataset=marschner_lobb/marschner_lobb.json
start_pvrd hosts --hostfile "$PVR_CLUSTER_DIR/hostfile"
pvrd_pid=${pvrd_pids[0]}

note "a long rotation on h1..h3; h2 dies after its third frame"
marker=$PVR_CLUSTER_DIR/third-frame
pvrsh_on_h0 "$here/lost.tcl" "127.0.0.1:$PORT_hosts" 3 $dataset "$marker" >"$PVR_CLUSTER_DIR/lost.out" &
client=$!
third_frame() {
  kill -0 $client 2>/dev/null || fail "the session ended before its third frame: $(cat "$PVR_CLUSTER_DIR/lost.out")"
  [ -e "$marker" ]
}
wait_until 30 "no third frame" third_frame
# One listing, read twice: a pipe into grep could end the listing early.
procs=$(job_processes)
grep -q '^h2 [0-9]* pvr-node$' <<<"$procs" || fail "no rank runs on h2: $(paste -sd';' <<<"$procs")"
killed_at=$(date +%s%3N)
ip netns pids pvr-h2 | xargs -r kill -KILL
wait $client || fail "the rotation did not fail: $(cat "$PVR_CLUSTER_DIR/lost.out")"

out=$(cat "$PVR_CLUSTER_DIR/lost.out")
error_at=$(sed -n 's/^error_at //p' <<<"$out")
code=$(sed -n 's/^errorcode //p' <<<"$out")
note "client error after $((error_at - killed_at)) ms: $code: $(sed -n '/^message /,$p' <<<"$out" | cut -c1-200)"
[ "$code" = "PVR REMOTE RANK_FAILED" ] || fail "the client got '$code', not PVR REMOTE RANK_FAILED: $out"
[ $((error_at - killed_at)) -le 10000 ] || fail "the error came $((error_at - killed_at)) ms after the host died (limit 10 s)"
sed -n '/^message /,$p' <<<"$out" | grep -qw h2 || fail "the error does not name the lost host h2: $out"

note "no job process on any host; pvrd still runs"
no_job_processes_within 10
kill -0 "$pvrd_pid" || fail "pvrd is gone (log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.hosts.log" | paste -sd' '))"

note "h2 comes back; the next session runs on h1..h3"
"$CLUSTER" boot h2
got=$(pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_hosts" 3 $dataset "$PVR_CLUSTER_DIR/frames.after" 2) ||
  fail "the session after the loss failed (pvrd log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.hosts.log" | paste -sd' '))"
[ "$(sed -n 's/^hosts //p' <<<"$got")" = "h1 h2 h3" ] || fail "status hosts after the loss: $got"
no_job_processes_within 10
note "ok"
