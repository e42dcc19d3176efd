"""hdw.run_study against `hdw study`: the same runs table (row for row, every value but the
wall time), the same traces and study.json, and a folder `hdw report` accepts."""

import polars as pl
import pyarrow.parquet as pq
import pytest

import hdw
from hdw_cli import ROOT, hdw as run_cli, read_json

STUDY = ROOT / "studies" / "step.toml"


def test_study_outputs_match_the_cli(tmp_path):
    cli, py = tmp_path / "cli", tmp_path / "py"
    run_cli("study", STUDY, "--out", cli, "--no-report", "--threads", "2")
    runs = hdw.run_study(STUDY, out=py, threads=2)
    expected = pl.read_parquet(cli / "runs.parquet")
    written = pl.read_parquet(py / "runs.parquet")
    assert runs.columns == expected.columns == written.columns
    assert runs.height == expected.height == 25
    assert runs.drop("wall_time").equals(expected.drop("wall_time"), null_equal=True)
    assert written.drop("wall_time").equals(expected.drop("wall_time"), null_equal=True)
    assert pl.read_parquet(py / "traces.parquet").equals(
        pl.read_parquet(cli / "traces.parquet"), null_equal=True
    )
    assert read_json(py / "study.json") == read_json(cli / "study.json")
    # Units and descriptions travel in the field metadata, as hdw writes them.
    field = pq.read_schema(py / "runs.parquet").field("rise_time")
    assert field.metadata[b"unit"] == b"s"
    # The report of the Python-written folder.
    run_cli("report", py)
    assert (py / "report.md").exists()


def test_one_part_and_thread_count():
    runs = hdw.run_study(STUDY, parts=["variants"], threads=1)
    assert runs["part"].unique().to_list() == ["variants"]
    assert runs.height == 9 and (runs["status"] == "ok").all()


def test_malformed_study_names_file_line_and_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\n[base]\nt_end = 0.1\n[[axis]]\nname = "sigm0"\nvalues = [1.0]\n')
    with pytest.raises(ValueError) as e:
        hdw.run_study(bad)
    msg = str(e.value)
    assert "bad.toml:" in msg and "sigm0" in msg and "sigma0" in msg
    with pytest.raises(ValueError, match="no part 'x'"):
        hdw.run_study(STUDY, parts=["x"])
