#!/usr/bin/env bash
# Re-runs every bad-input and interruption case of issue #39 against an hdw binary and
# prints one Markdown row per case: exit code, first stderr line, peak memory [MB], wall
# time [s] and what the case left on disk. The CLI tests (tests/cli/refusals.rs,
# fault_injection.rs) hold each behaviour; this script is for measuring them on a release
# build, e.g. before and after a change:
#   tests/fault/cases.sh target/release/hdw /tmp/hdw-cases > cases.md
set -uo pipefail
HDW=$(realpath "${1:?usage: cases.sh HDW SCRATCH}")
REPO=$(cd "$(dirname "$0")/../.." && pwd)
W=${2:?usage: cases.sh HDW SCRATCH}
rm -rf "$W"; mkdir -p "$W"; cd "$W" || exit 1
LIMIT=${CASE_TIMEOUT:-60}

# What a folder holds: file names with sizes, hidden temporaries included.
left() {
  if [ ! -e "$1" ]; then echo "no $1"; return; fi
  if [ -f "$1" ]; then echo "$1 $(stat -c %s "$1") B"; return; fi
  local l; l=$(cd "$1" && find . -mindepth 1 -type f -printf '%P %s B, ' | head -c 300)
  echo "$1/: ${l:-empty}"
}

row() { # name, folder to inspect, command...
  local name=$1 dir=$2; shift 2
  local t0 t1 rc
  t0=$(date +%s.%N)
  timeout -s INT "$LIMIT" /usr/bin/time -f %M -o rss.txt "$@" >stdout.txt 2>stderr.txt
  rc=$?
  t1=$(date +%s.%N)
  report "$name" "$dir" "$rc" "$t0" "$t1"
}

report() {
  local name=$1 dir=$2 rc=$3 t0=$4 t1=$5
  local first rss
  first=$(grep -v '^\s*$' stderr.txt | grep -v 'Command exited\|Command terminated' | head -1 | cut -c1-160 | tr '|' '/')
  rss=$(tail -1 rss.txt 2>/dev/null)
  [ "$rc" = 124 ] && first="(timeout ${LIMIT}s) $first"
  printf '| %s | %s | %s | %.0f | %.2f | %s |\n' "$name" "$rc" "$first" \
    "$(echo "${rss:-0}/1024" | bc -l)" "$(echo "$t1-$t0" | bc -l)" "$(left "$dir")"
}

# Start a command, send SIGINT after $2 seconds, wait for it.
interrupt_row() { # name, seconds, folder, command...
  local name=$1 after=$2 dir=$3; shift 3
  local t0 t1 rc pid
  t0=$(date +%s.%N)
  /usr/bin/time -f %M -o rss.txt "$@" >stdout.txt 2>stderr.txt &
  pid=$!
  sleep "$after"
  pkill -INT -P "$pid" 2>/dev/null
  wait "$pid"; rc=$?
  t1=$(date +%s.%N)
  report "$name" "$dir" "$rc" "$t0" "$t1"
}

echo "| case | exit | first stderr line | peak MB | wall s | left on disk |"
echo "|---|---:|---|---:|---:|---|"

# Data lost or half-written
row "simulate ms_n=2.5 (maxwell-slip)" s1 "$HDW" simulate --stiffness maxwell-slip --set ms_n=2.5 --out s1
row "simulate c=1e308" s2 "$HDW" simulate --set c=1e308 --out s2
row "simulate Tc=1e308" s2b "$HDW" simulate --set Tc=1e308 --out s2b
row "simulate --t-end 1e308" s2c "$HDW" simulate --t-end 1e308 --out s2c
row "simulate --voltage 1e308" s3 "$HDW" simulate --voltage 1e308 --out s3
row "simulate chirp --freq 1e9" s4 "$HDW" simulate --input chirp --freq 1e9 --out s4
"$HDW" simulate --out s5 >/dev/null 2>&1
before=$(md5sum s5/trace.parquet s5/metrics.json | md5sum)
row "good run, then c=1e308 into the same folder" s5 "$HDW" simulate --set c=1e308 --out s5
after=$(md5sum s5/trace.parquet s5/metrics.json | md5sum)
[ "$before" = "$after" ] && echo "| ↳ earlier trace.parquet and metrics.json | | byte-identical after the failed run | | | |" \
  || echo "| ↳ earlier trace.parquet and metrics.json | | CHANGED by the failed run | | | |"
