#!/usr/bin/env bash
# A mini-cluster of four "hosts" on this machine, for the multi-host tests
# and benches (docs/cluster.md tells how it maps onto a real cluster):
#
#   host  namespace  address       runs
#   h0    pvr-h0     10.213.7.10   munged, slurmctld; pvrd and pvrsh when a test starts them
#   h1    pvr-h1     10.213.7.11   sshd, slurmd
#   h2    pvr-h2     10.213.7.12   sshd, slurmd
#   h3    pvr-h3     10.213.7.13   sshd, slurmd
#
# Each host is a network namespace with a veth pair to the bridge pvr-br0 in
# the root namespace (the bridge has no address: nothing leaves the /24).
# A process started "on" a host (cluster.sh exec) also gets a UTS namespace
# (its own hostname) and a mount namespace in which /etc/hosts is the
# cluster's and /run is private, so sshd has its privilege separation
# directory without touching the machine. The filesystem is otherwise shared:
# the data directory and the programs are at the same paths on every host.
#
#   cluster.sh up           create everything (state under $PVR_CLUSTER_DIR)
#   cluster.sh down         kill every process on the hosts, remove everything
#   cluster.sh exec H CMD   run CMD on host H with $PVR_CLUSTER_DIR/env.sh applied
#   cluster.sh boot H       start a compute host's daemons again (after a test killed them)
#   cluster.sh veth-bytes H the bytes H sent + received on its veth (one number)
#   cluster.sh compute-bytes  the bytes that went between compute hosts h1..h3
# (The hosts share the machine's /sys: these two work on a host as well.)
#
# PVR_CLUSTER_DIR (default /tmp/pvr-cluster) holds: env.sh (Open MPI over
# ssh, SLURM_CONF), hostfile (h1..h3, one slot each), hosts, ssh/ (keys,
# ssh_config, known_hosts), munge/, slurm/ (slurm.conf, state, logs), log/.
# When Slurm cannot run here, `up` says why, writes the reason to
# $PVR_CLUSTER_DIR/slurm.unavailable and still brings up the rest.
#
# Exit status 77: this machine does not allow the cluster (not root, a
# program missing, no UTS or mount namespaces, no network namespace, bridge
# or veth); the message says which. A failed `up` removes what it made.
set -euo pipefail

readonly HOSTS=(h0 h1 h2 h3)
readonly COMPUTE=(h1 h2 h3)
readonly SUBNET=10.213.7
readonly BRIDGE=pvr-br0
readonly SKIP=77
DIR=${PVR_CLUSTER_DIR:-/tmp/pvr-cluster}
SELF=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/$(basename "${BASH_SOURCE[0]}")

die() { echo "cluster.sh: $*" >&2; exit 1; }
skip() { echo "cluster.sh: SKIP: $*" >&2; exit $SKIP; }
namespace() { echo "pvr-$1"; }
address() { echo "$SUBNET.$((10 + ${1#h}))"; }
veth() { echo "pvr-v${1#h}"; }  # the bridge end, in the root namespace
valid_host() { [[ " ${HOSTS[*]} " == *" $1 "* ]] || die "no host '$1' (hosts: ${HOSTS[*]})"; }

