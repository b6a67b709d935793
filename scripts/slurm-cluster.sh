#!/usr/bin/env bash
# A real single-node Slurm cluster on this machine, without systemd: for CI and for trying
# `specconv farm`. Needs root and Debian's slurm-wlm and munge (apt-get install slurm-wlm munge).
#
#   scripts/slurm-cluster.sh start    # munged, slurmctld, slurmd; returns when the node is idle
#   scripts/slurm-cluster.sh status   # sinfo, or exit 1 when the controller does not answer
#   scripts/slurm-cluster.sh stop     # stops the daemons by their PID files
#
# `start` writes /etc/slurm/slurm.conf (refusing to replace one it did not write) and is a no-op
# when the cluster already answers. Settings chosen for containers: no cgroups
# (proctrack/linuxproc, task/none), the node on 127.0.0.1, no scheduling delay (an array of
# short tasks otherwise waits for the scheduler's interval), finished jobs kept an hour so that
# `specconv farm status` reads their exit codes, and a per-task completion log
# (jobcomp/filetxt) since there is no accounting database.
set -euo pipefail

CONF=/etc/slurm/slurm.conf
MARK="# written by specconv scripts/slurm-cluster.sh"
NODE=specconv-node
LOGS=/var/log/slurm
PIDS=(/run/slurmd.pid /run/slurmctld.pid /run/munge/munged.pid)

die() { echo "slurm-cluster: $*" >&2; exit 1; }

answers() { scontrol ping 2>/dev/null | grep -q 'is UP'; }

write_conf() {
  if [ -f "$CONF" ] && ! grep -qF "$MARK" "$CONF"; then
    die "$CONF exists and was not written by this script; stop that cluster or move the file"
  fi
  # The node as slurmd sees it (CPUs, sockets, cores, threads), memory less 1 GiB for the system.
  local node mem cpus
  node=$(slurmd -C | head -n 1 | sed -e 's/^NodeName=[^ ]* //' -e 's/ RealMemory=[0-9]*//')
  mem=$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' | head -n 1)
  mem=$(( mem > 2048 ? mem - 1024 : mem ))
  cpus=$(echo "$node" | sed -n 's/.*CPUs=\([0-9]*\).*/\1/p')
  mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd "$LOGS"
  cat >"$CONF" <<EOF
$MARK
ClusterName=specconv
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=$LOGS/slurmctld.log
SlurmdLogFile=$LOGS/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=$(( mem / cpus ))
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
MinJobAge=3600
ReturnToService=2
JobCompType=jobcomp/filetxt
JobCompLoc=$LOGS/jobcomp.log
NodeName=$NODE NodeAddr=127.0.0.1 $node RealMemory=$mem State=UNKNOWN
PartitionName=main Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
}

start() {
  [ "$(id -u)" -eq 0 ] || die "start needs root (munged, slurmctld and slurmd are system daemons)"
  command -v slurmctld >/dev/null || die "slurmctld not found; apt-get install slurm-wlm munge"
  if answers; then
    echo "slurm-cluster: already running"
    sinfo
    return
  fi
  write_conf
  [ -s /etc/munge/munge.key ] || runuser -u munge -- mungekey --create
  mkdir -p /run/munge && chown munge:munge /run/munge
  if ! [ -S /run/munge/munge.socket.2 ] || ! munge -n >/dev/null 2>&1; then
    runuser -u munge -- munged
  fi
  slurmctld -c
  slurmd -N "$NODE"
  for _ in $(seq 1 60); do
    if sinfo -h -N -o '%T' 2>/dev/null | grep -qx idle; then
      sinfo
      return
    fi
    sleep 0.5
  done
  tail -n 20 "$LOGS/slurmctld.log" "$LOGS/slurmd.log" >&2 || true
  die "the node did not become idle within 30 s (logs above)"
}

stop() {
  # Read every PID first: a stopping daemon may remove its own file.
  local pids=() f
  for f in "${PIDS[@]}"; do
    if [ -s "$f" ]; then pids+=("$(cat "$f")"); fi
  done
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for _ in $(seq 1 40); do
    local alive=0
    for p in "${pids[@]}"; do if kill -0 "$p" 2>/dev/null; then alive=1; fi; done
    [ "$alive" -eq 0 ] && break
    sleep 0.25
  done
  rm -f /run/slurmctld.pid /run/slurmd.pid
  echo "slurm-cluster: stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) answers || die "the controller does not answer"; sinfo ;;
  *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
