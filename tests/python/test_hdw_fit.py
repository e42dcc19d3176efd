"""hdw.fit_hysteresis and hdw.fit_friction from arrays against `hdw fit` on the shipped
data sets: the same fit.json content (every value, error, interval and flag; only the
wall times and the record of files read differ)."""

import numpy as np
import polars as pl
import pytest

import hdw
from hdw_cli import ROOT, hdw as run_cli, read_json, without

DATA = ROOT / "data"
VARYING = {"wall_time_s", "data"}


def test_hysteresis_fit_matches_the_cli(tmp_path):
    path = DATA / "hysteresis-paper-range.csv"
    run_cli("fit", "hysteresis", path, "--fix", "a=0", "--out", tmp_path)
    d = pl.read_csv(path)
    fit = hdw.fit_hysteresis(d["t"], d["theta"], d["torque"], fix={"a": 0.0})
    assert without(fit.report, VARYING) == without(read_json(tmp_path / "fit.json"), VARYING)
    assert fit.report["parameters"]["a"]["fixed"] is True
    fitted = pl.read_parquet(tmp_path / "fitted.parquet")
    assert np.array_equal(fit.fitted, fitted["fitted"].to_numpy())
    assert np.array_equal(fit.residuals, d["torque"].to_numpy() - fit.fitted)
    assert set(fit.values) == {"a", "b", "c", "mem_A", "mem_B"}


def test_friction_fit_matches_the_cli(tmp_path):
    steady, transient = DATA / "friction-steady.csv", DATA / "friction-transient.parquet"
    run_cli("fit", "friction", "--steady", steady, "--transient", transient, "--out", tmp_path)
    s, tr = pl.read_csv(steady), pl.read_parquet(transient)
    fit = hdw.fit_friction(tr["t"], tr["omega"], tr["torque"],
                           steady={"omega": s["omega"], "torque": s["torque"]})
    assert without(fit.report, VARYING) == without(read_json(tmp_path / "fit.json"), VARYING)
    tf = pl.read_parquet(tmp_path / "transient-fitted.parquet")
    assert np.array_equal(fit.stages["transient"]["fitted"], tf["fitted"].to_numpy())
    assert fit.stages["steady"] is not None
    # The shipped sets were made with Tc = 0.2, Ts = 0.35 (data/README.md).
    assert abs(fit.values["Tc"] - 0.2) < 0.01 and abs(fit.values["Ts"] - 0.35) < 0.01


def test_law_comparison_ranks_every_law():
    d = pl.read_parquet(DATA / "hysteresis-wide-range.parquet")
    cmp = hdw.fit_hysteresis(d["t"][:4000], d["theta"][:4000], d["torque"][:4000], law="all")
    laws = [e["law"] for e in cmp["comparison"]]
    assert sorted(laws) == ["bouc-wen", "maxwell-slip", "memory"]
    assert set(cmp["fits"]) <= set(laws)


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: hdw.fit_hysteresis([0, 1, 2], [0, 1e-4], [0, 1, 2]), ["has 2 values", "'t' has 3"]),
        (lambda: hdw.fit_hysteresis(np.arange(50.0), np.zeros(50), np.zeros(50), law="spring"),
         ["spring", "memory"]),
        (lambda: hdw.fit_hysteresis(np.arange(50.0), np.zeros(50), np.zeros(50), fix={"sigm0": 1}),
         ["sigma0"]),
        (lambda: hdw.fit_friction(), ["no friction data"]),
        (lambda: hdw.fit_friction(t=[0.0, 1.0], omega=[0.0, 1.0]), ["t, omega and torque"]),
        (lambda: hdw.fit_friction(steady={"omega": [1.0], "torq": [1.0]}), ["torq"]),
    ],
)
def test_bad_fits_are_value_errors(call, words):
    with pytest.raises(ValueError) as e:
        call()
    for w in words:
        assert w.lower() in str(e.value).lower(), (w, str(e.value))
