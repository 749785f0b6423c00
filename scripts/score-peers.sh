#!/usr/bin/env bash
# Peer scores (issue 7): skeletons of lakes_scotland and islands_hebrides made
# by two other tools — pygeoops.centerline (PyPI) and GRASS `v.voronoi -s`
# (Debian grass-core) — written to GeoPackages with the source FID, then
# scored with skeletonise's metrics next to our own methods.
#
# usage: scripts/score-peers.sh            (installs what it needs; root for apt)
# env:   DATA=…gshhg-train.gpkg  OUT=target/score-peers  LAYERS="…"  METHODS="CDT MA"
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
DATA=${DATA:-$ROOT/../shared/data/gshhg-train.gpkg}
OUT=${OUT:-$ROOT/target/score-peers}
LAYERS=${LAYERS:-"lakes_scotland islands_hebrides"}
METHODS=${METHODS:-"CDT"}
mkdir -p "$OUT"
DATA=$(realpath "$DATA")

# --- tools -------------------------------------------------------------------
if [ ! -x "$OUT/venv/bin/python" ]; then
  python3 -m venv "$OUT/venv"
fi
"$OUT/venv/bin/python" -c "import pygeoops, geopandas, pyogrio" 2>/dev/null ||
  "$OUT/venv/bin/pip" install -q pygeoops geopandas pyogrio
if ! command -v grass >/dev/null; then
  apt-get update -qq && apt-get install -y -qq --no-install-recommends grass-core
fi
(cd "$ROOT" && cargo build --release -q --example score_file)
SCORE="$ROOT/target/release/examples/score_file"

# --- peer skeletons ----------------------------------------------------------
rm -f "$OUT/pygeoops.gpkg" "$OUT"/grass-*.gpkg
for L in $LAYERS; do
  "$OUT/venv/bin/python" "$ROOT/scripts/score_peers_pygeoops.py" "$DATA" "$L" "$OUT/pygeoops.gpkg"
  EPSG=$(ogrinfo -so "$DATA" "$L" | sed -n 's/.*ID\["EPSG",\([0-9]*\)\]\]$/\1/p' | tail -1)
  # v.in.ogr numbers areas 1..N in feature order = the source FIDs (1..N in
  # the training file); v.voronoi -s gives each skeleton its area's cat.
  start=$(date +%s.%N)
  grass --tmp-location "EPSG:$EPSG" --exec bash -c "
    set -e
    v.in.ogr -o --q input='$DATA' layer='$L' output=poly
    g.region --q vector=poly
    v.voronoi -s --q input=poly output=skel
    v.out.ogr --q input=skel type=line output='$OUT/grass-$L.gpkg' output_layer='$L' format=GPKG
  " >"$OUT/grass-$L.log" 2>&1 || { echo "GRASS failed on $L: see $OUT/grass-$L.log" >&2; exit 1; }
  echo -e "$L\tGRASS v.voronoi -s\t$(echo "$(date +%s.%N) - $start" | bc)s"
done

# --- scores ------------------------------------------------------------------
for L in $LAYERS; do
  for M in $METHODS; do
    "$SCORE" "$DATA" "$L" --method "$M" --raw --csv "$OUT/$L-$M-raw.csv"
    "$SCORE" "$DATA" "$L" --method "$M" --csv "$OUT/$L-$M.csv"
  done
  "$SCORE" "$DATA" "$L" --skeletons "$OUT/pygeoops.gpkg" "$L" --fid-field src_fid --csv "$OUT/$L-pygeoops.csv"
  "$SCORE" "$DATA" "$L" --skeletons "$OUT/grass-$L.gpkg" "$L" --fid-field cat --csv "$OUT/$L-grass.csv"
done | tee "$OUT/scores.tsv"
