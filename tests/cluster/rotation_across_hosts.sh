#!/usr/bin/env bash
# Through pvrsh and a real pvrd on h0 whose hostfile names h1..h3: a
# session's three ranks run one on each compute host (status `hosts`), its
# rotation's frames arrive in order and equal, within 1/255, the frames of
# the same session with its three ranks on h0 alone, and the ranks talked
# TCP between the hosts' namespaces (the veths' byte counters).
#
# Needs pvrd --advertise and the node's `hosts` status entry (issue 10).
source "$(dirname "$0")/lib.sh"
cluster_up
make_data >/dev/null
dataset=marschner_lobb/marschner_lobb.json
frames=8

note "pvrd on h0, ranks on h1..h3 connecting back to h0's address"
start_pvrd hosts --hostfile "$PVR_CLUSTER_DIR/hostfile" --advertise 10.213.7.10
got=$(pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_hosts" 3 $dataset "$PVR_CLUSTER_DIR/frames.hosts" $frames) ||
  fail "the session on three hosts failed (pvrd log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.hosts.log" | paste -sd' '))"

note "the same session with every rank on h0"
start_pvrd local
ref=$(pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_local" 3 $dataset "$PVR_CLUSTER_DIR/frames.local" $frames) ||
  fail "the session on h0 failed (pvrd log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.local.log" | paste -sd' '))"

in_order=$(seq -s' ' 0 $((frames - 1)))
[ "$(sed -n 's/^order //p' <<<"$got")" = "$in_order" ] || fail "frames on three hosts arrived as: $got"
[ "$(sed -n 's/^order //p' <<<"$ref")" = "$in_order" ] || fail "frames on h0 arrived as: $ref"
[ "$(sed -n 's/^hosts //p' <<<"$got")" = "h1 h2 h3" ] || fail "status hosts on three hosts: $got"
[ "$(sed -n 's/^hosts //p' <<<"$ref")" = "h0 h0 h0" ] || fail "status hosts on h0: $ref"
same_frames "$PVR_CLUSTER_DIR/frames.hosts" "$PVR_CLUSTER_DIR/frames.local" $frames r

# Each frame's pieces composited on two hosts must reach the third: at
# least one byte per pixel of every frame went between compute hosts while
# the rotation ran (and none for the session on h0 alone).
crossed=$(sed -n 's/^bytes //p' <<<"$got")
least=$((frames * 96 * 96))
[ "$crossed" -ge "$least" ] || fail "only $crossed bytes went between the compute hosts for $frames frames of 96x96"
[ "$(sed -n 's/^bytes //p' <<<"$ref")" -lt 1000 ] || fail "the session on h0 alone sent bytes between compute hosts: $ref"
no_job_processes_within 10
note "ok: $crossed bytes between compute hosts"