interrupt_row "Ctrl-C after 5 s: simulate --t-end 200" 5 s6 "$HDW" simulate --t-end 200 --dt-out 1e-5 --max-output-values 0 --out s6
interrupt_row "Ctrl-C after 5 s: simulate --t-end 1e9" 5 s7 "$HDW" simulate --t-end 1e9 --out s7
row "simulate --dt-out 1e-12" s8 "$HDW" simulate --dt-out 1e-12 --out s8

# Silently wrong
row "--set A=3e4 --set mem_A=4e4" s9 "$HDW" simulate --set A=3e4 --set mem_A=4e4 --out s9
printf 'A = 3e4\nmem_A = 4e4\n' > both.toml
row "params file with A and mem_A" s10 "$HDW" simulate --params both.toml --out s10
printf 'name = "st"\n[base]\nt_end = 0.01\n[base.set]\nA = 3e4\nmem_A = 4e4\n' > both-study.toml
row "study set with A and mem_A" s11 "$HDW" study both-study.toml --out s11
"$HDW" synth hysteresis --samples 2000 --out h.csv >/dev/null 2>&1
awk 'NR==500{sub(/\./,",")} {print}' h.csv > comma.csv
row "CSV row with a decimal comma" f1 "$HDW" fit hysteresis comma.csv --out f1
row "fit hysteresis --columns t,t,torque" f2 "$HDW" fit hysteresis h.csv --columns t,t,torque --out f2
"$HDW" simulate --out p0 >/dev/null 2>&1
row "plot --log-x over x ≤ 0" p1 "$HDW" plot p0/trace.parquet --x theta --line Tb --log-x --out p1/loop.svg
row "datasheet 1e308" d1 "$HDW" datasheet --k1 1e308 --k2 1e308 --k3 1e308 --t1 29 --t2 108 --out d1

# Memory and crashes
yes '0.001,0.5,0.25' | head -c 250000000 > big.csv
row "simulate --params a 250 MB CSV" m1 "$HDW" simulate --params big.csv --out m1
printf 'name = "z"\n[base]\nparams_file = "/dev/zero"\n' > zero.toml
row "study params_file = /dev/zero" m2 "$HDW" study zero.toml --out m2
printf 'name = "long"\n[base]\nt_end = 20.0\n[traces]\nkeep = true\ndt_out = 1e-5\n[[axis]]\nname = "voltage"\nvalues = [12.0, 24.0]\n' > long.toml
row "study: 2 runs × 20 s traces at dt_out 1e-5" m3 "$HDW" study long.toml --out m3
row "sensitivity --check ishigami --samples 1e9" m4 "$HDW" sensitivity --check ishigami --samples 1000000000
row "synth hysteresis --samples 1e10" m5 "$HDW" synth hysteresis --samples 10000000000 --out m5.csv
row "sensitivity --check ishigami --bootstrap 1e9" m6 "$HDW" sensitivity --check ishigami --samples 256 --bootstrap 1000000000
row "study --threads 100000" m7 "$HDW" study "$REPO/studies/step.toml" --threads 100000 --out m7
if [ -n "${BIG_FIT:-}" ]; then
  "$HDW" synth hysteresis --samples 10000000 --duration 250 --out h10m.csv >/dev/null 2>&1
  row "fit hysteresis on 10 000 000 rows" m8 "$HDW" fit hysteresis h10m.csv --out m8
fi

