#!/usr/bin/env bash
# The Python package's measurements, one run on this machine (see scripts/bench_python.py):
# the command line against skeletonise.apply on the training islands and rivers (compute
# time and conversion overhead), pygeoops.centerline against skeletonise.skeletonise on the
# same GeoSeries, and the Dask example on a generated layer with 1 and 2 workers.
#   scripts/bench-python.sh [N_POLYGONS [REPEAT]]     # default 100000 polygons, best of 3
# Builds the release binary and wheel first; the generated layer goes to target/bench/.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/py-venv
cargo build --release --quiet --bin skeletonise
scripts/python-env.sh
"$venv/bin/python" -m pip install -q pygeoops
exec "$venv/bin/python" scripts/bench_python.py target/release/skeletonise "${1:-100000}" "${2:-3}"
