#!/usr/bin/env bash
# Raster staircases on data the project was not tuned to: the five largest GSHHG river-lakes that
# fit in 250 km × 250 km (none of them a training river), each as a water mask would give it —
# rasterised at 30 m (gdal_rasterize) and vectorised again (gdal_polygonize -8, the largest piece) —
# beside its vector form. `scripts/quality.sh` counts hooks, legs, Z and pieces per method and for
# the chosen skeleton (every method run, the pipeline of `pipelines/compare-methods.yaml`).
#
#   scripts/raster-riverlakes.sh [OUT.md]     # default: docs/raster-riverlakes.md
#   CELL=10 scripts/raster-riverlakes.sh /tmp/rr10.md   # another cell size (metres; default 30)
#
# Needs target/bench/gshhg-lakes.gpkg (made by scripts/make-gshhg-lakes.sh from the Debian packages
# gmt and gmt-gshhg-full) and GDAL's utilities. Takes about half a minute after the build.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
OUT=${1:-docs/raster-riverlakes.md}
CELL=${CELL:-30}
LAKES=target/bench/gshhg-lakes.gpkg
WORK=target/bench/raster-riverlakes
if [ ! -f "$LAKES" ]; then
  echo "error: $LAKES is missing; make it with scripts/make-gshhg-lakes.sh" >&2
  exit 1
fi
rm -rf "$WORK"
mkdir -p "$WORK"
DATA=$WORK/riverlakes.gpkg
quiet() { grep -v "proj_as_wkt" || true; }   # GDAL 3.6 on EPSG:8857, see make-gshhg-lakes.sh

ids=$(ogrinfo -q -ro -dialect SQLite "$LAKES" -sql "SELECT id FROM lakes WHERE riverlake = 1
        AND ST_MaxX(geom) - ST_MinX(geom) < 250000 AND ST_MaxY(geom) - ST_MinY(geom) < 250000
        ORDER BY area_km2 DESC LIMIT 5" 2>&1 | sed -n 's/^ *id (Integer[0-9]*) = //p')
[ "$(echo "$ids" | wc -w)" = 5 ] || { echo "error: expected 5 river-lakes, found: $ids" >&2; exit 1; }
layers=()
for id in $ids; do
  ogr2ogr -f GPKG -update -append "$DATA" "$LAKES" lakes -where "id = $id" -nln "vector_$id" \
    -nlt POLYGON 2>&1 | quiet
  gdal_rasterize -q -burn 1 -tr "$CELL" "$CELL" -ot Byte -a_nodata 0 -l "vector_$id" "$DATA" "$WORK/$id.tif" 2>&1 | quiet
  gdal_polygonize.py -q -8 "$WORK/$id.tif" -f GPKG "$WORK/$id-poly.gpkg" poly v 2>&1 | quiet
  ogr2ogr -f GPKG -update -append "$DATA" "$WORK/$id-poly.gpkg" -nln "raster_$id" -nlt POLYGON \
    -sql "SELECT * FROM poly WHERE v = 1 ORDER BY ST_Area(geom) DESC LIMIT 1" 2>&1 | quiet
  layers+=("vector_$id" "raster_$id")
done
DATA=$DATA LAYERS="${layers[*]}" OUT="$OUT" scripts/quality.sh
# The whole run of the default pipeline with every method, per layer (2 threads).
cargo build --release -q
times=$WORK/times.md
{
  echo "## Whole runs with every method"
  echo
  echo "\`skeletonise run\` with \`pipelines/compare-methods.yaml\` on each layer, \`/usr/bin/time -v\`, one run."
  echo
  echo "| layer | boundary vertices | wall s | max RSS MB | chosen |"
  echo "|---|--:|--:|--:|---|"
  for L in "${layers[@]}"; do
    /usr/bin/time -v -o "$WORK/$L.time" target/release/skeletonise run -q pipelines/compare-methods.yaml \
      --set "input.source=$DATA" --set "input.layer=$L" --set output.report=null \
      -o "$WORK/$L.gpkg" 2>/dev/null
    n=$(ogrinfo -q -ro -dialect SQLite "$DATA" -sql "SELECT ST_NPoints(geom) AS n FROM \"$L\"" |
      sed -n 's/^ *n (Integer[0-9]*) = //p')
    wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$WORK/$L.time" |
      awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; printf "%.2f", s }')
    rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$WORK/$L.time" | awk '{ printf "%.0f", $1 / 1024 }')
    chosen=$(ogrinfo -q -ro "$WORK/$L.gpkg" -sql "SELECT method FROM skeletons" | sed -n 's/^ *method (String) = //p' | sort | uniq -c | awk '{ printf "%s%s×%s", sep, $2, $1; sep = ", " }')
    echo "| $L | $n | $wall | $rss | $chosen |"
  done
} >"$times"
# Title and provenance above the tables of scripts/quality.sh.
{
  echo "# Raster staircases on river-lakes the project was not tuned to"
  echo
  echo "Made by \`scripts/raster-riverlakes.sh\`: the five largest GSHHG river-lakes that fit in 250 km ×"
  echo "250 km (ids $(paste -sd, <<<"$ids") of \`target/bench/gshhg-lakes.gpkg\`), each as \`vector_ID\` and as"
  echo "\`raster_ID\` (rasterised at $CELL m, \`gdal_polygonize -8\`, the largest piece, repaired by"
  echo "\`prepare: { make_valid: true }\`). GSHHG: Wessel, P., and W. H. F. Smith, A Global Self-consistent,"
  echo "Hierarchical, High-resolution Shoreline Database, J. Geophys. Res., 101, 8741–8743, 1996 (LGPL)."
  echo
  tail -n +3 "$OUT"
  echo
  cat "$times"
} >"$OUT.tmp"
mv "$OUT.tmp" "$OUT"
