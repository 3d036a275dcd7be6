#!/usr/bin/env bash
# pvr-node's batch mode with its three ranks on three hosts renders the same
# float image as with the three ranks on one host (within 1e-5 in every
# channel), and the compositing went over TCP between the hosts' namespaces.
source "$(dirname "$0")/lib.sh"
cluster_up
data=$(make_data)
scene=$PVR_CLUSTER_DIR/scene.json
cat >"$scene" <<EOF
{"volume": {"file": "$data/marschner_lobb/marschner_lobb.json"},
 "transfer_function": {"points": [[0,0,0,0,0],[0.3,0.2,0.4,1,0.05],[0.6,1,0.8,0.2,0.3],[1,1,1,1,0.8]]},
 "image": {"width": 128, "height": 128, "background": [0,0,0,1]}}
EOF

note "three ranks on h1, h2, h3 (ranks reach each other only over the veths)"
before=$(compute_bytes)
on h0 mpirun --hostfile "$PVR_CLUSTER_DIR/hostfile" -np 3 "$PVR_NODE" --batch "$scene" -o "$PVR_CLUSTER_DIR/hosts3.exr" \
  >"$PVR_CLUSTER_DIR/hosts3.txt" 2>&1 || fail "pvr-node on three hosts: $(cat "$PVR_CLUSTER_DIR/hosts3.txt")"
crossed=$(($(compute_bytes) - before))

note "three ranks on h1 alone"
on h1 mpirun -np 3 "$PVR_NODE" --batch "$scene" -o "$PVR_CLUSTER_DIR/host1.exr" \
  >"$PVR_CLUSTER_DIR/host1.txt" 2>&1 || fail "pvr-node on one host: $(cat "$PVR_CLUSTER_DIR/host1.txt")"

idiff -fail 1e-5 -warn 1e-5 "$PVR_CLUSTER_DIR/hosts3.exr" "$PVR_CLUSTER_DIR/host1.exr" >"$PVR_CLUSTER_DIR/idiff.txt" ||
  fail "three hosts and one host differ by more than 1e-5: $(cat "$PVR_CLUSTER_DIR/idiff.txt")"

# The compositing messages alone carry this many bytes (pvr-node's report:
# "compositing: ... N MB sent"); every one of them went between two hosts.
sent=$(sed -n 's/^compositing:.*, \([0-9.]*\) MB sent.*/\1/p' "$PVR_CLUSTER_DIR/hosts3.txt")
[ -n "$sent" ] || fail "pvr-node printed no compositing line: $(cat "$PVR_CLUSTER_DIR/hosts3.txt")"
want=$(awk -v mb="$sent" 'BEGIN { printf "%d", mb * 1e6 }')
[ "$crossed" -ge "$want" ] || fail "only $crossed bytes went between the compute hosts; compositing alone sent $want"
note "ok: $crossed bytes between compute hosts (compositing sent $want)"