# host_command HOST: sets HOSTCMD to the command prefix that runs a program
# on HOST: its network namespace (nsenter rather than `ip netns exec`, which
# mounts a fresh /sys that hides /sys/fs/cgroup, and slurmd will not start
# without it), a UTS namespace named HOST, a mount namespace with the
# cluster's /etc/hosts and a private /run. Every step execs: the program
# ends up with the pid of the caller.
host_command() {
  HOSTCMD=(nsenter --net="/run/netns/$(namespace "$1")" unshare --uts --mount --propagation private
    sh -c 'hostname "$1" && mount --bind "$2/hosts" /etc/hosts && mount -t tmpfs -o mode=0755 pvr-run /run &&
           mkdir -p /run/sshd && shift 2 && exec "$@"' pvr-on "$1" "$DIR")
}

# on HOST CMD...: CMD on HOST without the cluster environment (used by up).
on() {
  host_command "$1"
  shift
  "${HOSTCMD[@]}" "$@"
}

# --- up ---------------------------------------------------------------------

check_machine() {
  [ "$(id -u)" -eq 0 ] || skip "needs root (network namespaces, a bridge, sshd on port 22)"
  local p
  for p in ip unshare nsenter ssh sshd ssh-keygen mpirun; do
    command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] || skip "needs $p (packages iproute2, util-linux, openssh-server, openmpi-bin)"
  done
  unshare --uts --mount --propagation private true 2>/dev/null ||
    skip "cannot create UTS and mount namespaces (unshare --uts --mount refused)"
  if ip netns list 2>/dev/null | grep -q '^pvr-h'; then
    die "a cluster is up already (namespaces $(ip netns list | grep -o '^pvr-h[0-9]' | paste -sd' ')); run: $SELF down"
  fi
}

# IPv4 only on the cluster's links: no IPv6 neighbour discovery or router
# solicitations on the bridge, so its byte counters count our traffic.
# (A per-interface setting: it goes with the interface.)
no_ipv6() { echo 1 >"/proc/sys/net/ipv6/conf/$1/disable_ipv6"; }

make_network() {
  # `ip netns add` makes its directory (a bind mount of itself) if missing;
  # `down` removes it again then, when no namespace is left in it.
  [ -d /run/netns ] || : >"$DIR/.made-run-netns"
  ip link add "$BRIDGE" type bridge 2>/dev/null || skip "cannot create bridge $BRIDGE (ip link add type bridge refused)"
  no_ipv6 "$BRIDGE"
  ip link set "$BRIDGE" up
  local h ns
  for h in "${HOSTS[@]}"; do
    ns=$(namespace "$h")
    ip netns add "$ns" 2>/dev/null || skip "cannot create network namespace $ns (ip netns add refused)"
    ip link add "$(veth "$h")" type veth peer name eth0 netns "$ns" 2>/dev/null ||
      skip "cannot create a veth pair into $ns"
    no_ipv6 "$(veth "$h")"
    nsenter --net="/run/netns/$ns" sh -c 'echo 1 >/proc/sys/net/ipv6/conf/eth0/disable_ipv6'
    ip link set "$(veth "$h")" master "$BRIDGE" up
    ip -n "$ns" link set lo up
    ip -n "$ns" addr add "$(address "$h")/24" dev eth0
    ip -n "$ns" link set eth0 up
  done
}

write_names() {
  {
    echo "127.0.0.1 localhost"
    local h
    for h in "${HOSTS[@]}"; do echo "$(address "$h") $h"; done
  } >"$DIR/hosts"
  local h
  for h in "${COMPUTE[@]}"; do echo "$h slots=1"; done >"$DIR/hostfile"
}

# Host keys per host, one root key pair for every login, an ssh_config that
# names the hosts (so /etc/hosts need not), known_hosts: no prompt ever.
write_ssh() {
  local ssh=$DIR/ssh h
  mkdir -p "$ssh"
  chmod 700 "$ssh"
  ssh-keygen -q -t ed25519 -N '' -C pvr-cluster -f "$ssh/id_ed25519"
  cp "$ssh/id_ed25519.pub" "$ssh/authorized_keys"
  : >"$ssh/known_hosts"
  {
    for h in "${HOSTS[@]}"; do printf 'Host %s\n  HostName %s\n' "$h" "$(address "$h")"; done
    # BatchMode: never a prompt. ServerAlive*: a host that vanishes without
    # closing its connections (veth down) ends the ssh session, and so Open
    # MPI's daemon on it, within ~6 s.
    cat <<EOF2
Host *
  User root
  IdentityFile $ssh/id_ed25519
  IdentitiesOnly yes
  UserKnownHostsFile $ssh/known_hosts
  GlobalKnownHostsFile /dev/null
  StrictHostKeyChecking yes
  BatchMode yes
  ConnectTimeout 5
  ServerAliveInterval 2
  ServerAliveCountMax 3
  LogLevel ERROR
EOF2
  } >"$ssh/ssh_config"
  for h in "${COMPUTE[@]}"; do
    ssh-keygen -q -t ed25519 -N '' -C "$h" -f "$ssh/host_$h"
    echo "$h,$(address "$h") $(cut -d' ' -f1,2 "$ssh/host_$h.pub")" >>"$ssh/known_hosts"
    # StrictModes no: the keys live under /tmp, which is world-writable, and
    # StrictModes refuses an authorized_keys file below such a directory.
    cat >"$ssh/sshd_config.$h" <<EOF2
Port 22
ListenAddress $(address "$h")
HostKey $ssh/host_$h
PidFile $DIR/run/sshd.$h.pid
AuthorizedKeysFile $ssh/authorized_keys
PermitRootLogin prohibit-password
PubkeyAuthentication yes
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
StrictModes no
PrintMotd no
X11Forwarding no
MaxStartups 64
EOF2
  done
}

