#!/usr/bin/env bash
# End-to-end test of deploy/slurm on a real (one-node) Slurm cluster. Needs root and the
# distribution's slurm-wlm and munge packages (installed if missing); not part of
# `cargo test`. Run it with `just slurm-test` or directly:
#
#   tests/slurm/run.sh                         # builds hdw in release first (slow from cold)
#   HDW=target/debug/hdw tests/slurm/run.sh    # any hdw binary
#
# 1. Table 4 (studies/table4.toml) as an array of 4 shards plus the dependent report job;
#    the merged runs must equal a one-machine `hdw study` of the same file (same run ids,
#    identical metric values) and report.md and every plot must be byte-identical.
# 2. tests/slurm/resume-study.toml as 4 shards; task 2 is cancelled (scancel) after it has
#    committed some runs, the report job is then dropped by Slurm; task 2 is submitted
#    again with the same command and must resume (skip the committed runs); the final
#    report must hold every run exactly once, equal to a one-machine run.
# The cluster is stopped at the end, pass or fail. WORK (default /tmp/hdw-slurm-test)
# holds the outputs and logs.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
say() { echo "run.sh [$(($(date +%s) - t0)) s]: $*" >&2; }
fail() {
    echo "run.sh: FAIL: $*" >&2
    exit 1
}
t0=$(date +%s)
[[ $EUID -eq 0 ]] || fail "needs root (it starts the Slurm and munge daemons)"

if [[ -z ${HDW:-} ]]; then
    say "building hdw (release); set HDW=path to use a built binary"
    cargo build --release -p hd-cli
    HDW=${CARGO_TARGET_DIR:-$root/target}/release/hdw
fi
HDW=$(realpath "$HDW")
export HDW
[[ -x $HDW ]] || fail "HDW=$HDW is not an executable"
command -v jq >/dev/null || apt-get install -y --no-install-recommends jq >/dev/null ||
    fail "jq is needed and could not be installed"
work=${WORK:-/tmp/hdw-slurm-test}
rm -rf "$work"
mkdir -p "$work"
cluster=$root/deploy/slurm/local-cluster.sh
submit=$root/deploy/slurm/submit.sh
jobs_seen=()

trap '"$cluster" stop || true' EXIT
"$cluster" start

# Wait until none of the given jobs is queued or running (at most 30 min).
wait_jobs() {
    local ids
    ids=$(
        IFS=,
        echo "$*"
    )
    for _ in $(seq 1800); do
        [[ -z $(squeue -h -j "$ids" 2>/dev/null) ]] && return 0
        sleep 1
    done
    fail "jobs $ids still queued after 30 min"
}

# The state of each task of job $1, one line each.
states() { scontrol -o show job "$1" | grep -oE 'JobState=[A-Z_]+'; }

# Fail unless every task of job $1 ended in state $2.
expect_state() {
    local bad
    bad=$(scontrol -o show job "$1" | grep -v "JobState=$2 " || true)
    [[ -z $bad ]] || fail "job $1: expected every task $2, got: $(echo "$bad" | grep -oE '(JobId|ArrayTaskId|JobState)=[^ ]+' | tr '\n' ' ')"
}

# The runs of DIR/runs.parquet as CSV: id, index, status and every kept metric, by id.
runs_csv() {
    local metrics
    metrics=$(jq -r '.metrics | map(. + ":max") | join(",")' "$1/study.json")
    "$HDW" explore "$1/runs.parquet" --group-by run_id,run_index,status --agg "$metrics" --format csv
}

# DIR A and DIR B hold the same runs (ids, indices, status, metric values to the bit) and
# the same report.md and plots.
same_results() {
    runs_csv "$1" >"$work/a.csv"
    runs_csv "$2" >"$work/b.csv"
    local n
    n=$(($(wc -l <"$work/a.csv") - 1))
    [[ $n -gt 0 ]] || fail "$1/runs.parquet has no runs"
    diff -q "$work/a.csv" "$work/b.csv" >/dev/null || fail "runs differ between $1 and $2: diff $work/a.csv $work/b.csv"
    awk -F, 'NR > 1 && $4 != 1 { bad = 1 } END { exit bad }' "$work/b.csv" || fail "$2: a run_id appears more than once"
    cmp -s "$1/report.md" "$2/report.md" || fail "report.md differs: diff $1/report.md $2/report.md"
    local plots=0 f
    for f in "$1"/*.svg; do
        cmp -s "$f" "$2/$(basename "$f")" || fail "plot $(basename "$f") differs between $1 and $2"
        plots=$((plots + 1))
    done
    [[ $(find "$2" -maxdepth 1 -name '*.svg' | wc -l) -eq $plots ]] || fail "$2 has other plots than $1"
    say "same results: $n runs (ids, status, every metric), report.md and $plots plots identical"
}

submit_ids() { # parse "array=ID report=ID"
    array=$(sed -E 's/.*array=([0-9]+).*/\1/' <<<"$1")
    report=$(sed -E 's/.*report=([0-9]+).*/\1/' <<<"$1")
    [[ $array =~ ^[0-9]+$ && $report =~ ^[0-9]+$ ]] || fail "submit.sh printed '$1'"
    jobs_seen+=("array $array" "report $report")
}

