#!/usr/bin/env bash
# Work-precision runs of the full model, 1 s, seed case: hd-model (Rodas4, Dopri5), scipy
# LSODA and diffsol at rtol 1e-6 … 1e-10 (atol = rtol·1e-3). Needs the release build of
# hd-model's bench_case example and of benches/diffsol-compare. Results go to $OUT.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-target/bench-results}
mkdir -p "$OUT"
cargo build --release -q -p hd-model --example bench_case
BC=target/release/examples/bench_case
DC=benches/diffsol-compare/target/release/diffsol-compare
[ -x "$DC" ] || (cd benches/diffsol-compare && cargo build --release -q)
"$BC" full 1e-12 1e-15 1 1 > "$OUT/ref.json"
for rtol in 1e-6 1e-7 1e-8 1e-9 1e-10; do
  atol=$(python3 -c "print($rtol*1e-3)")
  "$BC" full "$rtol" "$atol" 1 10 1e-4 rodas4 > "$OUT/rodas4_$rtol.json"
  "$BC" full "$rtol" "$atol" 1 10 1e-4 dopri5 > "$OUT/dopri5_$rtol.json"
  echo "## rtol $rtol"
  "$DC" "$OUT/rodas4_$rtol.json" "$OUT/ref.json" 3 bdf:nolimit,esdirk34:nolimit,tsit45 | tail -n +3
  python3 - "$OUT/dopri5_$rtol.json" "$OUT/ref.json" <<'PY'
import json, sys
import numpy as np
d, r = (json.load(open(p)) for p in sys.argv[1:3])
e = np.max(np.abs(np.array(d["theta_z"]) - np.array(r["theta_z"]))) / r["thz_amp"]
print(f"{'hd-model Dopri5':<22} {d['wall_best_s']:>10.5f} {'':>7} {d['steps']:>8} "
      f"{d['rejected']:>8} {'-':>9} {0:>8} {'':>16} {e:>11.2e}")
PY
  python3 benches/scipy_compare.py --case seed-1s --rtol "$rtol" --reps 1 --no-build \
    --no-odeint --json "$OUT/scipy_$rtol.json" | grep -E "^solve_ivp"
done