# start_sshd HOST: sshd on HOST, and wait until h0 logs in there.
start_sshd() {
  local h=$1
  on "$h" /usr/sbin/sshd -f "$DIR/ssh/sshd_config.$h" -E "$DIR/log/sshd.$h.log" ||
    die "sshd on $h did not start (see $DIR/log/sshd.$h.log)"
  # The first packets between namespaces: a failure here may also be the
  # bridge dropping them (bridge netfilter, /proc/sys/net/bridge).
  wait_for "ssh from h0 to $h ($(address "$h"))" 10 on h0 ssh -F "$DIR/ssh/ssh_config" "$h" true
}

# wait_for WHAT SECONDS CMD...: retries CMD until it succeeds.
wait_for() {
  local what=$1 seconds=$2 i
  shift 2
  for ((i = 0; i < seconds * 5; i++)); do
    "$@" >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  "$@" >&2 || die "$what: not ready after ${seconds}s (logs in $DIR/log)"
}

write_env() {
  # Open MPI 4.1 splits plm_rsh_agent at spaces into the command and its
  # arguments (and at ':' into alternatives: the path must have none).
  [[ "$DIR" != *[:\ ]* ]] || die "PVR_CLUSTER_DIR must not contain ':' or spaces: $DIR"
  cat >"$DIR/env.sh" <<EOF
# The mini-cluster's environment (tests/cluster/cluster.sh). A site sets the
# same OMPI_MCA_* variables for pvrd: they reach mpirun through its environment.
export PVR_CLUSTER_DIR=$DIR
export OMPI_MCA_plm_rsh_agent="ssh -F $DIR/ssh/ssh_config"
export OMPI_MCA_pml=ob1
export OMPI_MCA_btl=self,vader,tcp
export OMPI_MCA_btl_tcp_if_include=$SUBNET.0/24
export OMPI_MCA_oob_tcp_if_include=$SUBNET.0/24
export OMPI_MCA_rmaps_base_oversubscribe=1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export SLURM_CONF=$DIR/slurm/slurm.conf
EOF
}

