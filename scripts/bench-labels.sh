#!/usr/bin/env bash
# Lake label lines, side by side: the peer tool label_centerlines (PyPI label-centerlines
# 2022.6.0, its CLI's defaults, via scripts/label_centerlines_peer.py) against
# `skeletonise run pipelines/lake-labels.yaml` (its `line` labels) on the lakes_scotland layer.
# Both sets of lines are scored with `skeletonise score` (distortion Z: lower is better;
# coverage: the share of the polygon's cross-bars the line hits) and a markdown table is printed:
# tool, lakes, lakes with a line, wall seconds of the whole run (start-up included), seconds per
# lake (label_centerlines: the median of its per-lake get_centerline times; skeletonise: whole run
# / lakes), Z mean (over the lakes that got a score) and worst, coverage mean (over all lakes,
# a lake without a line counting 0), curvature (each line's worst turn over a stretch one local
# width long: mean and worst), and the whole-run time ratio label_centerlines / skeletonise.
#
#   scripts/bench-labels.sh
#   DATA=…/gshhg-train.gpkg LAYER=lakes_scotland BIN=…/skeletonise scripts/bench-labels.sh
#
# Needs python3 (with venv), gdal-bin (ogr2ogr), /usr/bin/time and a built
# target/release/skeletonise (it is not built here: run `cargo build --release` first; a missing
# binary is waited for up to 5 minutes, in case a build is under way). Makes target/lc-venv with
# label-centerlines, numpy<2 (the package calls np.math, gone in numpy 2), geopandas, pyogrio and
# shapely from PyPI if it is missing. Writes target/bench/{lc-lakes,sk-labels,sk-label-lines,
# lc-lakes-scored,sk-labels-scored}.gpkg and the table to target/bench/labels.md.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
DATA=${DATA:-tests/data/gshhg-train.gpkg}
LAYER=${LAYER:-lakes_scotland}
BIN=${BIN:-$ROOT/target/release/skeletonise}
VENV=$ROOT/target/lc-venv
OUT=$ROOT/target/bench
mkdir -p "$OUT"

# --- tools -------------------------------------------------------------------
if ! "$VENV/bin/python" -c "import label_centerlines, geopandas, pyogrio" 2>/dev/null; then
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q label-centerlines==2022.6.0 "numpy<2" geopandas pyogrio shapely
fi
for _ in $(seq 10); do
  [ -x "$BIN" ] && break
  echo "waiting for $BIN (a build may be under way)…" >&2
  sleep 30
done
[ -x "$BIN" ] || { echo "no $BIN: run cargo build --release" >&2; exit 1; }

# --- label_centerlines -------------------------------------------------------
/usr/bin/time -f %e -o "$OUT/lc-lakes.time" \
  "$VENV/bin/python" scripts/label_centerlines_peer.py "$DATA" "$LAYER" "$OUT/lc-lakes.gpkg" \
  >"$OUT/lc-lakes.log"
cat "$OUT/lc-lakes.log"

# --- skeletonise ---------------------------------------------------------------
/usr/bin/time -f %e -o "$OUT/sk-labels.time" \
  "$BIN" run pipelines/lake-labels.yaml --set "input.source=$DATA" --set "input.layer=$LAYER" \
  -o "$OUT/sk-labels.gpkg" -q
rm -f "$OUT/sk-label-lines.gpkg"
ogr2ogr -f GPKG "$OUT/sk-label-lines.gpkg" "$OUT/sk-labels.gpkg" labels -where "kind = 'line'" -nln lines

# --- scores --------------------------------------------------------------------
for T in lc-lakes sk-label-lines; do
  "$BIN" score --polygons "$DATA" --polygons-layer "$LAYER" --skeletons "$OUT/$T.gpkg" \
    --skeletons-layer lines --skeleton-key src_fid -o "$OUT/$T-scored.gpkg" --overwrite -q
done

"$VENV/bin/python" - "$OUT" "$DATA" "$LAYER" <<'PY' | tee "$OUT/labels.md"
import re
import sqlite3
import statistics
import sys

out, data, layer = sys.argv[1:4]

def rows(path, sql):
    db = sqlite3.connect(path)
    try:
        return db.execute(sql).fetchall()
    finally:
        db.close()

lakes = rows(data, f'select count(*) from "{layer}"')[0][0]
summary = dict(re.findall(r"(\w+)=(\S+)", open(f"{out}/lc-lakes.log").read()))

import math

import geopandas as gpd
import shapely

polygons = gpd.read_file(data, layer=layer, fid_as_index=True).geometry


def worst_turn(line, polygon):
    """The most the line turns (degrees) over any stretch one local width long: from each
    vertex, the signed turns summed over the next 2 d of line, d the vertex's distance to the
    shore (the bound a label's letters need; the label step holds it to `smooth`, 60)."""
    pts = [p for i, p in enumerate(line.coords) if i == 0 or p != line.coords[i - 1]]
    seg = [(b[0] - a[0], b[1] - a[1]) for a, b in zip(pts, pts[1:])]
    length = [math.hypot(*d) for d in seg]
    into = [0.0] + [math.atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1])
                    for u, v in zip(seg, seg[1:])]
    shore = polygon.boundary
    worst = 0.0
    for i in range(len(pts) - 2):
        window = 2 * shore.distance(shapely.Point(pts[i]))
        along, total, j = 0.0, 0.0, i + 1
        while j < len(seg) and along < window:
            total += into[j]
            worst = max(worst, abs(total))
            along += length[j]
            j += 1
    return math.degrees(worst)


