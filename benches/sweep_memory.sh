#!/usr/bin/env bash
# Peak memory and speed of large sweeps (issue #18, item 4), for one hdw binary:
#   benches/sweep_memory.sh [HDW] [SIZES]      e.g. benches/sweep_memory.sh target/release/hdw "10000 100000"
# - a tiny linear-variant study (24 V, 1 kHz sine, t_end 4 ms) on a K̄ × Jz grid with
#   --no-report at each size: peak RSS (/usr/bin/time -v), wall time, runs per second;
# - a 10⁶ × 10⁶ grid: time to refuse, exit code, stderr;
# - --shard 1/100000 of a 10⁴ × 10⁴ (10⁸-run) grid: time until its first line and in all.
# Set REPORT=1 to also run the 1000 × 1000 grid with its report and list the plot sizes.
set -u
HDW=${1:-target/release/hdw}
SIZES=${2:-"10000 100000 400000 1000000"}
W=$(mktemp -d /tmp/sweep-memory.XXXX)
grid() { # name nk nj
cat > "$W/$1.toml" <<TOML
name = "$1"
[base]
variant = "linear"
t_end = 0.004
[input]
kind = "sine"
voltage = 24.0
freq = 1000.0
[metrics]
keep = ["thz_amp", "thz_ripple"]
[[axis]]
name = "Kbar"
logspace = { start = 1e4, stop = 1e6, num = $2 }
[[axis]]
name = "Jz"
logspace = { start = 1e-4, stop = 1e-2, num = $3 }
TOML
}
echo "binary: $HDW"
for n in $SIZES; do
  nj=100; nk=$((n / nj))
  grid "s$n" $nk $nj
  /usr/bin/time -v "$HDW" study "$W/s$n.toml" --out "$W/o$n" --no-report 2> "$W/t$n.log" > /dev/null
  rss=$(awk '/Maximum resident/ {print $6}' "$W/t$n.log")
  wall=$(awk '/Elapsed \(wall/ {print $8}' "$W/t$n.log")
  rate=$(grep -o '[0-9]* runs/s' "$W/t$n.log" | head -1)
  size=$(stat -c %s "$W/o$n/runs.parquet" 2>/dev/null || echo "-")
  printf "%8d runs: peak RSS %7.1f MiB, wall %s, %s, runs.parquet %s bytes\n" "$n" "$(echo "$rss/1024" | bc -l)" "$wall" "$rate" "$size"
  rm -rf "$W/o$n"
done
grid huge 1000000 1000000
s=$(date +%s.%N); "$HDW" study "$W/huge.toml" --out "$W/ohuge" 2> "$W/huge.err"; code=$?; e=$(date +%s.%N)
printf "10^6 x 10^6 grid: exit %d after %.2f s; stderr (%d lines): %s\n" $code "$(echo "$e-$s" | bc -l)" "$(wc -l < "$W/huge.err")" "$(head -c 300 "$W/huge.err")"
grid big 10000 10000
s=$(date +%s.%N)
"$HDW" study "$W/big.toml" --out "$W/obig" --shard 1/100000 --no-report 2>&1 | while IFS= read -r -d $'\r' line || [ -n "$line" ]; do
  case "$line" in *"to run on"*) printf "10^8 grid, shard 1/100000: announced after %.2f s: %s\n" "$(echo "$(date +%s.%N)-$s" | bc -l)" "$(echo "$line" | head -1)";; esac
done
printf "10^8 grid, shard 1/100000: finished after %.2f s\n" "$(echo "$(date +%s.%N)-$s" | bc -l)"
if [ "${REPORT:-0}" = 1 ]; then
  grid r1000 1000 1000
  /usr/bin/time -v "$HDW" study "$W/r1000.toml" --out "$W/or" 2> "$W/r.log" > /dev/null
  echo "1000 x 1000 grid with report: $(grep -o '[0-9]* runs/s' "$W/r.log" | head -1), peak RSS $(awk '/Maximum resident/ {print $6}' "$W/r.log") KiB; plots:"
  ls -l "$W/or"/*.svg | awk '{print "  " $5 " bytes " $9}'
fi
rm -rf "$W"
