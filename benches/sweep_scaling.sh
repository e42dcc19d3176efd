#!/usr/bin/env bash
# Wall time of `hdw study` on the table4 study, whole and per part, with 1 and 2 threads.
# Usage: benches/sweep_scaling.sh [path/to/hdw]   (default: a release build of hd-cli)
set -euo pipefail
cd "$(dirname "$0")/.."
HDW=${1:-}
if [ -z "$HDW" ]; then
  cargo build --release -q -p hd-cli
  HDW=target/release/hdw
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() { # label, args...
  local label=$1; shift
  local t0 t1
  t0=$(date +%s.%N)
  "$HDW" study studies/table4.toml --no-report --out "$out/$label" "$@" 2>/dev/null
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }'
}
printf '%-28s %10s %10s %8s\n' "case" "1 thread" "2 threads" "speed-up"
for part in damped-sine all; do
  if [ "$part" = all ]; then args=(); n=6400; else args=(--part "$part"); n=1600; fi
  t1=$(run "$part-1" --threads 1 "${args[@]}")
  t2=$(run "$part-2" --threads 2 "${args[@]}")
  awk -v p="$part" -v a="$t1" -v b="$t2" -v n="$n" \
    'BEGIN { printf "%-28s %9.2fs %9.2fs %7.2fx   (%d runs, %.0f runs/s on 2 threads)\n", p, a, b, a / b, n, n / b }'
done
