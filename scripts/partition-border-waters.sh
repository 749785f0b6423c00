#!/usr/bin/env bash
# Partitions the six real border waters of tests/data/border-waters.gpkg (DCW units that cover
# GSHHG lakes and river-lakes, made by scripts/make_border_waters.py) with
# pipelines/partition-border-waters.yaml, the units as given (UTM) and in EPSG:4326, and prints one
# Markdown table: what was rejected, the coverage's validity (GEOS), area, nearest bank, centring (z),
# how far the legal lines inside the water lie from the new boundaries, and the largest relative
# difference of a unit's area between the two CRSs (scripts/partition_quality.py --covering).
#   scripts/partition-border-waters.sh [BINARY]      # default target/release/skeletonise
# Needs the Python environment of scripts/python-env.sh (shapely, pyogrio).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-target/release/skeletonise}
py=${PYTHON:-target/py-venv/bin/python}
src=tests/data/border-waters.gpkg
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| case | waters (vertices) | units | held (km²) | rejected | valid coverage | area (rel.) | nearest | mean z | legal line from the new one: median (of the width), max (km) | EPSG:4326 units: largest area difference (rel.) | wall (s) |"
echo "|---|--:|--:|--:|--:|---|--:|--:|--:|--:|--:|--:|"
for c in geneva constance erie titicaca parana victoria; do
    t0=$(date +%s.%N)
    SKELETONISE_SRC=$src "$bin" run pipelines/partition-border-waters.yaml --set input.layer=waters_$c \
        --set input.neighbours.layer=units_$c -o "$out/$c.gpkg" -q 2>/dev/null
    t1=$(date +%s.%N)
    SKELETONISE_SRC=$src "$bin" run pipelines/partition-border-waters.yaml --set input.layer=waters_$c \
        --set input.neighbours.layer=units_${c}_4326 -o "$out/$c-4326.gpkg" -q 2>/dev/null
    "$py" - "$src" "$c" "$out" "$t0" "$t1" <<'PY'
import json, subprocess, sys
import numpy as np, pyogrio, shapely
sys.path.insert(0, "scripts")
import partition_quality as q
src, c, out, t0, t1 = sys.argv[1:6]
wall = float(t1) - float(t0)
m = q.measure_ours(src, f"waters_{c}", f"units_{c}", f"{out}/{c}.gpkg", samples=20000, covering=True)
w = pyogrio.read_dataframe(src, layer=f"waters_{c}")
u = pyogrio.read_dataframe(src, layer=f"units_{c}")
layers = [n for n, _ in pyogrio.list_layers(f"{out}/{c}.gpkg")]
rej = len(pyogrio.read_dataframe(f"{out}/{c}.gpkg", layer="rejected")) if "rejected" in layers else 0
a = pyogrio.read_dataframe(f"{out}/{c}.gpkg", layer="coverage")
b = pyogrio.read_dataframe(f"{out}/{c}-4326.gpkg", layer="coverage")
diff = float(np.max(np.abs(a.geometry.area.values - b.geometry.area.values) / a.geometry.area.values))
nv = int(shapely.get_num_coordinates(w.geometry.values).sum())
print(f"| {c} | {len(w)} ({nv}) | {len(u)} | {m['held'] / 1e6:.1f} | {rej} | {m['coverage_valid'] and m['all_valid']} | "
      f"{m['area_rel']:.1e} | {m['nearest']:.4f} | {m['z_mean']:.6f} | {m['legal_offset_median']:.2f}, "
      f"{m['legal_offset_max'] / 1000:.1f} | {diff:.1e} | {float(wall):.2f} |")
PY
done
