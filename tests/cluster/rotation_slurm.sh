#!/usr/bin/env bash
# Through pvrsh and pvrd --launcher slurm on h0: a session whose nodes are
# all held by another job waits in the queue and its client says so (with
# the Slurm job id; the job carries the session's account); once the nodes
# are free its three ranks run on h1..h3 and its rotation equals the one on
# h0 alone, in order; the allocation is released when the session ends and
# when its client vanishes, and no job process is left on any host.
#
# Needs pvrd --launcher slurm, --advertise, queue progress in pvrsh's open
# (`-account`) and the node's `hosts` status entry (issue 10).
source "$(dirname "$0")/lib.sh"
cluster_up
needs_slurm
make_data >/dev/null
dataset=marschner_lobb/marschner_lobb.json
frames=8
start_pvrd slurm --launcher slurm --advertise 10.213.7.10
start_pvrd local

queue_empty() { [ -z "$(on h0 squeue -h -o %i)" ]; }

note "every node held by another job: the session queues and its client says so"
blocker=$(on h0 salloc -N 3 --no-shell -J blocker 2>&1 | sed -n 's/.*Granted job allocation \([0-9]*\).*/\1/p')
[ -n "$blocker" ] || fail "salloc -N 3 --no-shell did not allocate the nodes"
: >"$PVR_CLUSTER_DIR/pvrsh.err"
pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_slurm" 3 $dataset "$PVR_CLUSTER_DIR/frames.slurm" $frames \
  -account pvrtest >"$PVR_CLUSTER_DIR/slurm.out" &
client=$!
wait_until 30 "pvrsh printed no 'pvr: queued: slurm job' line: $(cat "$PVR_CLUSTER_DIR/pvrsh.err")" \
  grep -q '^pvr: queued: slurm job [0-9]' "$PVR_CLUSTER_DIR/pvrsh.err"
job=$(sed -n 's/^pvr: queued: slurm job \([0-9]*\).*/\1/p' "$PVR_CLUSTER_DIR/pvrsh.err" | head -n 1)
state=$(on h0 squeue -h -j "$job" -o '%T %a %j')
[[ "$state" == "PENDING pvrtest pvr-"* ]] || fail "slurm job $job of the session: '$state', not pending under account pvrtest"
on h0 scancel "$blocker"
wait $client || fail "the session through Slurm failed: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrsh.err" | paste -sd' ') (pvrd log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.slurm.log" | paste -sd' '))"
got=$(cat "$PVR_CLUSTER_DIR/slurm.out")

note "the same session with every rank on h0"
pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_local" 3 $dataset "$PVR_CLUSTER_DIR/frames.local" $frames >/dev/null ||
  fail "the session on h0 failed"
[ "$(sed -n 's/^order //p' <<<"$got")" = "$(seq -s' ' 0 $((frames - 1)))" ] || fail "frames through Slurm arrived as: $got"
[ "$(sed -n 's/^hosts //p' <<<"$got" | tr ' ' '\n' | sort | paste -sd' ')" = "h1 h2 h3" ] ||
  fail "status hosts through Slurm: $got"
same_frames "$PVR_CLUSTER_DIR/frames.slurm" "$PVR_CLUSTER_DIR/frames.local" $frames r

note "the allocation is released when the session ends"
wait_until 10 "jobs left in the queue after the session: $(on h0 squeue -h -o '%i %T %j')" queue_empty
no_job_processes_within 10

note "a client that vanishes mid-rotation: its allocation is released"
marker=$PVR_CLUSTER_DIR/third-frame
pvrsh_on_h0 "$here/lost.tcl" "127.0.0.1:$PORT_slurm" 3 $dataset "$marker" >/dev/null &
client=$!
wait_until 30 "no third frame through Slurm" test -e "$marker"
[ -n "$(on h0 squeue -h -o %i)" ] || fail "no Slurm job while the session renders"
for pid in $(ip netns pids pvr-h0); do
  [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = pvrsh ] && kill -KILL "$pid"
done
wait $client 2>/dev/null || true
wait_until 10 "jobs left in the queue after the client vanished: $(on h0 squeue -h -o '%i %T %j')" queue_empty
no_job_processes_within 10
note "ok"
