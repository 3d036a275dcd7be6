#!/usr/bin/env bash
# The mini-cluster itself, with plain programs: every host has its own name,
# h0 reaches h1..h3 by ssh without a prompt, Open MPI launches over ssh onto
# the hostfile's hosts, and `down` leaves nothing behind (no namespace, no
# bridge, no process, no directory).
source "$(dirname "$0")/lib.sh"
cluster_up

note "each host has its own name, the root namespace keeps its own"
for h in h0 h1 h2 h3; do
  got=$(on "$h" hostname)
  [ "$got" = "$h" ] || fail "hostname on $h is '$got'"
done
[ "$(hostname)" != h0 ] || fail "the machine's own hostname changed to h0"

note "ssh from h0 to every compute host, by name, without a prompt"
for h in h1 h2 h3; do
  got=$(on h0 ssh -F "$PVR_CLUSTER_DIR/ssh/ssh_config" "$h" hostname </dev/null)
  [ "$got" = "$h" ] || fail "ssh h0 -> $h ran on '$got'"
done

note "mpirun over ssh puts one rank on each host of the hostfile"
got=$(on h0 mpirun --hostfile "$PVR_CLUSTER_DIR/hostfile" -np 3 hostname 2>/dev/null | sort | paste -sd' ')
[ "$got" = "h1 h2 h3" ] || fail "mpirun -np 3 hostname gave '$got'"

note "down removes every namespace, the bridge, every process and the directory"
pids=$(for h in h0 h1 h2 h3; do ip netns pids "pvr-$h"; done | paste -sd' ')
[ -n "$pids" ] || fail "no daemon runs on the hosts before down"
"$CLUSTER" down
left=$(ip netns list | grep '^pvr-h' || true)
[ -z "$left" ] || fail "namespaces left: $left"
! ip link show pvr-br0 >/dev/null 2>&1 || fail "bridge pvr-br0 left"
# A process counts as gone once it is dead (a zombie waits for whoever
# reaps it, which for a daemon is the machine's init, not us).
for pid in $pids; do
  state=$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null || echo gone)
  case "$state" in gone | Z | X) ;; *) fail "process $pid ($(cat "/proc/$pid/comm")) survived down" ;; esac
done
[ ! -e "$PVR_CLUSTER_DIR" ] || fail "$PVR_CLUSTER_DIR left"
note "ok"
