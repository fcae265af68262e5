#!/usr/bin/env bash
# `make test-cluster`: the cluster path run on a real Slurm. Installs Debian's slurm-wlm and
# munge when missing, starts a throw-away single-node cluster (munged, slurmctld, slurmd on
# this host, every file under one temp directory, ports of its own), submits
# deploy/slurm/build-city.sbatch as a 4-task array over a synthetic town and
# deploy/slurm/merge-city.sbatch after it (--dependency=afterok), waits with a timeout, and
# checks the merged city is byte-identical to a single full build. Every daemon it started is
# stopped by its pid on the way out, whether the run passed or not.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
LOTS=${EDO_CITY_CLUSTER_LOTS:-3000}
TIMEOUT=${EDO_CITY_CLUSTER_TIMEOUT:-600}

if [ -z "${EDO_CITY_CLUSTER_BIN:-}" ]; then
  # The debug binary `make test` has just built: a release build would add minutes to CI
  # for a town that takes seconds either way.
  cargo build --quiet
  export EDO_CITY_CLUSTER_BIN=$ROOT/target/debug/edo-city
fi
BIN=$EDO_CITY_CLUSTER_BIN
# slurmd runs the jobs as root here (SlurmUser=root): go on through sudo when not root.
if [ "$(id -u)" != 0 ]; then
  exec sudo --preserve-env=EDO_CITY_CLUSTER_BIN,EDO_CITY_CLUSTER_LOTS,EDO_CITY_CLUSTER_TIMEOUT \
    bash "$0" "$@"
fi

# shellcheck source=scripts/apt-install.sh
. scripts/apt-install.sh
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
  || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  echo "test-cluster: installing slurm-wlm and munge (Debian)"
  apt_install slurm-wlm munge
fi

T=$(mktemp -d /tmp/edo-city-slurm.XXXXXX)
PIDS=()
stop_all() {
  local rc=$?
  for pid in "${PIDS[@]}"; do
    kill "$pid" 2>/dev/null || true
  done
  for pid in "${PIDS[@]}"; do
    for _ in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "$pid" 2>/dev/null || true
  done
  if [ "$rc" != 0 ]; then
    echo "test-cluster: FAILED; the daemons' logs:" >&2
    for f in "$T"/log/* "$T"/jobs/*; do
      [ -f "$f" ] && { echo "--- $f" >&2; tail -n 30 "$f" >&2; }
    done
  fi
  rm -rf "$T"
  exit "$rc"
}
trap stop_all EXIT
trap 'exit 130' INT TERM

mkdir -p "$T"/{log,state,spool,munge,jobs}
chmod 755 "$T"
chmod 755 "$T/munge"
HOST=$(hostname -s)
# Ports of our own, so a real Slurm on this machine is left alone.
CTLD_PORT=$((20000 + RANDOM % 20000))
SLURMD_PORT=$((CTLD_PORT + 1))
CPUS=$(nproc)

# Munge: a random key and a socket of our own.
head -c 1024 /dev/urandom >"$T/munge/munge.key"
chmod 400 "$T/munge/munge.key"
munged --force --key-file="$T/munge/munge.key" --socket="$T/munge/munge.socket" \
  --pid-file="$T/munge/munged.pid" --log-file="$T/log/munged.log" \
  --seed-file="$T/munge/munged.seed"
for _ in $(seq 50); do [ -s "$T/munge/munged.pid" ] && break; sleep 0.1; done
PIDS+=("$(cat "$T/munge/munged.pid")")

cat >"$T/slurm.conf" <<EOF
ClusterName=edocity
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/munge.socket
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SchedulerParameters=kill_invalid_depend
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
SlurmdTimeout=60
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=4096 State=UNKNOWN
PartitionName=edocity Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$T/slurm.conf

slurmctld -D -i -f "$SLURM_CONF" >"$T/log/slurmctld.out" 2>&1 &
PIDS+=("$!")
slurmd -D -f "$SLURM_CONF" -N "$HOST" >"$T/log/slurmd.out" 2>&1 &
PIDS+=("$!")

# Wait for the node to be idle.
for i in $(seq 120); do
  state=$(sinfo -h -n "$HOST" -o %t 2>/dev/null || true)
  [ "$state" = idle ] && break
  if [ "$i" = 120 ]; then
    echo "test-cluster: the node never came up (state '$state')" >&2
    exit 1
  fi
  sleep 0.5
done
echo "test-cluster: $(sinfo -V) on $HOST, $CPUS CPUs"

# The town, and the single full build to compare with.
"$BIN" synth --lots "$LOTS" --seed 3 "$T/town" >/dev/null
printf 'seed = 3\n' >"$T/hypothesis.toml"
"$BIN" build "$T/town" --params "$T/hypothesis.toml" --out "$T/full" --quiet

export EDO_CITY=$BIN EDO_CITY_INPUT=$T/town EDO_CITY_PARAMS=$T/hypothesis.toml \
  EDO_CITY_OUT=$T/out
ARRAY=$(sbatch --parsable --array=1-4 --cpus-per-task=1 --mem=1G \
  --output="$T/jobs/%x-%A_%a.out" deploy/slurm/build-city.sbatch)
MERGE=$(sbatch --parsable --dependency="afterok:$ARRAY" --mem=1G \
  --output="$T/jobs/%x-%j.out" deploy/slurm/merge-city.sbatch)
echo "test-cluster: array job $ARRAY (4 shards), merge job $MERGE after it"

deadline=$((SECONDS + TIMEOUT))
while squeue -h -j "$ARRAY,$MERGE" 2>/dev/null | grep -q .; do
  if [ "$SECONDS" -ge "$deadline" ]; then
    echo "test-cluster: jobs still queued or running after ${TIMEOUT}s:" >&2
    squeue >&2 || true
    exit 1
  fi
  # A failed shard leaves the merge waiting on a dependency that can never be met.
  if squeue -h -j "$MERGE" -o %r 2>/dev/null | grep -q DependencyNeverSatisfied; then
    echo "test-cluster: a shard failed, so the merge can never run" >&2
    scancel "$MERGE" || true
    exit 1
  fi
  sleep 1
done
for f in "$T"/jobs/*.out; do echo "--- $(basename "$f")"; cat "$f"; done

# Every shard and the merge completed, and the merged city is the full build to the byte.
state=$(scontrol show job "$MERGE" 2>/dev/null | grep -o 'JobState=[A-Z]*' || true)
if [ ! -f "$T/out/manifest.json" ]; then
  echo "test-cluster: the merge wrote no manifest ($state)" >&2
  exit 1
fi
if ! diff -r "$T/full" "$T/out" >"$T/log/diff.txt"; then
  echo "test-cluster: the merged city differs from the full build:" >&2
  head -n 20 "$T/log/diff.txt" >&2
  exit 1
fi
echo "test-cluster: $LOTS lots in 4 Slurm array tasks + merge: byte-identical to the full build"
