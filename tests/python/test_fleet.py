"""hdw.fleet against `hdw fleet` on a small synthetic fleet: the same fits table (only the
wall times differ), the worn unit in the alarms, and a refused manifest as a ValueError
naming the manifest and the column."""

import pytest

import hdw
from hdw_cli import HDW, hdw as run_cli


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("fleet") / "data"
    run_cli("synth", "fleet", "--robots", "2", "--joints", "2", "--days", "24", "--duration", "3",
            "--levels", "5", "--wear", "r2/j1@12", "--out", d)
    return d


def test_fleet_matches_the_cli(data, tmp_path):
    cli = tmp_path / "cli"
    run_cli("fleet", "--manifest", data / "manifest.csv", "--covariates", "temperature",
            "--baseline-days", "8", "--no-plots", "--out", cli)
    r = hdw.fleet(data / "manifest.csv", covariates=["temperature"], baseline_days=8,
                  out=tmp_path / "py", options=["--no-plots"], hdw=HDW)
    import polars as pl

    expected = pl.read_parquet(cli / "fits.parquet").drop("fit_time_s")
    assert r.fits.drop("fit_time_s").equals(expected)
    assert r.fits.filter(pl.col("status") == "ok").height == 4 * 96
    assert set(r.alarms["unit_id"].to_list()) == {"r2/j1"}
    assert r.drift.filter(pl.col("flagged")).select("unit_id").unique().to_series().to_list() == ["r2/j1"]
    tc = next(p for p in r.report["parameters"] if p["parameter"] == "Tc")
    assert tc["normalisation"] != "none"


def test_a_bad_manifest_is_a_value_error(tmp_path):
    m = tmp_path / "m.csv"
    m.write_text("file,robot,joint,date\nx.csv,r1,j1,2026-01-01\n")
    with pytest.raises(ValueError, match="no column 'temp'"):
        hdw.fleet(m, covariates=["temp"], out=tmp_path / "o", hdw=HDW)
