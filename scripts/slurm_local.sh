#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for tests and for trying `shadowlab sweep slurm`
# without a cluster (docs/cluster.md). Everything lives in DIR: munge key and socket, slurm.conf,
# state, spool, logs; nothing under /etc or /run is used, and no systemd is needed.
#
#   scripts/slurm_local.sh start DIR   starts munged, slurmctld and slurmd; waits until the node is idle;
#                                      prints `export SLURM_CONF=DIR/slurm.conf` (source it for sbatch, squeue)
#   scripts/slurm_local.sh stop DIR    stops exactly the daemons that `start DIR` started (DIR/*.pid)
#
# Runs as root (slurmd starts jobs as their user). Needs the Debian packages munge and slurm-wlm
# (scripts/setup.sh). Containers without cgroups are fine: process tracking by /proc, no task
# binding, no accounting.
set -euo pipefail

cmd=${1:-}
dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }

alive() {
  # A zombie (exited, not yet reaped by init) counts as stopped.
  local st
  st=$(ps -o stat= -p "$1" 2>/dev/null) && [ "${st:0:1}" != Z ]
}

stop() {
  # Only our own daemons, by the pids recorded at start (never by name: other clusters may run here).
  for d in slurmd slurmctld munged; do
    f="$dir/$d.pid"
    [ -f "$f" ] || continue
    pid=$(cat "$f")
    if alive "$pid"; then
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 50); do alive "$pid" || break; sleep 0.1; done
      if alive "$pid"; then kill -9 "$pid" 2>/dev/null || true; fi
    fi
    rm -f "$f"
  done
}

if [ "$cmd" = stop ]; then
  stop
  exit 0
fi
[ "$cmd" = start ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }

for b in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$b" >/dev/null || { echo "slurm_local: $b not found: install munge and slurm-wlm (scripts/setup.sh)" >&2; exit 1; }
done

mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
# munged insists: the socket's folder searchable by all, the key readable by its owner only.
chmod 755 "$dir"
mkdir -p "$dir/state" "$dir/spool" "$dir/log"
head -c 1024 /dev/urandom > "$dir/munge.key"
chmod 600 "$dir/munge.key"

# Three free TCP ports (controller, node daemon, srun) from the kernel.
read -r ctld_port slurmd_port srun_port < <(/usr/bin/python3 - <<'EOF'
import socket
socks = [socket.socket() for _ in range(3)]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])
EOF
)
host=$(hostname -s)
cpus=$(nproc)
# The loopback address is given explicitly: containers often cannot resolve their own host name.
cat > "$dir/slurm.conf" <<EOF
# One node, this machine: written by scripts/slurm_local.sh.
ClusterName=shadowlab
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SrunPortRange=$srun_port-$srun_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge.sock
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.daemon.pid
SlurmdPidFile=$dir/slurmd.daemon.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=3600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF

trap 'stop' ERR
munged -F --key-file="$dir/munge.key" --socket="$dir/munge.sock" --pid-file="$dir/munged.daemon.pid" \
  --log-file="$dir/log/munged.log" --seed-file="$dir/munged.seed" > "$dir/log/munged.out" 2>&1 &
echo $! > "$dir/munged.pid"
for _ in $(seq 50); do [ -S "$dir/munge.sock" ] && break; sleep 0.1; done
[ -S "$dir/munge.sock" ] || { echo "slurm_local: munged did not start (see $dir/log/munged.out)" >&2; false; }

export SLURM_CONF="$dir/slurm.conf"
slurmctld -D -f "$SLURM_CONF" > "$dir/log/slurmctld.out" 2>&1 &
echo $! > "$dir/slurmctld.pid"
slurmd -D -f "$SLURM_CONF" > "$dir/log/slurmd.out" 2>&1 &
echo $! > "$dir/slurmd.pid"

# Ready when the node reports idle (the controller answers and the node has registered).
for _ in $(seq 300); do
  state=$(sinfo -h -o %T 2>/dev/null || true)
  [ "$state" = idle ] && break
  sleep 0.1
done
[ "$state" = idle ] || { echo "slurm_local: the node did not become idle (state \"$state\"; logs in $dir/log)" >&2; false; }
echo "export SLURM_CONF=$SLURM_CONF"
