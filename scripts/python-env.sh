#!/usr/bin/env bash
# Makes the Python environment under target/py-venv (nothing is installed system-wide):
# maturin, pytest, GeoPandas, Dask from PyPI, then builds the package's wheel into
# target/wheels with scripts/build-wheel.sh (abi3, manylinux_2_28: the wheel that installs
# on any Linux, checked by auditwheel) and installs it there. The wheel is built with the
# cargo profile $SKELETONISE_WHEEL_PROFILE (default release, as CI).
#   scripts/python-env.sh             # the environment and the wheel
#   scripts/python-env.sh --no-wheel  # the environment only (scripts/build-wheel.sh uses it)
# On a fresh Debian/Ubuntu machine it first installs Python's venv module and headers (the
# binding's unit tests link to libpython) when they are missing.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/py-venv
py=${PYTHON:-python3}
has_libpython() {
  "$1" -c 'import os, sys, sysconfig as s
d, l = s.get_config_var("LIBDIR"), s.get_config_var("LDLIBRARY")
sys.exit(0 if d and l and os.path.exists(os.path.join(d, l)) else 1)'
}
if ! command -v "$py" >/dev/null 2>&1 || ! "$py" -c 'import venv, ensurepip' 2>/dev/null || ! has_libpython "$py"; then
  scripts/apt-install.sh "for the Python package" python3 python3-venv python3-dev
  py=python3
fi
[ -x "$venv/bin/python" ] || "$py" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q maturin pytest geopandas dask distributed dask-geopandas pyarrow "shapely>=2.2" pyogrio
if [ "${1:-}" = --no-wheel ]; then
  exit 0
fi
# It leaves one wheel in target/wheels, or fails.
scripts/build-wheel.sh
"$venv/bin/python" -m pip install -q --force-reinstall --no-deps target/wheels/skeletonise-*.whl
