#!/usr/bin/env bash
# Slurm smoke test of the scale-out route (book: scale-out.md), as root on a Debian machine:
#   1. installs slurm-wlm and munge from Debian's packages when they are missing;
#   2. starts a private one-node cluster on loopback (own munge key and socket, own slurm.conf,
#      free ports, state in a temp folder; nothing under /etc is changed);
#   3. runs a tiny transmittance sweep once without Slurm (the single-machine reference), then
#      submits it with submit.sh as a 3-task job array plus a dependent (afterok) merge job;
#   4. checks the merged files equal the single run's byte for byte (summary.csv without its
#      wall-clock columns), then stops the daemons it started and removes its folder.
# MCBENCH=<binary> skips the build (.ci/run passes the binary its tests just built); KEEP=1 keeps
# the temp folder. Exit code 0 only when everything above held.
set -euo pipefail
started=$(date +%s)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
say() { echo "[smoke $(($(date +%s) - started))s] $*"; }
fail() { echo "[smoke] FAILED: $*" >&2; exit 1; }

[[ $(id -u) == 0 ]] || fail "needs root (it starts slurmctld, slurmd and munged)"
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge (apt-get)"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq slurm-wlm munge >/dev/null
fi
say "$(slurmctld -V), $(munged --version 2>&1 | head -n1)"

if [[ -z "${MCBENCH:-}" ]]; then
    say "building mcbench (release)"
    (cd "$repo" && cargo build --release -q -p experiments --bin mcbench)
    MCBENCH="${CARGO_TARGET_DIR:-$repo/target}/release/mcbench"
fi
MCBENCH=$(realpath "$MCBENCH")
[[ -x "$MCBENCH" ]] || fail "no mcbench binary at $MCBENCH"
export MCBENCH

work=$(mktemp -d /tmp/mcbench-slurm.XXXXXX)
chmod 755 "$work"
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
    if [[ "${KEEP:-0}" == 1 ]]; then echo "[smoke] kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

free_port() {
    local p
    for _ in $(seq 50); do
        p=$(shuf -i 20000-60000 -n 1)
        if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then echo "$p"; return; fi
    done
    fail "no free port"
}

# munge: a private daemon with its own key and socket.
mkdir -p "$work/munge"
chmod 711 "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge/munge.key"
munged -F --force --key-file="$work/munge/munge.key" --socket="$work/munge/munge.sock" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/munged.seed" >"$work/munge/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [[ -S "$work/munge/munge.sock" ]] && break; sleep 0.1; done
[[ -S "$work/munge/munge.sock" ]] || fail "munged did not start: $(cat "$work/munge/munged.log" 2>/dev/null)"

# Slurm: one node ("smoke") on 127.0.0.1 with this machine's cores.
ctld_port=$(free_port)
slurmd_port=$(free_port)
[[ "$ctld_port" != "$slurmd_port" ]] || slurmd_port=$((ctld_port + 1))
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
cat >"$SLURM_CONF" <<CONF
ClusterName=mcbench-smoke
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.sock
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=600
NodeName=smoke NodeHostname=localhost NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=smoke Nodes=smoke Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -D -i >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N smoke >"$work/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 120); do
    state=$(sinfo -h -n smoke -o %T 2>/dev/null || true)
    [[ "$state" == idle* ]] && break
    sleep 0.5
done
[[ "${state:-}" == idle* ]] || fail "node not idle (state '${state:-}'): $(tail -n 5 "$work/slurmctld.log" "$work/slurmd.log" 2>&1)"
say "cluster up: node smoke idle, slurmctld on port $ctld_port"

# The sweep: transmittance (its claims and post hook) on two tiny beds, 40 repetitions = 3 blocks
# per cell, so the shards split repetitions as well as cells.
cat >"$work/tiny.toml" <<'TOML'
budgets = [10, 20, 40]
[[testbeds]]
id = "eq21-medium"
variant = "transmittance"
params = { resolution = 4 }
[[testbeds]]
id = "eq21-medium"
variant = "central-ray"
TOML
run=(transmittance --config "$work/tiny.toml" --reps 40)
(cd "$work" && "$MCBENCH" run "${run[@]}" --threads 2 --results single/results --plots single/plots >single.log 2>&1) ||
    fail "single run: $(tail -n 3 "$work/single.log")"
say "single-machine run done"

cd "$work"
export MCBENCH_RESULTS="$work/sharded/results" MCBENCH_PLOTS="$work/sharded/plots"
read -r array merge < <("$here/submit.sh" 3 transmittance "${run[@]}")
say "submitted array job $array (3 shards) and merge job $merge (afterok:$array)"
job_state() { scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | sort -u | cut -d= -f2 | paste -sd, -; }
for _ in $(seq 600); do
    m=$(job_state "$merge")
    [[ "$m" == COMPLETED || "$m" == *FAIL* || "$m" == CANCELLED* || "$m" == TIMEOUT ]] && break
    [[ "$(job_state "$array")" == *FAIL* ]] && break
    sleep 0.5
done
say "array job $array: $(job_state "$array"); merge job $merge: $(job_state "$merge")"
if [[ "$(job_state "$merge")" != COMPLETED ]]; then
    tail -n 5 "$work"/mcbench-*.out "$work/slurmctld.log" 2>&1 || true
    fail "merge job did not complete"
fi
for i in 1 2 3; do
    say "shard task $i: $(grep -h "shard $i/3" "$work"/mcbench-shard-"${array}"_*.out)"
done
grep -h '^merged results' "$work/mcbench-merge-$merge.out" | sed 's/^/[smoke] /'

# The check: merged == single, byte for byte, wall-clock columns aside.
s="$work/single/results/transmittance" m="$work/sharded/results/transmittance"
cmp <(zcat "$s/integrals.csv.gz") <(zcat "$m/integrals.csv.gz") || fail "integrals.csv differs between the merged and the single run"
say "integrals.csv.gz: identical text ($(zcat "$m/integrals.csv.gz" | wc -l) lines)"
for f in fig8_bands.csv; do
    cmp "$s/$f" "$m/$f" || fail "$f differs between the merged and the single run"
    say "$f: identical ($(wc -l <"$m/$f") lines)"
done
python3 - "$s" "$m" <<'PY' || fail "summary.csv or summary.json differ beyond wall-clock fields"
import csv, json, sys
timing = {"seconds", "efficiency", "seconds_median", "efficiency_mse", "p_eff", "wall_seconds", "overhead", "speedup", "run_id",
          "cpu_seconds", "efficiency_wall", "overhead_wall", "speedup_wall", "cpu_seconds_total",
          "efficiency_renderer", "speedup_ci_low", "speedup_ci_high", "overhead_renderer", "speedup_renderer",
          "speedup_renderer_ci_low", "speedup_renderer_ci_high", "break_even_ray_ns"}
def table(d):
    rows = list(csv.reader(open(d + "/summary.csv")))
    keep = [i for i, h in enumerate(rows[0]) if h not in timing]
    return [[r[i] for i in keep] for r in rows]
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in timing}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
a, b = sys.argv[1], sys.argv[2]
assert table(a) == table(b), "summary.csv differs"
ja, jb = (strip(json.load(open(d + "/summary.json"))) for d in (a, b))
assert ja == jb, "summary.json differs"
print(f"[smoke] summary.csv: identical without wall-clock columns ({len(table(b)) - 1} rows); "
      f"summary.json: identical without wall-clock fields ({len(jb['paper'])} claims, {len(jb['tests'])} tests)")
PY
say "PASSED: 3 Slurm shards + merge == single run"
