#!/usr/bin/env bash
# Through pvrsh and a real pvrd on h0 whose hostfile names h1..h3 (one slot
# each): a session's two or three ranks run one on each compute host
# (status `hosts`), its rotation's frames arrive in order and equal, within
# 1/255 (the frames are 8-bit on the wire), the frames of the same session
# with its ranks on h0 alone, and the ranks talked TCP between the hosts'
# namespaces while the rotation ran (the veths' byte counters).
#
# Needs pvrd --advertise and the node's `hosts` status entry (issue 10).
source "$(dirname "$0")/lib.sh"
cluster_up
make_data >/dev/null
dataset=marschner_lobb/marschner_lobb.json
frames=8
in_order=$(seq -s' ' 0 $((frames - 1)))
start_pvrd hosts --hostfile "$PVR_CLUSTER_DIR/hostfile" --advertise 10.213.7.10
start_pvrd local

# field NAME TEXT: the rest of TEXT's line that starts with NAME.
field() { sed -n "s/^$1 //p" <<<"$2"; }

for ranks in 2 3; do
  note "$ranks ranks on h1.., connecting back to h0's address"
  got=$(pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_hosts" $ranks $dataset "$PVR_CLUSTER_DIR/hosts.$ranks" $frames) ||
    fail "the session on $ranks hosts failed (pvrd log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.hosts.log" | paste -sd' '))"
  note "the same session with its $ranks ranks on h0"
  ref=$(pvrsh_on_h0 "$here/rotation.tcl" "127.0.0.1:$PORT_local" $ranks $dataset "$PVR_CLUSTER_DIR/local.$ranks" $frames) ||
    fail "the session on h0 failed (pvrd log: $(tail -n 5 "$PVR_CLUSTER_DIR/pvrd.local.log" | paste -sd' '))"

  [ "$(field order "$got")" = "$in_order" ] || fail "frames on $ranks hosts arrived as: $got"
  [ "$(field order "$ref")" = "$in_order" ] || fail "frames on h0 arrived as: $ref"
  [ "$(field hosts "$got")" = "$(seq -f 'h%g' -s' ' 1 $ranks)" ] || fail "status hosts on $ranks hosts: $got"
  [ "$(field hosts "$ref")" = "$(printf 'h0\n%.0s' $(seq $ranks) | paste -sd' ')" ] || fail "status hosts on h0: $ref"
  same_frames "$PVR_CLUSTER_DIR/hosts.$ranks" "$PVR_CLUSTER_DIR/local.$ranks" $frames r

  # Each frame's pieces composited on different hosts must meet: at least
  # one byte per pixel of every frame went between compute hosts while the
  # rotation ran, and (next to) none for the session on h0 alone.
  crossed=$(field bytes "$got")
  [ "$crossed" -ge $((frames * 96 * 96)) ] ||
    fail "only $crossed bytes went between the compute hosts for $frames frames of 96x96 on $ranks hosts"
  [ "$(field bytes "$ref")" -lt 1000 ] || fail "the session on h0 alone sent bytes between compute hosts: $ref"
  note "ok: $crossed bytes between compute hosts"
done
no_job_processes_within 10
