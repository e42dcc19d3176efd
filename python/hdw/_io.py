"""Reading recorded inputs and writing Parquet tables from Python (the extension has no
file formats of its own)."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _hdw


def read_profile(path: "os.PathLike[str] | str") -> Tuple[np.ndarray, np.ndarray]:
    """Read a recorded voltage profile: columns ``t`` [s] and ``u`` [V] of a CSV file (header
    row, comma-separated) or a Parquet file (needs polars or pyarrow)."""
    p = Path(path)
    if p.suffix.lower() == ".parquet":
        try:
            import polars as pl

            df = pl.read_parquet(p, columns=["t", "u"])
            return df["t"].to_numpy().astype(float), df["u"].to_numpy().astype(float)
        except ImportError:
            import pyarrow.parquet as pq

            tab = pq.read_table(p, columns=["t", "u"])
            return (
                tab.column("t").to_numpy().astype(float),
                tab.column("u").to_numpy().astype(float),
            )
    with open(p, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise ValueError(f"{p}: empty file: expected a header row with columns t, u")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in ("t", "u") if c not in header]
    if missing:
        raise ValueError(f"{p}: no column {', '.join(missing)} (columns: {', '.join(header)})")
    it, iu = header.index("t"), header.index("u")
    try:
        t = np.array([float(r[it]) for r in rows[1:]])
        u = np.array([float(r[iu]) for r in rows[1:]])
    except (ValueError, IndexError) as e:
        raise ValueError(f"{p}: expected numbers in columns t and u ({e})") from None
    return t, u


def _arrow_column(name: str, col: Any) -> Any:
    import pyarrow as pa

    if isinstance(col, np.ndarray) and col.dtype.kind == "f":
        return pa.array(col, mask=~np.isfinite(col))
    if isinstance(col, np.ndarray):
        return pa.array(col)
    if all(v is None or isinstance(v, str) for v in col):
        return pa.array(col, type=pa.string())
    return pa.array(col, type=pa.uint64())


def write_table(path: Path, columns: Dict[str, Any]) -> None:
    """Write ``columns`` as Parquet the way ``hdw`` does: NaN as null, each documented
    column's unit and description in its field metadata and under the file-level key
    ``hdw.columns``. Uses pyarrow; without it, polars (then without the metadata)."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        from ._tables import table

        df = table(columns)
        if isinstance(df, dict):
            raise ImportError("writing Parquet needs pyarrow or polars: pip install pyarrow")
        df.write_parquet(tmp)
        os.replace(tmp, path)
        return
    fields, arrays, doc = [], [], {}
    for name, col in columns.items():
        arr = _arrow_column(name, col)
        info = _hdw.column_doc(name)
        meta = None
        if info is not None:
            meta = {"unit": info[0], "description": info[1]}
            doc[name] = meta
        fields.append(pa.field(name, arr.type, metadata=meta))
        arrays.append(arr)
    schema = pa.schema(fields, metadata={"hdw.columns": json.dumps(doc)})
    pq.write_table(pa.Table.from_arrays(arrays, schema=schema), tmp, compression="zstd")
    os.replace(tmp, path)


def write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    tmp.write_text(text)
    os.replace(tmp, path)


def out_dir(out: Optional["os.PathLike[str] | str"]) -> Optional[Path]:
    """The output folder, created."""
    if out is None:
        return None
    p = Path(out)
    p.mkdir(parents=True, exist_ok=True)
    return p
