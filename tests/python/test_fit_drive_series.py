"""series.parquet of `hdw fit drive` on the shipped EMPS estimation run, read by DuckDB and
polars: the rows behind every score, the samples the benchmark's rule scores marked, the
scores recomputed from them in SQL equal to fit.json's, and every column's unit."""

import json
import math

import duckdb
import polars as pl
import pyarrow.parquet as pq

from hdw_cli import ROOT, hdw, read_json


def fitted(tmp_path):
    """The shipped EMPS configuration with one friction law, fitted into tmp_path/out."""
    text = (ROOT / "data" / "emps" / "fit.toml").read_text()
    data = ROOT / "data" / "emps" / "DATA_EMPS.mat"
    text = text.replace('friction = "all"', 'friction = "coulomb-viscous"')
    text = text.replace('file = "DATA_EMPS.mat"', f'file = "{data.as_posix()}"')
    cfg = tmp_path / "fit.toml"
    cfg.write_text(text)
    out = tmp_path / "out"
    hdw("fit", "drive", "--config", cfg, "--out", out)
    return out


def test_series_back_the_scores_in_duckdb_and_polars(tmp_path):
    out = fitted(tmp_path)
    path = out / "series.parquet"
    fit = read_json(out / "fit.json")
    frame = pl.read_parquet(path)
    assert frame.columns == [
        "experiment", "set", "model", "sample", "t", "output", "unit",
        "measured", "simulated", "residual", "scored",
    ]
    lowered = [c.lower() for c in frame.columns]
    assert len(set(lowered)) == len(lowered)
    assert frame.height == 2 * 24841
    # DuckDB reads the same columns, `set` unquoted among them.
    rel = duckdb.sql(
        f"SELECT experiment, set, output, count(*) AS n FROM '{path}' GROUP BY ALL ORDER BY output"
    )
    assert rel.fetchall() == [
        ("estimation", "estimation", "force", 24841),
        ("estimation", "estimation", "position", 24841),
    ]
    # The benchmark's rule: the first 49 samples are not scored.
    first = duckdb.sql(f"SELECT min(sample) FROM '{path}' WHERE scored").fetchall()[0][0]
    assert first == 49 and fit["score_rule"]["name"] == "emps"
    # Relative error ‖y − ŷ‖/‖y‖ by the rule and over every sample, in SQL and in polars.
    sql = f"""SELECT output,
                     100 * sqrt(sum(residual * residual) FILTER (WHERE scored)
                                / sum(measured * measured) FILTER (WHERE scored)) AS rule,
                     100 * sqrt(sum(residual * residual) / sum(measured * measured)) AS every
              FROM '{path}' GROUP BY output"""
    for output, rule, every in duckdb.sql(sql).fetchall():
        score = fit["experiments"]["estimation"][output]
        assert math.isclose(rule, score["rel_error"], rel_tol=1e-9), (output, rule, score)
        assert math.isclose(every, score["all_samples"]["rel_error"], rel_tol=1e-9)
        assert score["samples"] == 24841 - 49
    force = frame.filter((pl.col("output") == "force") & pl.col("scored"))
    rel = 100 * math.sqrt((force["residual"] ** 2).sum() / (force["measured"] ** 2).sum())
    assert math.isclose(rel, fit["experiments"]["estimation"]["force"]["rel_error"], rel_tol=1e-9)


def test_series_columns_carry_units_and_descriptions(tmp_path):
    path = fitted(tmp_path) / "series.parquet"
    schema = pq.read_schema(path)
    for field in schema:
        meta = field.metadata or {}
        assert b"unit" in meta and b"description" in meta, field.name
    assert schema.field("t").metadata[b"unit"] == b"s"
    assert schema.field("measured").metadata[b"unit"].decode() == "force: N, position: m"
    kv = duckdb.sql(
        f"SELECT value FROM parquet_kv_metadata('{path}') WHERE key = 'hdw.columns'"
    ).fetchall()
    assert set(json.loads(kv[0][0])) == set(schema.names)
