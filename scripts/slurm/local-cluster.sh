#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for testing the job arrays for real:
#   scripts/slurm/local-cluster.sh start   # installs slurm-wlm and munge if needed, starts munged,
#                                          # slurmctld and slurmd; prints the SLURM_CONF to export
#   scripts/slurm/local-cluster.sh stop
# Everything it writes lives in $QSGI_SLURM_DIR (default /tmp/qsgi-slurm). Needs root (or sudo):
# the daemons run as root with no cgroups (proctrack/linuxproc, task/none), so it works in
# containers too. Not for production clusters: their administrators configure those.
set -euo pipefail

dir=${QSGI_SLURM_DIR:-/tmp/qsgi-slurm}
conf=$dir/slurm.conf
if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi

stop() {
  for daemon in slurmd slurmctld; do
    if [ -f "$dir/$daemon.pid" ]; then "${sudo[@]}" kill "$(cat "$dir/$daemon.pid")" 2>/dev/null || true; fi
  done
  if [ -f "$dir/munged.pid" ]; then "${sudo[@]}" kill "$(cat "$dir/munged.pid")" 2>/dev/null || true; fi
  sleep 1
}

start() {
  packages=(slurm-wlm munge)
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "local-cluster: installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    "${sudo[@]}" apt-get update -qq
    "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
  stop
  "${sudo[@]}" mkdir -p "$dir/state" "$dir/spool" "$dir/munge" "$dir/munge-run"
  # munge: our own key and socket, so a system munged (if any) is left alone.
  "${sudo[@]}" sh -c "dd if=/dev/urandom bs=1 count=1024 of=$dir/munge/munge.key 2>/dev/null"
  "${sudo[@]}" chmod 700 "$dir/munge" "$dir/munge-run"
  "${sudo[@]}" chmod 400 "$dir/munge/munge.key"
  "${sudo[@]}" /usr/sbin/munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge-run/munge.socket" \
    --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munge/seed"
  host=$(hostname -s)
  cpus=$(nproc)
  memory=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))
  "${sudo[@]}" tee "$conf" >/dev/null <<CONF
ClusterName=qsgi-test
SlurmctldHost=$host
AuthType=auth/munge
AuthInfo=socket=$dir/munge-run/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
SchedulerParameters=kill_invalid_depend
ReturnToService=2
MpiDefault=none
SlurmdTimeout=60
InactiveLimit=0
KillWait=5
NodeName=$host CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$conf
  "${sudo[@]}" env SLURM_CONF="$conf" /usr/sbin/slurmctld -f "$conf"
  "${sudo[@]}" env SLURM_CONF="$conf" /usr/sbin/slurmd -f "$conf"
  for _ in $(seq 60); do
    if sinfo -h -o '%t' 2>/dev/null | grep -q -E '^(idle|mix|alloc)'; then
      echo "local-cluster: up ($host, $cpus CPUs); export SLURM_CONF=$conf"
      return 0
    fi
    sleep 1
  done
  echo "local-cluster: the node did not come up; see $dir/slurmctld.log and $dir/slurmd.log" >&2
  sinfo >&2 || true
  return 1
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: $0 start|stop" >&2; exit 2 ;;
esac