# ---- 1. Table 4: sharded on Slurm against one machine --------------------------------
say "1. Table 4 on one machine (reference)"
"$HDW" study studies/table4.toml --out "$work/t4-single" 2>"$work/t4-single.log"
say "1. Table 4 as an array of 4 shards + report job"
submit_ids "$("$submit" --shards 4 --cpus 1 studies/table4.toml "$work/t4-slurm")"
say "submitted array $array, report $report"
wait_jobs "$array" "$report"
expect_state "$array" COMPLETED
expect_state "$report" COMPLETED
say "array $array: $(states "$array" | wc -l) tasks COMPLETED; report $report COMPLETED"
same_results "$work/t4-single" "$work/t4-slurm"

# ---- 2. Cancel one task mid-run, submit it again -------------------------------------
study=tests/slurm/resume-study.toml
out=$work/resume-slurm
say "2. $study on one machine (reference)"
"$HDW" study "$study" --out "$work/resume-single" 2>"$work/resume-single.log"
planned=$(jq '.runs | length' "$work/resume-single/study.json")
per_shard=$((planned / 4))
submit_ids "$("$submit" --shards 4 --cpus 1 "$study" "$out")"
first_array=$array first_report=$report
say "submitted array $array, report $report; waiting for task 2 to commit runs"
committed_parts() { find "$out/parts" -name 'runs-shard-2-of-4-*.parquet' 2>/dev/null | wc -l; }
for _ in $(seq 600); do
    [[ -f $out/runs-shard-2-of-4.parquet ]] && fail "task 2 finished before it could be cancelled (make the study longer)"
    [[ $(committed_parts) -ge 2 ]] && break
    sleep 0.2
done
[[ $(committed_parts) -ge 2 ]] || fail "task 2 committed nothing within 2 min"
scancel "${array}_2"
say "cancelled ${array}_2 after $(committed_parts) committed parts"
wait_jobs "$array" "$report"
task2=$(scontrol -o show job "${array}_2" | grep -oE 'JobState=[A-Z_]+')
[[ $task2 == JobState=CANCELLED ]] || fail "task ${array}_2: expected CANCELLED, got $task2"
for k in 1 3 4; do expect_state "${array}_$k" COMPLETED; done
[[ ! -f $out/report.md ]] || fail "the report ran although task 2 was cancelled"
[[ ! -f $out/runs-shard-2-of-4.parquet ]] || fail "shard 2 has a final table although it was cancelled"
kept=$("$HDW" explore "$out/parts/runs-shard-2-of-4-*.parquet" --group-by part --format csv | awk -F, 'NR == 2 { print $2 }')
[[ $kept -gt 0 && $kept -lt $per_shard ]] || fail "shard 2 kept $kept of $per_shard runs when cancelled"
say "task 2 CANCELLED with $kept of $per_shard runs committed; tasks 1, 3, 4 COMPLETED; report $report dropped ($(scontrol -o show job "$report" 2>/dev/null | grep -oE 'JobState=[A-Z_]+ Reason=[A-Za-z]+' || echo 'no longer listed'))"

submit_ids "$("$submit" --shards 4 --cpus 1 --tasks 2 "$study" "$out")"
say "submitted task 2 again: array $array, report $report"
wait_jobs "$array" "$report"
expect_state "$array" COMPLETED
expect_state "$report" COMPLETED
log=$out/logs/hdw-shard-${array}_2.out
grep -q "$per_shard runs (shard 2/4 of $planned), $kept already done, $((per_shard - kept)) to run" "$log" ||
    fail "task 2 did not resume from its $kept committed runs: $(grep "already done" "$log")"
report_log=$out/logs/hdw-report-$report.out
grep -q "$planned rows, 0 duplicate rows" "$report_log" || fail "duplicates in the shards: $(grep rows "$report_log")"
grep -q "$planned of $planned planned runs" "$report_log" || fail "runs lost: $(tail -n 1 "$report_log")"
say "task 2 resumed: $kept already done, $((per_shard - kept)) run; report: $planned rows, 0 duplicates, 0 missing"
same_results "$work/resume-single" "$out"

"$cluster" stop
trap - EXIT
say "PASS in $(($(date +%s) - t0)) s; jobs: ${jobs_seen[*]} (cancelled: ${first_array}_2, dropped: $first_report)"
