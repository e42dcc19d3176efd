"""hdw.sobol_indices: the estimators of `hdw sensitivity` on outputs computed anywhere —
the same numbers as the CLI on a study's own design, and the Ishigami function's analytic
indices from a Saltelli sample built here (the layout SALib's sampler uses)."""

import numpy as np
import polars as pl
import pytest

import hdw
from hdw_cli import hdw as run_cli, sobol_study

SOBOL_STUDY = sobol_study("py-sobol", 0.04, 32, 3, [("c", 40000, 60000), ("Tc", 0.1, 0.2), ("Jz", 0.02, 0.03)])


def test_same_indices_as_hdw_sensitivity_on_a_study(tmp_path):
    study = tmp_path / "sobol.toml"
    study.write_text(SOBOL_STUDY)
    out = tmp_path / "out"
    runs = hdw.run_study(study, out=out).sort("run_index")
    run_cli("sensitivity", out)
    cli = pl.read_parquet(out / "sensitivity.parquet").filter(pl.col("metric") == "thz_amp")
    ours = hdw.sobol_indices(runs["thz_amp"].to_numpy(), ["c", "Tc", "Jz"])
    for name in ("c", "Tc", "Jz"):
        a = cli.filter(pl.col("parameter") == name).row(0, named=True)
        b = ours.filter(pl.col("parameter") == name).row(0, named=True)
        for k in ("S1", "S1_lo", "S1_hi", "ST", "ST_lo", "ST_hi", "n_used"):
            assert a[k] == b[k], (name, k, a[k], b[k])


def ishigami(x, a=7.0, b=0.1):
    return np.sin(x[:, 0]) + a * np.sin(x[:, 1]) ** 2 + b * x[:, 2] ** 4 * np.sin(x[:, 0])


def test_ishigami_analytic_indices():
    n, d = 4096, 3
    rng = np.random.default_rng(5)
    a_m, b_m = rng.uniform(-np.pi, np.pi, (2, n, d))
    blocks = [a_m] + [np.where(np.arange(d) == i, b_m, a_m) for i in range(d)] + [b_m]
    x = np.stack(blocks, axis=1).reshape(n * (d + 2), d)  # per base row: A, AB_1..AB_d, B
    s = hdw.sobol_indices(ishigami(x), ["x1", "x2", "x3"], bootstrap=200)
    # Analytic values for a = 7, b = 0.1 (Ishigami & Homma 1990).
    s1 = np.array([0.3139, 0.4424, 0.0])
    st = np.array([0.5576, 0.4424, 0.2437])
    assert np.max(np.abs(s["S1"].to_numpy() - s1)) < 0.05
    assert np.max(np.abs(s["ST"].to_numpy() - st)) < 0.05
    assert (s["S1_lo"] <= s["S1"]).all() and (s["S1"] <= s["S1_hi"]).all()


def test_bad_layout_is_a_value_error():
    with pytest.raises(ValueError, match="multiple of dims \\+ 2 = 5"):
        hdw.sobol_indices(np.ones(12), ["a", "b", "c"])
