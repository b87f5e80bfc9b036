# slurm_cluster.sh: sourced by tests/e2e/simulate_slurm.sh. A one-node Slurm
# (Debian's slurm-wlm 22.05) on localhost, as root, everything in a temp dir:
#   start_slurm DIR   munged, slurmctld and slurmd from DIR's own munge key and
#                     slurm.conf; exports SLURM_CONF; returns 1 (saying why)
#                     when the node does not come up
#   stop_slurm        cancels the cluster's jobs and stops the three daemons
#                     it started and slurmd's slurmstepd children, by their pids
# No accounting (sacct has nothing to say: `atonlab simulate --status` reads
# the files), proctrack/linuxproc and task/none (no cgroups needed).

slurm_pids=()

# A TCP port on 127.0.0.1 nothing listens on, from 20000 up, other than $1.
free_port() {
  python3 - "${1:-0}" <<'PY'
import socket, sys
avoid = int(sys.argv[1])
for port in range(20000, 30000):
    if port == avoid:
        continue
    s = socket.socket()
    try:
        s.bind(("0.0.0.0", port))
    except OSError:
        continue
    finally:
        s.close()
    print(port)
    break
PY
}

start_slurm() {
  local d=$1 host
  host=$(hostname -s)
  mkdir -p "$d/state" "$d/spool" "$d/munge" && chmod 700 "$d/munge"
  head -c 1024 /dev/urandom >"$d/munge/munge.key" && chmod 400 "$d/munge/munge.key"
  munged --force --key-file="$d/munge/munge.key" --socket="$d/munge/munge.socket" \
    --pid-file="$d/munge/munged.pid" --log-file="$d/munge/munged.log" --seed-file="$d/munge/munged.seed" ||
    { echo "munged did not start: $(tail -3 "$d/munge/munged.log" 2>/dev/null)"; return 1; }
  slurm_pids+=("$(cat "$d/munge/munged.pid")")
  local ctld_port slurmd_port
  ctld_port=$(free_port) && slurmd_port=$(free_port "$ctld_port")
  cat >"$d/slurm.conf" <<CONF
# A one-node test cluster (tests/e2e/slurm_cluster.sh)
ClusterName=atonlabtest
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$d/munge/munge.socket
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/slurmctld.log
SlurmdLogFile=$d/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
KillWait=5
MinJobAge=300
SchedulerParameters=sched_interval=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$d/slurm.conf
  slurmctld -D -i -f "$d/slurm.conf" >"$d/slurmctld.stdout" 2>&1 &
  slurm_pids+=("$!")
  slurmd -D -f "$d/slurm.conf" >"$d/slurmd.stdout" 2>&1 &
  slurm_pids+=("$!")
  local i
  for i in $(seq 1 60); do  # up to 30 s for the node to say it is idle
    if sinfo -h -o '%T' 2>/dev/null | grep -qx idle; then return 0; fi
    sleep 0.5
  done
  echo "the test cluster's node did not come up idle: sinfo says '$(sinfo -h -o '%T' 2>&1)'"
  tail -5 "$d/slurmctld.log" "$d/slurmd.log" 2>/dev/null
  return 1
}

stop_slurm() {
  local pid steps=()
  # Jobs still queued (a test that failed mid-way) are cancelled first, and
  # slurmd's slurmstepd children (one per running step) stopped with it, so
  # that nothing of this cluster outlives it.
  if [ ${#slurm_pids[@]} -eq 3 ]; then
    scancel --quiet --user="$(id -un)" 2>/dev/null
    for _ in $(seq 1 40); do [ -z "$(squeue -h 2>/dev/null)" ] && break; sleep 0.25; done
    mapfile -t steps < <(pgrep -P "${slurm_pids[2]}" 2>/dev/null)
  fi
  for pid in "${slurm_pids[@]}" "${steps[@]}"; do kill "$pid" 2>/dev/null; done
  slurm_pids+=("${steps[@]}")
  for pid in "${slurm_pids[@]}"; do
    for _ in $(seq 1 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.25; done
    kill -9 "$pid" 2>/dev/null
  done
  slurm_pids=()
}
