#!/usr/bin/env bash
# The `partition` step's benchmark, one run: N collapsed polygons from the training data (the
# Scottish lochs and the Danube reach, smooth, and the lochs as a raster of 40 m cells makes
# them, staircase banks), each with a coverage of about ten units around it
# (scripts/make_partition_bench.py; 1 000 polygons, 10 000 units by default), through
#   A: MA with prune and extend (the centrelines), and
#   B: the same with `partition`;
# wall time, CPU time and peak RSS from /usr/bin/time -v of each whole process. The step's own
# cost is its thread CPU time in B's run record (skeletonise_runs.stage_seconds: "partition", the
# polygons, the cells of the medial axis's diagram it splits — made beside MA's skeleton, counted
# here, not in "skeleton" — and the coverage assembled at the end); the MA skeleton's is its thread CPU time there
# too ("MA": "skeleton"). The whole run's extra cost (B's CPU time less A's) also counts reading
# the units and writing them grown. Then GEOS CoverageCleaner (shapely.coverage_clean, longest
# border) on the same units, for scale.
#
#   scripts/bench-partition.sh              # N=1000
#   N=200 scripts/bench-partition.sh
#
# Writes target/bench/partition.md and target/bench/partition-*.{time,log}; the data
# (target/bench/partition-N.gpkg) is generated once and never committed.
set -euo pipefail
cd "$(dirname "$0")/.."
N=${N:-1000}
WORK=$PWD/target/bench
mkdir -p "$WORK"
[ -x /usr/bin/time ] || { apt-get update -qq && apt-get install -y -qq --no-install-recommends time >/dev/null; }
[ -x target/py-venv/bin/python ] || scripts/python-env.sh >/dev/null
PY=$PWD/target/py-venv/bin/python
DATA=$WORK/partition-$N.gpkg
[ -f "$DATA" ] || "$PY" scripts/make_partition_bench.py "$DATA" --rivers "$N"
cargo build --release --quiet
BIN=$PWD/target/release/skeletonise

pipeline() { # NAME EXTRA_INPUT EXTRA_STEPS
  cat >"$WORK/partition-$1.yaml" <<EOF
name: bench-partition-$1
input:
  source: $DATA
  layer: rivers
$2
steps:
  - skeleton: { methods: [MA] }
  - prune: {}
  - extend: {}
$3
output: { path: $WORK/partition-$1.gpkg, overwrite: true }
EOF
}
pipeline ma "" ""
pipeline partition "  neighbours: { source: $DATA, layer: units }" "  - partition: {}"

for run in ma partition; do
  /usr/bin/time -v "$BIN" run "$WORK/partition-$run.yaml" -q 2>"$WORK/partition-$run.time" >/dev/null
done
/usr/bin/time -v "$PY" - "$DATA" <<'EOF' 2>"$WORK/partition-peer.time"
import sys, pyogrio, shapely
u = pyogrio.read_dataframe(sys.argv[1], layer="units")
shapely.coverage_clean(u.geometry.values, gap_width=50000.0)
EOF

wall() { sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$1" |
  awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; printf "%.2f", s }'; }
cpu() { awk -F': ' '/User time|System time/ { s += $2 } END { printf "%.2f", s }' "$1"; }
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1" | awk '{ printf "%.0f", $1 / 1024 }'; }
read -r ma_skeleton own <<<"$("$PY" -c "
import json, sys, pyogrio
r = pyogrio.read_dataframe(sys.argv[1], layer='skeletonise_runs', read_geometry=False)
s = json.loads(r.stage_seconds.iloc[-1])
print('%.2f %.2f' % (s['MA']['skeleton'], s['partition']))" "$WORK/partition-partition.gpkg")"
counts=$("$PY" -c "
import sys, pyogrio, shapely
r = pyogrio.read_dataframe(sys.argv[1], layer='rivers')
u = pyogrio.read_info(sys.argv[1], layer='units')['features']
print(len(r), int(shapely.get_num_coordinates(r.geometry.values).sum()), u)" "$DATA")
read -r polys verts units <<<"$counts"
step=$(awk -v b="$(cpu "$WORK/partition-partition.time")" -v a="$(cpu "$WORK/partition-ma.time")" 'BEGIN { printf "%.2f", b - a }')
{
  echo "## partition: $polys polygons ($verts vertices), $units units"
  echo
  echo "$(date -u +%Y-%m-%d), commit $(git rev-parse --short HEAD), $(nproc) cores"
  echo
  echo "| run | wall s | CPU s | peak RSS MB |"
  echo "|---|--:|--:|--:|"
  for run in ma partition peer; do
    case $run in
      ma) label="A: MA, prune, extend";;
      partition) label="B: A + partition";;
      peer) label="GEOS CoverageCleaner (longest border), same units";;
    esac
    echo "| $label | $(wall "$WORK/partition-$run.time") | $(cpu "$WORK/partition-$run.time") | $(rss "$WORK/partition-$run.time") |"
  done
  echo
  echo "The step: $own CPU s (B's stage_seconds), $(awk -v s="$own" -v m="$ma_skeleton" 'BEGIN { printf "%.2f", s / m }')× the MA skeleton's $ma_skeleton CPU s; the whole run's extra CPU time (B − A, with reading and writing the units) $step s, $(awk -v s="$step" -v m="$ma_skeleton" 'BEGIN { printf "%.2f", s / m }')×."
} | tee "$WORK/partition.md"