# Where results go
printf 'name = "../../escape"\n[base]\nt_end = 0.01\n' > esc.toml
row "study name ../../escape" o1 "$HDW" study esc.toml --out o1
printf '\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03\xff\xfe' > gz.csv
row "gzip data named .csv" o2 "$HDW" fit hysteresis gz.csv --out o2
row "fit hysteresis on a folder" o3 "$HDW" fit hysteresis . --out o3
row "simulate --t-end -1" o4 "$HDW" simulate --t-end -1 --out o4
printf 'name = "ms"\n[base]\nt_end = 0.01\n[solver]\nmax_steps = 0\n' > ms.toml
row "study max_steps = 0" o5 "$HDW" study ms.toml --out o5
printf 'name = "rep"\n[base]\nt_end = 0.01\n[[axis]]\nname = "voltage"\nvalues = [12, 12, 12]\n' > rep.toml
row "axis values [12, 12, 12]" o6 "$HDW" study rep.toml --out o6
printf 'name = "slow"\n[base]\nt_end = 500.0\n[[axis]]\nname = "voltage"\nlinspace = { start = 1, stop = 24, num = 40 }\n' > slow.toml
"$HDW" study slow.toml --out o7 >/dev/null 2>&1 &
sleep 2
row "a second study on a running study's folder" o7 "$HDW" study slow.toml --out o7
kill -INT %1 2>/dev/null; wait
printf 'name = "first"\n[base]\nt_end = 0.01\n' > first.toml
printf 'name = "second"\n[base]\nt_end = 0.01\n' > second.toml
"$HDW" study first.toml --out o8 >/dev/null 2>&1
row "a study into another study's folder" o8 "$HDW" study second.toml --out o8
row "↳ then with --resume" o8 "$HDW" study second.toml --out o8 --resume
(umask 022; "$HDW" simulate --t-end 0.01 --out u1 >/dev/null 2>&1)
echo "| umask 022: mode of trace.parquet | | $(stat -c %a u1/trace.parquet 2>/dev/null) | | | |"

# Identification (issue #51): `hdw fit drive` on the shipped configurations with one change
# each. Before: the first five ran at full CPU for minutes (nalgebra's SVD on a NaN matrix).
EMPS="$REPO/data/emps"
emps_cfg() { sed "s|file = \"DATA_EMPS.mat\"|file = \"$EMPS/DATA_EMPS.mat\"|" "$EMPS/fit.toml"; }
cv() { sed 's/friction = "all"/friction = "coulomb-viscous"/'; }
{ emps_cfg; printf '\n[params]\nM = -5.0\n'; } > i1.toml
row "fit drive: EMPS [params] M = -5" i1 "$HDW" fit drive --config i1.toml --out i1
{ emps_cfg | cv; printf '\n[bounds]\nM = [1.0, 2.0]\n'; } > i2.toml
row "fit drive: EMPS [bounds] M = [1, 2]" i2 "$HDW" fit drive --config i2.toml --out i2
{ emps_cfg | sed 's/friction = "all"/friction = "lugre"/'; printf '\n[params]\nsigma0 = -1.0\n'; } > i3.toml
row "fit drive: EMPS lugre, [params] sigma0 = -1" i3 "$HDW" fit drive --config i3.toml --out i3
"$HDW" synth drive --input chirp --freq 5 --t-end 1 --out chirp.csv >/dev/null 2>&1
compliant_cfg() { # record, extra lines before [[experiment]]
  sed -e "s|\"start.toml\"|\"$REPO/data/compliant/start.toml\"|" \
      -e "s|\"../../out/compliant/chirp.csv\"|\"$PWD/$1\"|" \
      -e "0,/^\[\[experiment\]\]/s||$2\n[[experiment]]|" "$REPO/data/compliant/fit.toml"
}
compliant_cfg chirp.csv '[params]\nJz = inf\n' > i4.toml
row "fit drive: compliant [params] Jz = inf" i4 "$HDW" fit drive --config i4.toml --out i4
awk -F, -v OFS=, 'NR==1{for(k=1;k<=NF;k++) if($k=="i") c=k; print; next} {$c=0; print}' chirp.csv > dead.csv
compliant_cfg dead.csv '' > i5.toml
row "fit drive: compliant, current column all zeros" i5 "$HDW" fit drive --config i5.toml --out i5
compliant_cfg chirp.csv '[params]\nR = 0.0\n' > i6.toml
row "fit drive: compliant [params] R = 0" i6 "$HDW" fit drive --config i6.toml --out i6
compliant_cfg chirp.csv 'substeps = 1000000\n' > i7.toml
row "fit drive: compliant substeps = 1000000" i7 "$HDW" fit drive --config i7.toml --out i7
emps_cfg | sed 's/delay = "auto"/delay = -1/' > i8.toml
row "fit drive: delay = -1" i8 "$HDW" fit drive --config i8.toml --out i8
emps_cfg | sed 's/gain = "gtau"/gain = nan/' > i9.toml
row "fit drive: gain = nan" i9 "$HDW" fit drive --config i9.toml --out i9
emps_cfg | sed 's/kp = "kp"/kp = nan/' > i10.toml
row "fit drive: kp = nan" i10 "$HDW" fit drive --config i10.toml --out i10
emps_cfg | sed 's/speed_filter = \[0.5, 0.5\]/speed_filter = [nan]/' > i11.toml
row "fit drive: speed_filter = [nan]" i11 "$HDW" fit drive --config i11.toml --out i11
{ emps_cfg | cv; printf '\n[params]\nsigma0 = 1e5\n'; } > i12.toml
row "fit drive: coulomb-viscous with [params] sigma0" i12 "$HDW" fit drive --config i12.toml --out i12
row "fit drive --config /dev/zero" i13 "$HDW" fit drive --config /dev/zero --out i13
row "fit drive --config a 250 MB file" i14 "$HDW" fit drive --config big.csv --out i14
compliant_cfg chirp.csv '' | sed "s|params_file = .*|params_file = \"/dev/zero\"|" > i15.toml
row "fit drive: params_file = /dev/zero" i15 "$HDW" fit drive --config i15.toml --out i15
emps_cfg | sed "s|file = \".*DATA_EMPS.mat\"|file = \"/dev/zero\"|" > i16.toml
row "fit drive: experiment file = /dev/zero" i16 "$HDW" fit drive --config i16.toml --out i16
emps_cfg > i17.toml
row "fit drive --validate /dev/zero" i17 "$HDW" fit drive --config i17.toml --validate /dev/zero --out i17
row "fit drive --validate a folder" i17 "$HDW" fit drive --config i17.toml --validate . --out i17
emps_cfg | cv > i18.toml
"$HDW" fit drive --config i18.toml --out i18 >/dev/null 2>&1
echo '<svg/>' > i18/validation-position.svg  # as an earlier fit with --validate leaves it
row "a fit into a folder holding an earlier fit's validation plot" i18 "$HDW" fit drive --config i18.toml --out i18
"$HDW" fit drive --config i17.toml --out i19 >/dev/null 2>&1 &
sleep 2
row "a second fit into a running fit's folder" i19 "$HDW" fit drive --config i18.toml --out i19
kill -INT %1 2>/dev/null; wait

