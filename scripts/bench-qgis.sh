#!/usr/bin/env bash
# The QGIS provider's overhead: `skeletonise:skeletonise` through processing.run in QGIS's
# Python against `skeletonise.skeletonise` in the package's venv, on the same layers, runs
# interleaved (QGIS, Python, QGIS, …), with the release wheel. Usage:
#   scripts/bench-qgis.sh [RUNS] [SRC LAYER]…     (default: 5 runs; the training islands, Lena, lochs)
# Prints the median of each side and their ratio per layer (scripts/bench_qgis.py).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
shift || true
if [ $# -eq 0 ]; then
  set -- tests/data/gshhg-train.gpkg islands_hebrides tests/data/gshhg-train.gpkg river_lena \
    tests/data/gshhg-train.gpkg lakes_scotland
fi
SKELETONISE_WHEEL_PROFILE=release scripts/python-env.sh
while [ $# -ge 2 ]; do
  src=$1 layer=$2
  shift 2
  q=() p=()
  for _ in $(seq "$runs"); do
    q+=("$(scripts/qgis-process.sh --python scripts/bench_qgis.py qgis "$src" "$layer" 1 2>/dev/null | tail -n 1)")
    p+=("$(target/py-venv/bin/python scripts/bench_qgis.py python "$src" "$layer" 1 | tail -n 1)")
  done
  printf '%s\n' "${q[@]}" "${p[@]}" | target/py-venv/bin/python scripts/bench_qgis.py summary
done
