#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for the tests and for trying
# `--executor slurm`: `start` installs slurm-wlm and munge from Debian when
# they are missing, writes a slurm.conf for this host (loopback only;
# consumable CPUs, oversubscribed so that more workers than cores can run),
# starts munged, slurmctld and slurmd, and waits until `srun -n1 true`
# answers. `stop` ends the daemons it started. Needs root.
set -euo pipefail

CONF_DIR=/etc/slurm
STATE=/var/lib/scenefit-slurm
RUN=/run/scenefit-slurm
HOST=$(hostname -s)
# More workers than cores must run at once (latency-bound workers).
OVERSUBSCRIBE=${SCENEFIT_SLURM_OVERSUBSCRIBE:-128}

die() { echo "slurm-local.sh: $*" >&2; exit 1; }

install() {
  if command -v slurmctld >/dev/null && command -v slurmd >/dev/null \
     && command -v srun >/dev/null && command -v munged >/dev/null; then
    return
  fi
  [ "$(id -u)" = 0 ] || die "slurm-wlm and munge are missing; run as root to install them"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
}

write_conf() {
  local cpus mem
  cpus=$(nproc)
  mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512 ))
  mkdir -p "$CONF_DIR" "$STATE/ctld" "$STATE/d" "$RUN"
  cat >"$CONF_DIR/slurm.conf" <<CONF
# written by scenefit's scripts/slurm-local.sh: one node, loopback only
ClusterName=scenefit
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmctldPort=6817
SlurmdPort=6818
SlurmctldPidFile=$RUN/slurmctld.pid
SlurmdPidFile=$RUN/slurmd.pid
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/d
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
ReturnToService=2
SlurmdParameters=config_overrides
KillWait=2
InactiveLimit=0
MinJobAge=30
MaxJobCount=100000
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:$OVERSUBSCRIBE
CONF
}

start_munge() {
  if pgrep -x munged >/dev/null; then return; fi
  if [ ! -s /etc/munge/munge.key ]; then
    mkdir -p /etc/munge
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
  fi
  mkdir -p /run/munge /var/lib/munge /var/log/munge
  chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2>/dev/null || true
  chmod 0400 /etc/munge/munge.key
  if id munge >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged
  else
    /usr/sbin/munged --force
  fi
}

running() { [ -s "$RUN/$1.pid" ] && kill -0 "$(cat "$RUN/$1.pid")" 2>/dev/null; }

start() {
  install
  write_conf
  start_munge
  running slurmctld || slurmctld
  running slurmd || slurmd
  local t0=$SECONDS
  until timeout 10 srun -n1 --job-name scenefit-probe true >/dev/null 2>&1; do
    if (( SECONDS - t0 > 60 )); then
      tail -n 20 "$STATE/slurmctld.log" "$STATE/slurmd.log" >&2 || true
      die "slurm did not answer \`srun -n1 true\` within 60 s"
    fi
    # a node that was down when slurmctld last ran comes back here
    scontrol update nodename="$HOST" state=resume >/dev/null 2>&1 || true
    sleep 0.5
  done
  echo "slurm-local.sh: single-node cluster up on $HOST ($(nproc) CPUs, oversubscribed x$OVERSUBSCRIBE)"
}

stop() {
  local d
  for d in slurmd slurmctld; do
    if running "$d"; then kill "$(cat "$RUN/$d.pid")" 2>/dev/null || true; fi
  done
  for d in slurmd slurmctld; do
    for _ in $(seq 50); do running "$d" || break; sleep 0.1; done
  done
  echo "slurm-local.sh: stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: $0 start|stop" >&2; exit 2 ;;
esac
