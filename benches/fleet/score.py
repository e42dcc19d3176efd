"""Score a `hdw fleet` run on a synthetic fleet against its truth (hdw synth fleet).

    python benches/fleet/score.py FLEET_DATA_DIR FLEET_OUT_DIR

Prints: per-log coverage (share of logs whose estimate lies within 3 standard errors of the
truth, per parameter and over all), detection delay of every worn unit and parameter
(first flagged day − onset day), and the alarms on units that do not wear.
Needs polars.
"""

import json
import sys

import polars as pl

data, out = sys.argv[1], sys.argv[2]
truth = pl.read_csv(f"{data}/truth.csv", infer_schema_length=None)
spec = json.load(open(f"{data}/truth.json"))
fits = pl.read_parquet(f"{out}/fits.parquet")
print(f"logs: {fits['log_index'].n_unique()}, failed: {fits.filter(pl.col('status') != 'ok')['log_index'].n_unique()}")
tl = truth.unpivot(index=["file"], on=["Tc", "Ts", "ws", "sigma2"], variable_name="parameter", value_name="truth")
j = fits.filter(pl.col("status") == "ok").join(tl, on=["file", "parameter"], how="inner")
j = j.with_columns(((pl.col("value") - pl.col("truth")) / pl.col("std_error")).alias("t"))
cov = j.group_by("parameter").agg(
    (pl.col("t").abs() <= 3).mean().alias("within_3se"),
    pl.col("t").mean().alias("mean_t"),
    pl.col("t").std().alias("sd_t"),
).sort("parameter")
print(cov)
per_log = j.group_by("file").agg((pl.col("t").abs() <= 3).all().alias("all_within"))
print(f"estimates within 3 SE: {(j['t'].abs() <= 3).mean():.4f}; logs with every parameter within 3 SE: {per_log['all_within'].mean():.4f}")
alarms = pl.read_csv(f"{out}/alarms.csv", infer_schema_length=None)
start = spec["start"]
worn = {w["unit_id"]: w["onset_day"] for w in spec["wear"]}
first = fits["day"].min()
for u, onset in worn.items():
    for p in spec["wear_parameters"]:
        a = alarms.filter((pl.col("unit_id") == u) & (pl.col("parameter") == p))
        if a.height:
            d = a["first_flagged_day"][0] - first - onset
            print(f"worn {u} {p}: flagged {a['first_flagged'][0]}, {d:.0f} days after onset (day {onset:.0f}); change {a['change_pct'][0]:.2f} % [{a['ci95_lo'][0]:.2f}, {a['ci95_hi'][0]:.2f}]")
        else:
            print(f"worn {u} {p}: NOT flagged")
false = alarms.filter(~pl.col("unit_id").is_in(list(worn)))
print(f"alarms on healthy units: {false.height}")
if false.height:
    print(false)