# Identification (issue #51): the poor groups, one change each.
exp_key() { # one key = value added to the EMPS [[experiment]] table
  emps_cfg | sed "s|^disturbance = .*|&\n$1|"; }
emps_cfg | sed 's/gain = "gtau"/gain = inf/' > j1.toml
row "fit drive: gain = inf" j1 "$HDW" fit drive --config j1.toml --out j1
emps_cfg | sed 's/gain = "gtau"/gain = 0/' > j2.toml
row "fit drive: gain = 0" j2 "$HDW" fit drive --config j2.toml --out j2
emps_cfg | sed 's/gain = "gtau"/gain = -35.15/' > j3.toml
row "fit drive: gain = -35.15" j3 "$HDW" fit drive --config j3.toml --out j3
exp_key 'position_scale = 0.0' > j4.toml
row "fit drive: position_scale = 0" j4 "$HDW" fit drive --config j4.toml --out j4
exp_key 'position_scale = -1.0' > j5.toml
row "fit drive: position_scale = -1" j5 "$HDW" fit drive --config j5.toml --out j5
exp_key 'command_scale = nan' > j6.toml
row "fit drive: command_scale = nan" j6 "$HDW" fit drive --config j6.toml --out j6
{ emps_cfg; printf '\n[params]\nM = nan\n'; } > j7.toml
row "fit drive: EMPS [params] M = nan" j7 "$HDW" fit drive --config j7.toml --out j7
emps_cfg | sed 's/kv = "kv"/kv = -1.0/' > j8.toml
row "fit drive: kv = -1" j8 "$HDW" fit drive --config j8.toml --out j8
compliant_cfg chirp.csv '[params]\nR = -1.0\n' > j9.toml
row "fit drive: compliant [params] R = -1" j9 "$HDW" fit drive --config j9.toml --out j9
compliant_cfg chirp.csv '[params]\nR = nan\n' > j10.toml
row "fit drive: compliant [params] R = nan" j10 "$HDW" fit drive --config j10.toml --out j10
compliant_cfg chirp.csv '[bounds]\nR = [1.0, 2.0]\n' > j11.toml
row "fit drive: compliant [bounds] R = [1, 2] (start 7.5)" j11 "$HDW" fit drive --config j11.toml --out j11
awk -F, -v OFS=, 'NR==1{print; next} {for(k=2;k<=NF;k++) $k=0; print}' chirp.csv > zeros.csv
compliant_cfg zeros.csv '' > j12.toml
row "fit drive: compliant, an all-zero record" j12 "$HDW" fit drive --config j12.toml --out j12
awk -F, -v OFS=, 'NR==1{for(k=1;k<=NF;k++) if($k=="u") c=k; print; next} {$c=0; print}' chirp.csv > u0.csv
compliant_cfg u0.csv '' > j13.toml
row "fit drive: compliant, zero voltage" j13 "$HDW" fit drive --config j13.toml --out j13
compliant_cfg chirp.csv '' | sed 's|^current = "i"|&\nvoltage_scale = 0.0|' > j14.toml
row "fit drive: compliant voltage_scale = 0" j14 "$HDW" fit drive --config j14.toml --out j14
awk -F, -v OFS=, 'NR==1{for(k=1;k<=NF;k++) if($k=="u") c=k; print; next} {$c=$c*1000; print}' chirp.csv > mv.csv
compliant_cfg mv.csv '' > j15.toml
row "fit drive: compliant, voltage logged in mV" j15 "$HDW" fit drive --config j15.toml --out j15
head -13 chirp.csv > rows12.csv
compliant_cfg rows12.csv '' > j16.toml
row "fit drive: compliant, a 12-row record" j16 "$HDW" fit drive --config j16.toml --out j16
{ emps_cfg; emps_cfg | sed -n '/^\[\[experiment\]\]/,/^disturbance/p'; } > j17.toml
row "fit drive: two experiments named estimation" j17 "$HDW" fit drive --config j17.toml --out j17
awk -F, -v OFS=, 'NR==1{for(k=1;k<=NF;k++) if($k=="i") c=k; print; next} {$c=$c*1000; print}' chirp.csv > ma.csv
compliant_cfg ma.csv '' > j18.toml
row "fit drive: compliant, current logged in mA" j18 "$HDW" fit drive --config j18.toml --out j18
"$HDW" synth drive --loop-kp 30 --loop-kv 0.5 --loop-reference steps --freq 5 --t-end 1 --motor-counts 65536 --out loop-steps.csv >/dev/null 2>&1
sed -e "s|\"start.toml\"|\"$REPO/data/compliant/start.toml\"|" -e "s|\"../../out/compliant/loop-steps.csv\"|\"$PWD/loop-steps.csv\"|" \
    -e 's/^kv = 0.5 /kv = 5.0 /' "$REPO/data/compliant/loop.toml" > j19.toml
