#!/usr/bin/env bash
# A single-node Slurm for tests and benchmarks, sourced (not run): `slurm_node_start WORK` starts
# munged, slurmctld and slurmd in the foreground as children of the calling script, with every
# file under WORK/slurm and WORK/munge, a node of this machine's CPUs, and a partition "main";
# it exports SLURM_CONF. `slurm_node_stop` cancels what is queued and stops the daemons. The
# caller defines `fail MESSAGE` (print and exit). WORK and every folder above it must be
# reachable by all (munged checks its socket's folders): a fresh folder in /tmp is.
slurm_node_pids=()

slurm_node_stop() {
  if [ -n "${SLURM_CONF:-}" ] && [ -f "$SLURM_CONF" ]; then
    scancel --full --signal=KILL --user=root >/dev/null 2>&1 || true
    for _ in $(seq 1 20); do
      [ -z "$(squeue -h 2>/dev/null)" ] && break
      sleep 0.5
    done
  fi
  for pid in "${slurm_node_pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${slurm_node_pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  slurm_node_pids=()
}

slurm_node_start() {
  local work=$1 cpus socket
  cpus=$(nproc)
  # munge: a root-owned key of mode 0600, a socket folder of mode 0755.
  mkdir -p "$work/munge" "$work/slurm/state" "$work/slurm/spool"
  chmod 755 "$work" "$work/munge"
  dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
  chmod 600 "$work/munge/munge.key"
  socket="$work/munge/munge.socket"
  munged -F --key-file="$work/munge/munge.key" --socket="$socket" --pid-file="$work/munge/munged.pid" \
    --log-file="$work/slurm/munged.log" --seed-file="$work/munge/munged.seed" >/dev/null 2>&1 &
  slurm_node_pids+=($!)

  export SLURM_CONF="$work/slurm/slurm.conf"
  cat > "$SLURM_CONF" <<CONF
ClusterName=sinmdmtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=16917
SlurmdPort=16918
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$work/slurm/state
SlurmdSpoolDir=$work/slurm/spool
SlurmctldPidFile=$work/slurm/slurmctld.pid
SlurmdPidFile=$work/slurm/slurmd.pid
SlurmctldLogFile=$work/slurm/slurmctld.log
SlurmdLogFile=$work/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/filetxt
JobCompLoc=$work/slurm/jobcomp.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
KillWait=5
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=16000 State=UNKNOWN
PartitionName=main Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
  for _ in $(seq 1 50); do [ -S "$socket" ] && break; sleep 0.1; done
  [ -S "$socket" ] || fail "munged did not start"
  slurmctld -D -f "$SLURM_CONF" >/dev/null 2>&1 &
  slurm_node_pids+=($!)
  slurmd -D -f "$SLURM_CONF" >/dev/null 2>&1 &
  slurm_node_pids+=($!)
  for _ in $(seq 1 60); do
    sinfo -h -o %t 2>/dev/null | grep -q idle && break
    sleep 0.5
  done
  sinfo -h -o %t 2>/dev/null | grep -q idle || fail "the node did not come up"
  echo "slurm: up"
}