def stats(scored, lines_gpkg):
    # one row per polygon that has a line; Z is NULL where the score could not be made
    r = rows(scored, "select src_fid, distortion, coverage from skeletons")
    z = [d for _, d, _ in r if d is not None]
    cov = {f: c or 0.0 for f, _, c in r}
    with_line = rows(lines_gpkg, "select count(distinct src_fid) from lines where geom is not null")[0][0]
    lines = gpd.read_file(lines_gpkg, layer="lines")
    turns = [
        worst_turn(part, polygons[fid])
        for fid, g in zip(lines["src_fid"], lines.geometry)
        if g is not None and not g.is_empty
        for part in getattr(g, "geoms", [g])
        if len(part.coords) > 1
    ]
    return dict(
        with_line=with_line,
        z_n=len(z),
        z_mean=statistics.fmean(z) if z else float("nan"),
        z_max=max(z) if z else float("nan"),
        cov=sum(cov.values()) / lakes,  # lakes without a line count 0
        turn_mean=statistics.fmean(turns) if turns else float("nan"),
        turn_max=max(turns) if turns else float("nan"),
    )

wall = {t: float(open(f"{out}/{t}.time").read().split()[-1]) for t in ("lc-lakes", "sk-labels")}
tools = [
    ("label_centerlines 2022.6.0 (defaults)", "lc-lakes", float(summary["median_seconds"])),
    ("skeletonise lake-labels.yaml", "sk-labels", wall["sk-labels"] / lakes),
]
print(f"\n{layer}: {lakes} lakes\n")
print("| tool | lakes | lakes with a line | wall s | s per lake | Z mean (scored) | Z worst "
      "| coverage mean | turn ° per local width: mean, worst | wall ratio lc / sk |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
ratio = wall["lc-lakes"] / wall["sk-labels"]
for name, t, per in tools:
    lines = "lc-lakes" if t == "lc-lakes" else "sk-label-lines"
    s = stats(f"{out}/{lines}-scored.gpkg", f"{out}/{lines}.gpkg")
    r = f"{ratio:.1f}" if t == "lc-lakes" else "1.0"
    print(f"| {name} | {lakes} | {s['with_line']} | {wall[t]:.2f} | {per:.3f} "
          f"| {s['z_mean']:.3f} ({s['z_n']}) | {s['z_max']:.3f} | {s['cov']:.3f} "
          f"| {s['turn_mean']:.0f}, {s['turn_max']:.0f} | {r} |")
print("\nlabel_centerlines s per lake: median of its get_centerline calls; skeletonise: wall / lakes.")
print("Turn: each line's worst turn over a stretch one local width long (twice the distance to the "
      "shore); the mean of those and the worst.")
PY

# Per lake, library call against library call: skeletonise.labels on one lake at a time, one thread
# (best of 5 per lake; the Python package as scripts/test-python.sh builds it into target/py-venv),
# against the median of label_centerlines' get_centerline calls above. Skipped without the package.
if [ -x target/py-venv/bin/python ] && target/py-venv/bin/python -c "import skeletonise" 2>/dev/null; then
  target/py-venv/bin/python - "$DATA" "$LAYER" "$OUT/lc-lakes.gpkg" <<'PY' | tee -a "$OUT/labels.md"
import statistics, sys, time
import geopandas as gpd
import skeletonise
data, layer, lc = sys.argv[1:4]
lakes = gpd.read_file(data, layer=layer, fid_as_index=True)
per = []
for i in range(len(lakes)):
    one = lakes.iloc[i:i + 1]
    best = float("inf")
    for _ in range(5):
        t = time.perf_counter()
        skeletonise.labels(one, threads=1)
        best = min(best, time.perf_counter() - t)
    per.append(best)
peer = statistics.median(gpd.read_file(lc, layer="lines")["seconds"])
mine = statistics.median(per)
print(f"per lake (library calls): skeletonise.labels median {mine:.4f} s (max {max(per):.4f}), "
      f"label_centerlines median {peer:.3f} s: {peer / mine:.0f}x")
PY
else
  echo "(no skeletonise package in target/py-venv: scripts/test-python.sh builds it; per-lake calls skipped)"
fi

# The world's lakes (GSHHG level 2, full resolution, 6 660 polygons, 842 159 vertices): made by
# scripts/make-gshhg-lakes.sh (Debian gmt + gmt-gshhg-full), skipped when absent. The label step
# alone (skeleton MA, label, prune trunk: no scores) and the whole lake-labels pipeline.
WORLD=${WORLD:-target/bench/gshhg-lakes.gpkg}
if [ -f "$WORLD" ]; then
  only=target/bench/world-labels-only.yaml
  cat > "$only" <<YAML
name: world-labels-only
input: { source: $WORLD, layer: lakes }
steps:
  - prepare:  { make_valid: true }
  - skeleton: { methods: [MA] }
  - label:    {}
  - prune:    { mode: trunk }
output: { path: target/bench/world-labels-only.gpkg, overwrite: true }
YAML
  for run in "$only" pipelines/lake-labels.yaml; do
    /usr/bin/time -f "%e s, %M KB" "$BIN" run "$run" -i "$WORLD" -l lakes -o target/bench/world-labels.gpkg --overwrite -q \
      2> target/bench/world-labels.time || { cat target/bench/world-labels.time; exit 1; }
    echo "world lakes, $(basename "$run"): $(tail -1 target/bench/world-labels.time)" | tee -a target/bench/labels.md
  done
else
  echo "(no $WORLD: scripts/make-gshhg-lakes.sh makes the world's lakes for the scale run)"
fi
