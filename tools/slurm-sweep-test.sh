#!/usr/bin/env bash
# Runs a parameter sweep on a real single-node Slurm on this machine, exactly as
# docs/sweeps.md tells users (--count, a job array of --index tasks, a dependent --collect
# job), and checks that its rows and digests equal those of a local `papertear sweep` of the
# same file. Installs Debian's slurm-wlm and munge when missing; writes its slurm.conf, munge
# key, state and logs in a temporary directory; starts munged, slurmctld and slurmd, and
# stops them again. Ends with one verdict line; exit 0 when the two sweeps agree.
#
#   PAPERTEAR=path/to/papertear bash tools/slurm-sweep-test.sh   # default: build/release/tools/papertear
# Needs root (the daemons; without it: exit 77, skipped). SLURM_TEST_KEEP=1 keeps the directory.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

say() { echo "slurm-sweep-test: $*"; }
verdict_fail() { echo "slurm-sweep-test: FAIL: $*"; exit 1; }

papertear=$(realpath "${PAPERTEAR:-build/release/tools/papertear}")
[[ -x $papertear ]] || verdict_fail "no papertear binary at $papertear (build it or set PAPERTEAR)"
if [[ $(id -u) -ne 0 ]]; then
  echo "slurm-sweep-test: SKIP: needs root (it installs Slurm and starts slurmctld, slurmd, munged)"
  exit 77  # CTest's SKIP_RETURN_CODE
fi

install_missing() {
  local missing=()
  command -v slurmctld >/dev/null || missing+=(slurmctld)
  command -v slurmd >/dev/null || missing+=(slurmd)
  command -v sbatch >/dev/null || missing+=(slurm-client)
  command -v munged >/dev/null || missing+=(munge)
  [[ ${#missing[@]} -eq 0 ]] && return
  say "installing slurm-wlm munge (missing: ${missing[*]})"
  export DEBIAN_FRONTEND=noninteractive
  apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null ||
    { apt-get update >/dev/null && apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null; }
}
install_missing

work=$(mktemp -d /tmp/papertear-slurm.XXXXXX)
chmod 700 "$work"
pids=()
cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  if [[ ${SLURM_TEST_KEEP:-0} == 1 ]]; then say "kept $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 1' INT TERM  # so that the EXIT trap stops the daemons on Ctrl-C or a timeout too

# Ports away from the defaults (6817/6818), so a Slurm already on this machine is not hit.
ctld_port=$((20000 + RANDOM % 20000))
node=$(hostname -s)
cpus=$(nproc)

start_munge() {
  mkdir -p "$work/munge"
  chmod 700 "$work/munge"
  dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$work/munge/munge.key"
  munged --force --foreground --key-file="$work/munge/munge.key" --socket="$work/munge/munge.socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/munged.seed" >"$work/munge/stderr.log" 2>&1 &
  pids+=($!)
}

write_slurm_conf() {
  mkdir -p "$work/state" "$work/spool" "$work/log"
  cat >"$work/slurm.conf" <<EOF
ClusterName=papertear-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$((ctld_port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool/slurmd-%n
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
MinJobAge=600
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
}

start_slurm() {
  export SLURM_CONF="$work/slurm.conf"
  slurmctld -D -f "$SLURM_CONF" >"$work/log/slurmctld.stderr" 2>&1 &
  pids+=($!)
  slurmd -D -f "$SLURM_CONF" >"$work/log/slurmd.stderr" 2>&1 &
  pids+=($!)
  local i
  for i in $(seq 60); do
    [[ $(sinfo -h -o %T 2>/dev/null) == idle ]] && return
    sleep 1
  done
  tail -5 "$work/log/slurmctld.log" "$work/log/slurmd.log" >&2 || true
  verdict_fail "the Slurm node did not come up idle within 60 s"
}

# The sweep: 2 fibre lengths x 2 seeds = 4 points of a small tearing sheet.
write_study() {
  mkdir -p "$work/submit" "$work/bin"
  ln -s "$papertear" "$work/bin/papertear"
  cat >"$work/submit/study.toml" <<'EOF'
seeds = [1, 2]

[set]
sheet.cells = [24, 16, 2]
run.steps = 200
run.frames = 4

[grid]
material.fiber_length = [2.0, 4.0]
EOF
  # docs/sweeps.md's study.sbatch, with this test's output directory and one CPU per task.
  cat >"$work/submit/study.sbatch" <<EOF
#!/bin/bash
#SBATCH --job-name=papertear-study
#SBATCH --cpus-per-task=1
#SBATCH --time=00:30:00
#SBATCH --array=0-3
papertear sweep study.toml --index "\$SLURM_ARRAY_TASK_ID" --out $work/shared/study \\
  --threads "\$SLURM_CPUS_PER_TASK" --quiet
EOF
}

job_state() { scontrol -o show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | sort -u | tr '\n' ' '; }

submit_and_wait() {
  cd "$work/submit"
  export PATH="$work/bin:$PATH"
  local n collect i state
  n=$(papertear sweep study.toml --count)
  jobid=$(sbatch --parsable --array=0-$((n - 1)) study.sbatch)
  collect=$(sbatch --parsable --dependency=afterany:"$jobid" --wrap "papertear sweep study.toml --collect $work/shared/study")
  say "submitted $n points as job array $jobid, collect job $collect"
  for i in $(seq 240); do
    state=$(job_state "$collect")
    case $state in
      *COMPLETED*) cd - >/dev/null; points=$n; return ;;
      *FAILED*|*CANCELLED*|*TIMEOUT*|*NODE_FAIL*)
        cat "$work"/submit/slurm-*.out >&2 || true
        verdict_fail "the collect job ended $state" ;;
    esac
    sleep 0.5
  done
  verdict_fail "the jobs did not finish within 120 s (array: $(job_state "$jobid"))"
}

compare() {
  local n=$1 jobid=$2 slurm=$work/shared/study local_dir=$work/local
  papertear sweep "$work/submit/study.toml" --out "$local_dir" --quiet >"$work/local.log" 2>&1 ||
    verdict_fail "the local sweep failed: $(tail -1 "$work/local.log")"
  [[ -f $slurm/sweep.csv ]] || verdict_fail "the collect job wrote no sweep.csv"
  cmp -s "$slurm/sweep.csv" "$local_dir/sweep.csv" || {
    diff "$slurm/sweep.csv" "$local_dir/sweep.csv" >&2 || true
    verdict_fail "Slurm's sweep.csv differs from the local sweep's"
  }
  local rows digests
  rows=$(($(wc -l <"$slurm/sweep.csv") - 1))
  [[ $rows -eq $n ]] || verdict_fail "sweep.csv has $rows rows, not $n"
  # The digest each array task printed last, against the local rows' digest column.
  digests=$(for i in $(seq 0 $((n - 1))); do tail -1 "$work/submit/slurm-${jobid}_$i.out"; done |
    sed -n 's/^digest: //p' | paste -sd' ')
  local col
  col=$(head -1 "$local_dir/sweep.csv" | tr ',' '\n' | grep -nx digest | cut -d: -f1)
  [[ $digests == "$(tail -n +2 "$local_dir/sweep.csv" | cut -d, -f"$col" | paste -sd' ')" ]] ||
    verdict_fail "the tasks' digests ($digests) differ from the local sweep's"
  echo "slurm-sweep-test: PASS: $n points as Slurm job array $jobid: rows and digests equal the local sweep's ($digests)"
}

start_munge
write_slurm_conf
start_slurm
write_study
points=0 jobid=
submit_and_wait  # sets points and jobid
compare "$points" "$jobid"
