#!/usr/bin/env bash
# A single-node SLURM on localhost (slurmctld + slurmd + munge) for the SLURM launcher test.
#
#   scripts/slurm_local.sh up       install (apt, as root) if needed, configure, start; idempotent
#   scripts/slurm_local.sh down     stop slurmd, slurmctld and munged
#   scripts/slurm_local.sh status   print whether the node is up (exit 0) or not (exit 1)
#
# Debian/Ubuntu only. Works without systemd (containers): the daemons are started directly.
# The node gets all of the machine's CPUs and most of its memory; one partition, "debug", is the default.
set -euo pipefail

PARTITION=${SLURM_LOCAL_PARTITION:-debug}
CONF_DIR=/etc/slurm
SPOOL=/var/spool/slurm
LOG_DIR=/var/log/slurm
NODE=$(hostname -s)

log() { echo "slurm_local: $*" >&2; }

install_packages() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null \
        && command -v sbatch >/dev/null; then
        return
    fi
    [[ $(id -u) == 0 ]] || { log "installing needs root (apt-get)"; exit 1; }
    log "installing slurmctld, slurmd, slurm-client, munge with apt-get"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends slurmctld slurmd slurm-client munge >/dev/null
}

configure_munge() {
    install -d -o munge -g munge -m 0700 /etc/munge /var/lib/munge /var/log/munge
    install -d -o munge -g munge -m 0755 /run/munge
    if [[ ! -s /etc/munge/munge.key ]]; then
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
    chown munge:munge /etc/munge/munge.key
    chmod 0400 /etc/munge/munge.key
}

configure_slurm() {
    local cpus mem_mb
    cpus=$(nproc)
    mem_mb=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 ))
    install -d -m 0755 "$CONF_DIR" "$SPOOL/ctld" "$SPOOL/d" "$LOG_DIR"
    # No cgroup.conf on purpose: slurm 22.05 has no CgroupPlugin=disabled and slurmd refuses to start
    # with a cgroup plugin inside an unprivileged container; linuxproc + task/none need none.
    cat >"$CONF_DIR/slurm.conf.new" <<CONF
# Written by cerebx scripts/slurm_local.sh: single-node SLURM on $NODE.
ClusterName=cerebx-local
SlurmctldHost=$NODE
SlurmUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
StateSaveLocation=$SPOOL/ctld
SlurmdSpoolDir=$SPOOL/d
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=$LOG_DIR/slurmctld.log
SlurmdLogFile=$LOG_DIR/slurmd.log
SchedulerType=sched/backfill
NodeName=$NODE CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=$PARTITION Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
CONF
    if ! cmp -s "$CONF_DIR/slurm.conf.new" "$CONF_DIR/slurm.conf"; then
        mv "$CONF_DIR/slurm.conf.new" "$CONF_DIR/slurm.conf"
        CONF_CHANGED=1
    else
        rm "$CONF_DIR/slurm.conf.new"
    fi
}

# The daemons' pid files: only the processes these name are checked and stopped.
declare -A PIDFILE=([munged]=/run/munge/munged.pid [slurmctld]=/run/slurmctld.pid [slurmd]=/run/slurmd.pid)

running() {
    local pid
    pid=$(cat "${PIDFILE[$1]}" 2>/dev/null) || return 1
    [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null && [[ $(cat "/proc/$pid/comm" 2>/dev/null) == "$1" ]]
}

stop_daemon() {
    running "$1" || return 0
    log "stopping $1"
    kill "$(cat "${PIDFILE[$1]}")" || true
    for _ in $(seq 20); do running "$1" || return 0; sleep 0.5; done
    log "$1 did not stop within 10 s"
}

start() {
    if ! running munged; then
        log "starting munged"
        runuser -u munge -- /usr/sbin/munged
    fi
    if [[ ${CONF_CHANGED:-0} == 1 ]]; then
        stop_slurm
    fi
    if ! running slurmctld; then
        log "starting slurmctld"
        /usr/sbin/slurmctld
    fi
    if ! running slurmd; then
        log "starting slurmd"
        /usr/sbin/slurmd 2>/dev/null
    fi
    for _ in $(seq 60); do
        if sinfo -h -N -o '%t' 2>/dev/null | grep -qE '^(idle|mix|alloc)'; then
            log "node $NODE is up; partition $PARTITION"
            return
        fi
        sleep 1
    done
    log "node did not come up within 60 s; see $LOG_DIR/slurmctld.log and $LOG_DIR/slurmd.log"
    exit 1
}

stop_slurm() {
    stop_daemon slurmd
    stop_daemon slurmctld
}

case ${1:-up} in
    up)
        install_packages
        configure_munge
        configure_slurm
        start
        ;;
    down)
        stop_slurm
        stop_daemon munged
        ;;
    status)
        sinfo -h -N -o '%N %t %c' 2>/dev/null | grep -qE ' (idle|mix|alloc) ' && { sinfo; exit 0; }
        log "not up"; exit 1
        ;;
    *)
        echo "usage: $0 up|down|status" >&2; exit 2
        ;;
esac
