"""Parquet columns a fit cannot read as measurements, made the way other tools write them
(pyarrow): a decimal column panicked inside the reader (exit 101), a boolean torque was
read as 0/1 and fitted to nonsense (exit 0). Each is now refused in one line naming the
file and the column."""

import decimal
import subprocess

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from hdw_cli import HDW


def _fit(path, out):
    return subprocess.run([HDW, "fit", "friction", "--transient", str(path), "--out",
                           str(out)], capture_output=True, text=True)


def _record(torque_array, path):
    t = np.arange(200) * 1e-3
    omega = np.sin(2 * np.pi * 5 * t)
    pq.write_table(pa.table({"t": t, "omega": omega, "torque": torque_array}), path)


def test_a_decimal_torque_column_is_refused_naming_it(tmp_path):
    t = np.arange(200) * 1e-3
    values = [decimal.Decimal(f"{0.3 * np.sign(np.sin(31.4 * x)):.6f}") for x in t]
    path = tmp_path / "dec.parquet"
    _record(pa.array(values, type=pa.decimal128(12, 6)), path)
    p = _fit(path, tmp_path / "o")
    assert p.returncode == 1, p.stderr
    assert "panicked" not in p.stderr
    lines = [line for line in p.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "column 'torque' holds fixed-point decimals" in lines[0], p.stderr


def test_a_boolean_torque_column_is_refused_naming_it(tmp_path):
    path = tmp_path / "bool.parquet"
    _record(pa.array(np.sin(np.arange(200) * 0.1) > 0), path)
    p = _fit(path, tmp_path / "o")
    assert p.returncode == 1, p.stderr
    assert "column 'torque' holds true/false values" in p.stderr, p.stderr
    assert not (tmp_path / "o" / "fit.json").exists()
