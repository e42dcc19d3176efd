#!/usr/bin/env bash
# Install what benches/peers.py needs: gfortran and cmake (NumbaLSODA builds its LSODA from
# source), and a virtual environment under target/peers-venv with the pinned Python packages
# of benches/requirements-peers.txt. Safe to re-run.
#
#   benches/setup-peers.sh            # then: target/peers-venv/bin/python benches/peers.py
set -euo pipefail
cd "$(dirname "$0")/.."
need=()
command -v gfortran >/dev/null || need+=(gfortran)
command -v cmake >/dev/null || need+=(cmake)
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}"
fi
VENV=target/peers-venv
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip
"$VENV/bin/python" -m pip install -q -r benches/requirements-peers.txt
"$VENV/bin/python" -c "import numba, numbalsoda, scipy, numpy; print('peers venv ready:', \
'numpy', numpy.__version__, 'scipy', scipy.__version__, 'numba', numba.__version__)"