row "fit drive: loop example with kv = 5.0 (truth 0.5)" j19 "$HDW" fit drive --config j19.toml --out j19
yes 'R = 6.0' | head -c 25000000 > p25.toml
compliant_cfg chirp.csv '' | sed "s|params_file = .*|params_file = \"$PWD/p25.toml\"|" > j20.toml
row "fit drive: a 25 MB params_file" j20 "$HDW" fit drive --config j20.toml --out j20
row "synth drive --sample-period 10" j21 "$HDW" synth drive --sample-period 10 --out j21.csv
row "synth drive: band wholly above Nyquist" j22 "$HDW" synth drive --freq 5000 --out j22.csv
row "synth drive --voltage 1e308" j23 "$HDW" synth drive --voltage 1e308 --out j23.csv
row "synth drive --loop-amplitude 1e308" j24 "$HDW" synth drive --loop-kp 30 --loop-kv 0.5 --loop-amplitude 1e308 --out j24.csv
row "synth drive --loop-delay 1000000000" j25 "$HDW" synth drive --loop-kp 30 --loop-kv 0.5 --loop-delay 1000000000 --out j25.csv
row "synth drive --t-end 20000" j26 "$HDW" synth drive --t-end 20000 --out j26.csv
row "export fmu --lib /dev/zero" j27 "$HDW" export fmu --lib /dev/zero --out j27.fmu
row "export fmu --lib a folder" j28 "$HDW" export fmu --lib . --out j28.fmu
echo 'not a library' > notalib.so
row "export fmu --lib a text file" j29 "$HDW" export fmu --lib notalib.so --out j29.fmu
