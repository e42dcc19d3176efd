#!/usr/bin/env bash
# Submit a study as a Slurm array job (one shard per task) and a report job that runs
# when every task has succeeded.
#
#   deploy/slurm/submit.sh [options] STUDY_FILE OUT_DIR [-- SBATCH_OPTIONS...]
#
# Options:
#   --shards N     array tasks = shards of the study (default 8)
#   --cpus C       cores per task, = hdw threads (default 4)
#   --tasks LIST   array indices to submit (default 1-N), e.g. 3 or 2,7 to run failed or
#                  cancelled tasks again: they resume, and a new report job follows them
#   --time T       time limit of each task (sbatch --time, e.g. 2:00:00)
#   --partition P  partition of both jobs
#   --no-report    submit the array only
# Options after -- go to sbatch for both jobs (e.g. --account=proj --mem-per-cpu=1G).
#
# Run it from a folder that the compute nodes see at the same path (the jobs start there),
# with STUDY_FILE and OUT_DIR on a shared file system. HDW names the hdw binary (default:
# hdw on PATH); it must run on the compute nodes. Logs go to OUT_DIR/logs/.
# Prints the job ids as one line: `array=ID report=ID`.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
die() { echo "submit.sh: $*" >&2; exit 2; }

shards=8 cpus=4 tasks="" time="" partition="" report=1
extra=()
args=()
while [[ $# -gt 0 ]]; do
    case $1 in
        --shards) shards=${2:?--shards needs a number}; shift 2 ;;
        --cpus) cpus=${2:?--cpus needs a number}; shift 2 ;;
        --tasks) tasks=${2:?--tasks needs a list such as 3 or 2,7}; shift 2 ;;
        --time) time=${2:?--time needs a limit such as 2:00:00}; shift 2 ;;
        --partition) partition=${2:?--partition needs a name}; shift 2 ;;
        --no-report) report=0; shift ;;
        --) shift; extra=("$@"); break ;;
        -*) die "unknown option $1 (see the comment at the top of $0)" ;;
        *) args+=("$1"); shift ;;
    esac
done
[[ ${#args[@]} -eq 2 ]] || die "expected STUDY_FILE OUT_DIR, got ${#args[@]} arguments"
study=${args[0]} out=${args[1]}
[[ $shards =~ ^[1-9][0-9]*$ ]] || die "--shards $shards: expected a whole number >= 1"
[[ $cpus =~ ^[1-9][0-9]*$ ]] || die "--cpus $cpus: expected a whole number >= 1"
[[ -f $study ]] || die "study file $study not found (paths are taken from $(pwd))"
hdw=${HDW:-hdw}
command -v "$hdw" >/dev/null || die "hdw binary '$hdw' not found: put hdw on PATH or set HDW=/path/to/hdw"
command -v sbatch >/dev/null || die "sbatch not found: run this on a Slurm login node"

mkdir -p "$out/logs"
common=(--parsable --export=ALL)
[[ -n $partition ]] && common+=(--partition="$partition")
shard_opts=(--array="${tasks:-1-$shards}" --cpus-per-task="$cpus" --output="$out/logs/hdw-shard-%A_%a.out")
[[ -n $time ]] && shard_opts+=(--time="$time")

array_id=$(sbatch "${common[@]}" "${shard_opts[@]}" "${extra[@]}" "$here/hdw-shard.sbatch" "$study" "$out" "$shards")
array_id=${array_id%%;*}
report_id=none
if ((report)); then
    # kill-on-invalid-dep: if a task fails or is cancelled, the report job is removed
    # instead of waiting forever; submit the failed tasks again with --tasks.
    report_id=$(sbatch "${common[@]}" --dependency="afterok:$array_id" --kill-on-invalid-dep=yes \
        --output="$out/logs/hdw-report-%j.out" "${extra[@]}" "$here/hdw-report.sbatch" "$out")
    report_id=${report_id%%;*}
fi
echo "array=$array_id report=$report_id"