# One munged for the cluster (its socket is a file every host sees);
# slurmctld on h0, slurmd on h1..h3. On failure: the reason, not an exit.
start_slurm() {
  local p
  for p in munged slurmctld slurmd srun salloc sinfo; do
    command -v "$p" >/dev/null || { slurm_unavailable "$p is not installed (packages munge, slurm-wlm)"; return 0; }
  done
  local munge=$DIR/munge slurm=$DIR/slurm
  mkdir -p "$munge" "$slurm/ctld" "${COMPUTE[@]/#/$slurm/spool.}"
  chmod 755 "$munge"  # munged wants its socket's directory searchable by all
  dd if=/dev/urandom of="$munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$munge/munge.key"
  if ! on h0 munged --key-file="$munge/munge.key" --socket="$munge/munge.socket" --pid-file="$DIR/run/munged.pid" \
    --log-file="$DIR/log/munged.log" --seed-file="$munge/seed" 2>>"$DIR/log/munged.log"; then
    slurm_unavailable "munged did not start: $(tail -n 1 "$DIR/log/munged.log")"
    return 0
  fi
  write_slurm_conf
  : >"$slurm/plugstack.conf"
  if ! SLURM_CONF=$slurm/slurm.conf on h0 slurmctld -c -L "$DIR/log/slurmctld.log" 2>>"$DIR/log/slurmctld.log"; then
    slurm_unavailable "slurmctld did not start: $(tail -n 1 "$DIR/log/slurmctld.log")"
    return 0
  fi
  local h
  for h in "${COMPUTE[@]}"; do
    if ! start_slurmd "$h"; then
      slurm_unavailable "slurmd on $h did not start: $(tail -n 1 "$DIR/log/slurmd.$h.log")"
      return 0
    fi
  done
  local i idle=0
  for ((i = 0; i < 100; i++)); do
    idle=$(SLURM_CONF=$slurm/slurm.conf on h0 sinfo -h -N -t idle -o %N 2>/dev/null | sort -u | wc -l) || idle=0
    [ "$idle" -eq ${#COMPUTE[@]} ] && return 0
    sleep 0.2
  done
  slurm_unavailable "only $idle of ${#COMPUTE[@]} slurmd registered idle with slurmctld in 20 s: $(SLURM_CONF=$slurm/slurm.conf on h0 sinfo -h -N -o '%N %t %E' 2>&1 | paste -sd';')"
}

start_slurmd() {
  SLURM_CONF=$DIR/slurm/slurm.conf on "$1" slurmd -N "$1" -L "$DIR/log/slurmd.$1.log" 2>>"$DIR/log/slurmd.$1.log"
}

slurm_unavailable() {
  echo "$1" >"$DIR/slurm.unavailable"
  echo "cluster.sh: Slurm is not available in this cluster: $1" >&2
}

write_slurm_conf() {
  local slurm=$DIR/slurm h
  # One CPU per node, so `-n 2` means two hosts. No cgroups: process
  # tracking by parent pid, no task binding, no accounting.
  {
    cat <<EOF
ClusterName=pvr
SlurmctldHost=h0($(address h0))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$DIR/munge/munge.socket
StateSaveLocation=$slurm/ctld
SlurmdSpoolDir=$slurm/spool.%n
SlurmctldPidFile=$DIR/run/slurmctld.pid
SlurmdPidFile=$DIR/run/slurmd.%n.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.%n.log
PlugStackConfig=$slurm/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
ReturnToService=2
KillWait=2
MinJobAge=2
InactiveLimit=0
SlurmdTimeout=60
EOF
    for h in "${COMPUTE[@]}"; do echo "NodeName=$h NodeAddr=$(address "$h") CPUs=1 State=UNKNOWN"; done
    echo "PartitionName=pvr Nodes=$(IFS=,; echo "${COMPUTE[*]}") Default=YES MaxTime=INFINITE State=UP"
  } >"$slurm/slurm.conf"
}

up() {
  check_machine
  mkdir -p "$DIR"
  chmod 755 "$DIR"
  [ -z "$(ls -A "$DIR")" ] || die "$DIR is not empty; give PVR_CLUSTER_DIR a fresh directory"
  : >"$DIR/.pvr-cluster"  # `down` removes only a directory that has this
  mkdir -p "$DIR/log" "$DIR/run"
  trap 'echo "cluster.sh: up failed; removing what it made" >&2; down_quietly' ERR EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
  write_names
  make_network
  write_env
  write_ssh
  local h
  for h in "${COMPUTE[@]}"; do start_sshd "$h"; done
  start_slurm
  trap - ERR EXIT INT TERM
  echo "cluster.sh: up: hosts ${HOSTS[*]} on $SUBNET.0/24; source $DIR/env.sh; hostfile $DIR/hostfile" >&2
}

# --- down -------------------------------------------------------------------

# Every process of every host (ip netns pids finds even those that changed
# their process group), TERM then KILL; then the namespaces and the bridge.
down() {
  local h ns pids i
  for h in "${HOSTS[@]}"; do
    ns=$(namespace "$h")
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -TERM 2>/dev/null || true
  done
  for ((i = 0; i < 25; i++)); do
    pids=$(for h in "${HOSTS[@]}"; do ip netns pids "$(namespace "$h")" 2>/dev/null; done)
    [ -z "$pids" ] && break
    sleep 0.2
  done
  for h in "${HOSTS[@]}"; do
    ns=$(namespace "$h")
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$ns" 2>/dev/null || true
  done
  ip link del "$BRIDGE" 2>/dev/null || true
  if [ -f "$DIR/.made-run-netns" ] && [ -z "$(ls -A /run/netns 2>/dev/null)" ]; then
    while mountpoint -q /run/netns; do umount /run/netns; done
    rmdir /run/netns
  fi
  if [ -f "$DIR/.pvr-cluster" ]; then rm -rf "$DIR"; fi
}

down_quietly() {
  trap - ERR EXIT INT TERM
  down 2>/dev/null || true
}

# --- exec and the rest --------------------------------------------------------

exec_on() {
  local host=$1
  shift
  valid_host "$host"
  [ $# -gt 0 ] || die "usage: cluster.sh exec HOST CMD..."
  ip netns list | grep -q "^$(namespace "$host")\b" || die "host $host is not up (run: $SELF up)"
  [ -f "$DIR/env.sh" ] || die "$DIR/env.sh is missing: is PVR_CLUSTER_DIR the directory given to up?"
  # shellcheck disable=SC1091
  set -a && . "$DIR/env.sh" && set +a
  host_command "$host"
  exec "${HOSTCMD[@]}" "$@"
}

# boot HOST: a compute host that lost its processes (a test killed them)
# starts its daemons again: sshd, and slurmd when Slurm is up.
boot() {
  valid_host "$1"
  [[ " ${COMPUTE[*]} " == *" $1 "* ]] || die "boot: $1 is not a compute host (${COMPUTE[*]})"
  [ -f "$DIR/.pvr-cluster" ] || die "no cluster in $DIR (run: $SELF up)"
  [ -z "$(ip netns pids "$(namespace "$1")")" ] || die "boot: $1 still runs processes"
  start_sshd "$1"
  if [ -f "$DIR/slurm/slurm.conf" ] && [ ! -f "$DIR/slurm.unavailable" ]; then
    start_slurmd "$1" || die "slurmd on $1 did not start again (see $DIR/log/slurmd.$1.log)"
  fi
}

veth_bytes() {
  valid_host "$1"
  local v
  v=$(veth "$1")
  echo $(($(cat "/sys/class/net/$v/statistics/rx_bytes") + $(cat "/sys/class/net/$v/statistics/tx_bytes")))
}

# compute_bytes: bytes carried between the compute hosts so far. A frame
# between two compute hosts crosses two of their veths; one between h0 and
# a compute host crosses h0's veth and one other. So the sum over the
# compute hosts minus h0's counts the compute-to-compute frames twice.
# (Only ranks talk there: ssh and Open MPI's daemons talk to h0.)
compute_bytes() {
  local sum=0 h
  for h in "${COMPUTE[@]}"; do sum=$((sum + $(veth_bytes "$h"))); done
  echo $(((sum - $(veth_bytes h0)) / 2))
}

case "${1:-}" in
  up) up ;;
  down) down ;;
  exec) shift; exec_on "$@" ;;
  boot) boot "${2:?usage: cluster.sh boot HOST}" ;;
  veth-bytes) veth_bytes "${2:?usage: cluster.sh veth-bytes HOST}" ;;
  compute-bytes) compute_bytes ;;
  *) die "usage: cluster.sh up|down|exec HOST CMD...|boot HOST|veth-bytes HOST|compute-bytes" ;;
esac
