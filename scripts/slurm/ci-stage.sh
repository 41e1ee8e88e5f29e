#!/usr/bin/env bash
# CI's Slurm stage (issue 17): Debian's Slurm on this one machine (munge, a controller and a node
# daemon with a private slurm.conf), then
#   1. scripts/slurm/evaluate.sbatch as a job array (2 shards) and the merge as a job depending on
#      it; the merged tables must equal a single-machine run of the same inputs;
#   2. a one-task array cancelled after its first finished trajectories and submitted again: it
#      resumes (the finished ones are not run again) and its tables equal the same run.
# Needs root (or sudo) and the tool built (BUILD_DIR, default build). Leaves the daemons stopped.
#
#   bash scripts/slurm/ci-stage.sh            # about 3 minutes on 2 cores
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR=${BUILD_DIR:-build}
P="$PWD/$BUILD_DIR/tools/pushgraph"
WORK=${WORK:-$PWD/out/slurm-ci}
SIMULATE=${SIMULATE:-6}
PROTOCOLS=${PROTOCOLS:-table1,fig5,consistency}
[ -x "$P" ] || { echo "ci-stage: no tool at $P (build it first)" >&2; exit 1; }
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)

# --- Slurm and munge from Debian, on this machine only ---------------------------------------
if ! command -v slurmctld > /dev/null || ! command -v munged > /dev/null; then
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends slurm-wlm munge > /dev/null
fi
rm -rf "$WORK"
mkdir -p "$WORK/state/ctld" "$WORK/state/d" "$WORK/logs"
host=$(hostname -s)
memory_mb=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512 ))
export SLURM_CONF="$WORK/slurm.conf"
cat > "$SLURM_CONF" <<EOF
# A one-node cluster for CI (scripts/slurm/ci-stage.sh). No cgroups, no accounting database.
ClusterName=pushgraph-ci
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$WORK/state/ctld
SlurmdSpoolDir=$WORK/state/d
SlurmctldPidFile=$WORK/state/slurmctld.pid
SlurmdPidFile=$WORK/state/slurmd.pid
SlurmctldLogFile=$WORK/logs/slurmctld.log
SlurmdLogFile=$WORK/logs/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MinJobAge=3600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$memory_mb State=UNKNOWN
PartitionName=ci Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF

stop_daemons() {
  "${sudo_cmd[@]}" pkill -x slurmctld 2> /dev/null || true
  "${sudo_cmd[@]}" pkill -x slurmd 2> /dev/null || true
}
trap stop_daemons EXIT
if ! munge -n 2> /dev/null | unmunge > /dev/null 2>&1; then
  "${sudo_cmd[@]}" mkdir -p /run/munge
  "${sudo_cmd[@]}" chown munge:munge /run/munge
  [ -s /etc/munge/munge.key ] || "${sudo_cmd[@]}" runuser -u munge -- /usr/sbin/mungekey --create
  "${sudo_cmd[@]}" runuser -u munge -- /usr/sbin/munged
fi
stop_daemons
"${sudo_cmd[@]}" env SLURM_CONF="$SLURM_CONF" slurmctld -f "$SLURM_CONF" -i
"${sudo_cmd[@]}" env SLURM_CONF="$SLURM_CONF" slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
  state=$(sinfo -h -o %T 2> /dev/null || true)
  [ "$state" = idle ] && break
  sleep 1
done
[ "$state" = idle ] || { echo "ci-stage: the node did not come up ($state)"; tail -20 "$WORK"/logs/*.log; exit 1; }
echo "ci-stage: slurm $(sinfo -V | awk '{print $2}') up, node $host idle ($(nproc) CPUs)"

# Waits for jobs to leave the queue; fails when one did not complete.
wait_jobs() {
  while [ -n "$(squeue -h -j "$1" 2> /dev/null)" ]; do sleep 1; done
  for id in ${1//,/ }; do
    bad=$(scontrol show job "$id" 2> /dev/null | grep -o 'JobState=[A-Z_]*' | grep -v COMPLETED || true)
    [ -z "$bad" ] || { echo "ci-stage: job $id ended $bad"; cat "$WORK"/logs/*.out 2> /dev/null | tail -30; exit 1; }
  done
}
# The tables that must agree (runtime.csv holds wall times, so it cannot).
same_tables() {
  for f in "$1"/*.csv; do
    case "$(basename "$f")" in runtime.csv) continue ;; esac
    cmp -s "$f" "$2/$(basename "$f")" || { echo "ci-stage: $(basename "$f") differs between $1 and $2"; diff "$f" "$2/$(basename "$f")" | head; exit 1; }
  done
  echo "ci-stage: $(ls "$1"/*.csv | grep -vc runtime.csv) tables of $1 equal $2's"
}

cd "$WORK"
export PUSHGRAPH="$P" PROTOCOLS SIMULATE EXTRA="--seed 1"
echo "ci-stage: single-machine run"
"$P" evaluate --simulate "$SIMULATE" --protocol "$PROTOCOLS" --seed 1 -j 2 --out single > logs/single.log 2>&1

# 1. A two-shard job array and the dependent merge.
array=$(OUT=eval sbatch --parsable --array=0-1 --cpus-per-task=1 --mem=1000 --output="logs/slurm-%A_%a.out" \
  "$OLDPWD/scripts/slurm/evaluate.sbatch")
merge=$(sbatch --parsable --dependency="afterok:$array" --cpus-per-task=1 --mem=500 --output="logs/merge-%j.out" \
  --wrap "$P evaluate merge eval/shard-* --out merged")
echo "ci-stage: submitted array $array (2 shards) and merge $merge (afterok:$array)"
wait_jobs "$array,$merge"
same_tables merged single

# 2. Kill one task after its first finished trajectories, submit it again: it resumes.
resume=$(OUT=resume sbatch --parsable --array=0-0 --cpus-per-task=1 --mem=1000 --output="logs/resume-%A_%a.out" \
  "$OLDPWD/scripts/slurm/evaluate.sbatch")
partial=resume/shard-0/rows.jsonl.partial
for _ in $(seq 600); do
  done_rows=$(grep -c '"stats"' "$partial" 2> /dev/null || true)
  [ "${done_rows:-0}" -ge 2 ] && break
  sleep 0.2
done
scancel "$resume"
wait_until_gone() { while [ -n "$(squeue -h -j "$1" 2> /dev/null)" ]; do sleep 1; done; }
wait_until_gone "$resume"
before=$(grep -c '"stats"' "$partial" 2> /dev/null || true)
before=${before:-0}
[ "$before" -ge 1 ] && [ "$before" -lt "$SIMULATE" ] ||
  { echo "ci-stage: the cancelled task had $before of $SIMULATE trajectories (wanted a partial run)"; exit 1; }
echo "ci-stage: cancelled job $resume with $before of $SIMULATE trajectories finished"
again=$(OUT=resume sbatch --parsable --array=0-0 --cpus-per-task=1 --mem=1000 --output="logs/resume-%A_%a.out" \
  "$OLDPWD/scripts/slurm/evaluate.sbatch")
wait_jobs "$again"
grep -q -- "--resume: $before trajectories already done" "logs/resume-${again}_0.out" ||
  { echo "ci-stage: the resubmitted task did not resume from $before finished trajectories"; cat "logs/resume-${again}_0.out"; exit 1; }
"$P" evaluate merge resume/shard-0 --out resume/merged > logs/resume-merge.log 2>&1
same_tables resume/merged single
echo "ci-stage: resubmitted job $again resumed ($before trajectories not run again) and completed"
