"""Every kind of Parquet file hdw writes reads the same in DuckDB, polars and pyarrow.

SQL engines fold the case of column names, so two columns that differ only by case (the
seed's `a` and `A`) would be renamed or confused by DuckDB; the files must hold every
parameter and metric under its own name, with the same values in every reader, and carry
each column's unit. Old study files that use the seed's letters A and B must still run.

The `hdw` binary is taken from $HDW (default: target/debug/hdw, built by cargo test).
"""

import json
import math
import os
import pathlib
import subprocess

import duckdb
import polars as pl
import pyarrow.parquet as pq
import pytest

from hdw_cli import sobol_study

ROOT = pathlib.Path(__file__).resolve().parents[2]
HDW = os.environ.get("HDW", str(ROOT / "target" / "debug" / "hdw"))

# A small study in the old spelling: axes on the seed's A and B, traces kept, and a
# Sobol' design part so that sensitivity.parquet is written too.
STUDY = """
name = "readers"
[base]
variant = "full"
t_end = 0.02
[input]
kind = "sine"
voltage = 24.0
freq = 50.0
[metrics]
keep = ["thz_amp", "efficiency", "tb_peak"]
cycles = 1
[traces]
keep = true
decimate = 20
[[part]]
name = "memory-grid"
[[part.axis]]
name = "A"
values = [30000.0, 40000.0]
[[part.axis]]
name = "B"
values = [200.0, 300.0, 400.0]
"""

SOBOL = sobol_study("readers-sobol", 0.02, 8, 1, [("A", 30000, 50000), ("c", 40000, 60000)])


def hdw(*args):
    run = subprocess.run([HDW, *args], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return run


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    root = tmp_path_factory.mktemp("readers")
    (root / "study.toml").write_text(STUDY)
    (root / "sobol.toml").write_text(SOBOL)
    hdw("study", str(root / "study.toml"), "--out", str(root / "study"), "--no-report")
    hdw("study", str(root / "sobol.toml"), "--out", str(root / "sobol"))
    hdw("simulate", "--t-end", "0.02", "--set", "A=45000", "--out", str(root / "sim"))
    return {
        "runs": root / "study" / "runs.parquet",
        "traces": root / "study" / "traces.parquet",
        "trace": root / "sim" / "trace.parquet",
        "sobol-runs": root / "sobol" / "runs.parquet",
        "sensitivity": root / "sobol" / "sensitivity.parquet",
    }


def same(a, b):
    if a is None or b is None:
        return a is None and b is None
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b


KINDS = ["runs", "traces", "trace", "sobol-runs", "sensitivity"]


@pytest.mark.parametrize("kind", KINDS)
def test_duckdb_reads_every_column_under_its_own_name_with_polars_values(outputs, kind):
    path = outputs[kind]
    frame = pl.read_parquet(path)
    rel = duckdb.sql(f"SELECT * FROM '{path}'")
    assert rel.columns == frame.columns, "DuckDB renamed or merged columns"
    lowered = [c.lower() for c in frame.columns]
    assert len(set(lowered)) == len(lowered), "two names differ only by case"
    rows = rel.fetchall()
    assert len(rows) == frame.height
    for k, name in enumerate(frame.columns):
        ours = frame[name].to_list()
        theirs = [r[k] for r in rows]
        bad = [i for i, (a, b) in enumerate(zip(ours, theirs)) if not same(a, b)]
        assert not bad, f"{kind}.{name}: row {bad[0]}: polars {ours[bad[0]]!r}, duckdb {theirs[bad[0]]!r}"


@pytest.mark.parametrize("kind", KINDS)
def test_every_column_carries_its_unit_and_description(outputs, kind):
    path = outputs[kind]
    schema = pq.read_schema(path)
    for field in schema:
        meta = field.metadata or {}
        assert b"unit" in meta and b"description" in meta, f"{kind}.{field.name} has no unit"
    kv = duckdb.sql(
        f"SELECT value FROM parquet_kv_metadata('{path}') WHERE key = 'hdw.columns'"
    ).fetchall()
    doc = json.loads(kv[0][0])
    assert set(doc) == set(schema.names)


def test_memory_parameters_are_not_confused_with_the_cubic_ones(outputs):
    path = outputs["runs"]
    got = duckdb.sql(
        f"SELECT a, mem_A, mem_B FROM '{path}' ORDER BY run_index"
    ).fetchall()
    # The old study's axes A (outer) and B (inner) landed in mem_A and mem_B; a keeps its
    # default 0.12 N·m/rad³.
    assert [(r[1], r[2]) for r in got] == [
        (a, b) for a in (30000.0, 40000.0) for b in (200.0, 300.0, 400.0)
    ]
    assert all(r[0] == 0.12 for r in got)
    # Case-insensitive SQL names still resolve to the right column (only one matches).
    assert duckdb.sql(f"SELECT MEM_a FROM '{path}' LIMIT 1").fetchall()[0][0] == 30000.0
    units = pq.read_schema(path).field("mem_A").metadata[b"unit"].decode()
    assert units == "N·m/rad"


def test_simulate_accepts_the_seed_letter_and_writes_the_canonical_name(outputs):
    metrics = json.loads((outputs["trace"].parent / "metrics.json").read_text())
    assert metrics["parameters"]["mem_A"] == 45000.0
    assert "A" not in metrics["parameters"]
