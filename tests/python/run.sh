#!/usr/bin/env bash
# The Python suite: Parquet outputs read by DuckDB, polars and pyarrow, and the hdw Python
# package (python/) against the CLI. Installs what it needs into a virtual environment under
# target/ (pip only), builds and installs the package with `pip install ./python` (maturin,
# its own cargo target dir target/py-build), then runs pytest against the hdw binary built
# by `cargo test --workspace` (or $HDW).
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
start=$(date +%s)
CARGO_TARGET_DIR="$PWD/target/py-build" \
    "$venv/bin/python" -m pip install -q --disable-pip-version-check ./python
echo "python package: built and installed in $(( $(date +%s) - start )) s"
[ -x "${HDW:-target/debug/hdw}" ] || cargo build -p hd-cli
# The FMU binary `hdw export fmu` packs (test_fmu.py): hd-fmu's shared library, which cargo
# leaves beside target/debug/hdw (deps/ when hd-fmu was built as hdw's dependency).
[ -n "${HDW:-}" ] || [ -e target/debug/libhd_fmu.so ] || [ -e target/debug/deps/libhd_fmu.so ] \
    || cargo build -p hd-fmu
# From the repository root, so that the installed package is imported, not python/hdw.
HDW="${HDW:-$PWD/target/debug/hdw}" "$venv/bin/python" -m pytest -q tests/python
