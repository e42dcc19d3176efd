#!/usr/bin/env bash
# A one-node Slurm cluster on this Debian/Ubuntu machine, from the distribution's packages
# (slurm-wlm, munge), for trying the array-job recipe before a real cluster.
#
#   deploy/slurm/local-cluster.sh start    # install if needed, configure, start the daemons
#   deploy/slurm/local-cluster.sh status   # daemons and the node's state
#   deploy/slurm/local-cluster.sh stop     # cancel every job, stop every daemon it started
#
# Needs root. The node gets this host's cores and memory (as `slurmd -C` reports them) and
# one partition, `debug`. Daemons run in the background with their state where the
# packages keep it: /etc/slurm/slurm.conf (written here, and only if absent or written by
# this script before), /var/lib/slurm, /var/log/slurm, /run/slurm, /run/munge. Every start
# begins with an empty job queue.
set -euo pipefail

CONF=/etc/slurm/slurm.conf
MARK="# Written by hdw deploy/slurm/local-cluster.sh; rewritten at each start."
RUN=/run/slurm
MUNGE_PID=/run/munge/munged.pid

die() { echo "local-cluster: $*" >&2; exit 1; }
say() { echo "local-cluster: $*" >&2; }

# The pid in FILE when that process is alive.
live_pid() {
    local pid
    [[ -f $1 ]] || return 1
    pid=$(cat "$1")
    [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null && echo "$pid"
}

install_packages() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null; then
        return
    fi
    command -v apt-get >/dev/null || die "slurm-wlm and munge are missing and there is no apt-get: install them with this system's package manager"
    say "installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null ||
        { apt-get update >/dev/null && apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null; } ||
        die "apt-get could not install slurm-wlm and munge"
}

write_config() {
    if [[ -f $CONF ]] && ! grep -qF "$MARK" "$CONF"; then
        die "$CONF exists and was not written by this script: this machine already has a Slurm configuration; refusing to replace it"
    fi
    local node host
    # e.g. "NodeName=vm CPUs=2 Boards=1 SocketsPerBoard=1 CoresPerSocket=2 ThreadsPerCore=1 RealMemory=24105"
    node=$(slurmd -C | head -n 1)
    [[ $node == NodeName=* ]] || die "slurmd -C did not describe this host (got: $node)"
    host=${node#NodeName=}
    host=${host%% *}
    mkdir -p /etc/slurm
    cat >"$CONF" <<EOF
$MARK
ClusterName=hdw-local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=slurm
AuthType=auth/munge
StateSaveLocation=/var/lib/slurm/slurmctld
SlurmdSpoolDir=/var/lib/slurm/slurmd
SlurmctldPidFile=$RUN/slurmctld.pid
SlurmdPidFile=$RUN/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
# No cgroups needed (containers, WSL): processes are tracked by parent id.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SchedulerType=sched/backfill
# Cores are the consumable: an array of one-core tasks fills every core.
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
JobRequeue=1
# Keep finished jobs visible to scontrol for 10 minutes.
MinJobAge=600
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
    echo "$host"
}

start_munge() {
    if live_pid "$MUNGE_PID" >/dev/null; then
        return
    fi
    [[ -s /etc/munge/munge.key ]] || { mungekey --create >/dev/null 2>&1 || die "cannot create /etc/munge/munge.key"; }
    chown munge:munge /etc/munge/munge.key
    chmod 0400 /etc/munge/munge.key
    install -d -o munge -g munge -m 0755 /run/munge
    install -d -o munge -g munge -m 0700 /var/lib/munge /var/log/munge
    runuser -u munge -- /usr/sbin/munged || die "munged did not start (see /var/log/munge/munged.log)"
    munge -n | unmunge >/dev/null || die "munge cannot encode and decode a credential"
}

start() {
    [[ $EUID -eq 0 ]] || die "start needs root (it installs packages and starts system daemons)"
    install_packages
    local host
    host=$(write_config)
    start_munge
    install -d -o slurm -g slurm -m 0755 "$RUN" /var/lib/slurm/slurmctld /var/log/slurm
    install -d -m 0755 /var/lib/slurm/slurmd
    if ! live_pid "$RUN/slurmctld.pid" >/dev/null; then
        # -c: start with an empty queue (jobs of an earlier session are forgotten).
        slurmctld -c || die "slurmctld did not start (see /var/log/slurm/slurmctld.log)"
    fi
    if ! live_pid "$RUN/slurmd.pid" >/dev/null; then
        slurmd || die "slurmd did not start (see /var/log/slurm/slurmd.log)"
    fi
    local state=""
    for _ in $(seq 60); do
        state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
        case $state in
            idle* | mixed* | allocated*) break ;;
            down* | drain*) scontrol update nodename="$host" state=resume 2>/dev/null || true ;;
        esac
        sleep 1
    done
    case $state in
        idle* | mixed* | allocated*) ;;
        *) die "node $host is '${state:-unknown}' after 60 s (see /var/log/slurm/slurmd.log and slurmctld.log)" ;;
    esac
    say "up: node $host ($(sinfo -h -n "$host" -o '%c CPUs, %m MB'), partition debug); stop with: $0 stop"
}

# Signal the process in pidfile $1 and wait up to 20 s for it to end.
stop_daemon() {
    local pid
    pid=$(live_pid "$1") || return 0
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 40); do
        kill -0 "$pid" 2>/dev/null || return 0
        sleep 0.5
    done
    say "$2 (pid $pid) still running after 20 s; killing it"
    kill -9 "$pid" 2>/dev/null || true
}

stop() {
    [[ $EUID -eq 0 ]] || die "stop needs root"
    if live_pid "$RUN/slurmctld.pid" >/dev/null; then
        local jobs
        jobs=$(squeue -h -o %A 2>/dev/null | sort -u | tr '\n' ' ')
        if [[ -n ${jobs// /} ]]; then
            say "cancelling jobs: $jobs"
            # shellcheck disable=SC2086 # one argument per job id
            scancel $jobs 2>/dev/null || true
            for _ in $(seq 30); do
                [[ -z $(squeue -h -o %A 2>/dev/null) ]] && break
                sleep 1
            done
        fi
    fi
    stop_daemon "$RUN/slurmd.pid" slurmd
    stop_daemon "$RUN/slurmctld.pid" slurmctld
    stop_daemon "$MUNGE_PID" munged
    local left="" name
    for name in slurmctld slurmd slurmstepd munged; do
        left+=$(pgrep -x "$name" | sed "s/^/$name:/" | tr '\n' ' ' || true)
    done
    [[ -z ${left// /} ]] || die "processes still running after stop: $left"
    say "stopped"
}

status() {
    local name file pid
    for name in munged slurmctld slurmd; do
        case $name in
            munged) file=$MUNGE_PID ;;
            *) file=$RUN/$name.pid ;;
        esac
        if pid=$(live_pid "$file"); then echo "$name: running (pid $pid)"; else echo "$name: stopped"; fi
    done
    if live_pid "$RUN/slurmctld.pid" >/dev/null; then
        sinfo
        squeue
    fi
}

case ${1:-} in
    start) start ;;
    stop) stop ;;
    status) status ;;
    *) die "usage: $0 start|stop|status" ;;
esac
