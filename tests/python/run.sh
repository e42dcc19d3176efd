#!/usr/bin/env bash
# The Python suite: Parquet outputs read by DuckDB, polars and pyarrow. Installs what it
# needs into a virtual environment under target/ (pip only), then runs pytest against the
# hdw binary built by `cargo test --workspace` (or $HDW).
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/py-tests
if [ ! -x "$venv/bin/python" ] && ! python3 -m venv "$venv" 2>/dev/null; then
    # A Debian python3 without the venv module: add it from the distribution.
    if command -v apt-get >/dev/null; then
        apt-get install -y -q python3-venv >/dev/null 2>&1 || true
    fi
    rm -rf "$venv"
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check -r tests/python/requirements.txt
[ -x "${HDW:-target/debug/hdw}" ] || cargo build -p hd-cli
HDW="${HDW:-$PWD/target/debug/hdw}" "$venv/bin/python" -m pytest -q tests/python
