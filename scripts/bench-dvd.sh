#!/usr/bin/env bash
# DVD against pygeoops.centerline, side by side in one run, on river_lena and
# islands_hebrides: the same boundary points on both sides (see
# scripts/bench_dvd_peer.py for how the shared spacing is chosen), wall time of
# the skeleton step, wall time and peak RSS of the whole process
# (/usr/bin/time -v), and the ratios.
#
#   scripts/bench-dvd.sh [DATA.gpkg]
#
# pygeoops, shapely, geopandas and pyogrio are installed from PyPI into
# target/bench-dvd/venv by this script; the crate itself never needs them.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=${1:-tests/data/gshhg-train.gpkg}
LAYERS=${LAYERS:-"river_lena islands_hebrides"}
WORK=target/bench-dvd
mkdir -p "$WORK"

if [ ! -x /usr/bin/time ]; then
    apt-get update -qq && apt-get install -y -qq time >/dev/null
fi
if [ ! -x "$WORK/venv/bin/python" ]; then
    python3 -m venv "$WORK/venv"
fi
"$WORK/venv/bin/pip" install -q --disable-pip-version-check pygeoops shapely geopandas pyogrio
PY="$WORK/venv/bin/python"
echo "pygeoops $("$PY" -c 'import pygeoops; print(pygeoops.__version__)')," \
     "shapely $("$PY" -c 'import shapely; print(shapely.__version__)'), GEOS $("$PY" -c 'import shapely; print(shapely.geos_version_string)')"

cargo build --release --quiet --example dvd_layer
OURS=target/release/examples/dvd_layer

field() { tr '\t' '\n' <"$1" | sed -n "s/^$2=//p" | head -1; }
wall() { sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$1" |
    awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s }'; }
div() { awk -v a="$1" -v b="$2" 'BEGIN { print a / b }'; }
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1" | awk '{ printf "%.0f", $1 / 1024 }'; }

# run NAME CMD...: stdout to $WORK/NAME.out, /usr/bin/time -v to $WORK/NAME.time
run() {
    local name=$1
    shift
    /usr/bin/time -v -o "$WORK/$name.time" "$@" >"$WORK/$name.out"
    cat "$WORK/$name.out"
}

ROWS=()
for layer in $LAYERS; do
    d=$("$PY" scripts/bench_dvd_peer.py "$DATA" "$layer" spacing)
    echo "== $layer: shared spacing d = $d"
    run "$layer-ours-1" "$OURS" "$DATA" "$layer" "spacing:$d" --threads 1
    run "$layer-ours-all" "$OURS" "$DATA" "$layer" "spacing:$d"
    run "$layer-peer" "$PY" scripts/bench_dvd_peer.py "$DATA" "$layer" run "$d"
    ROWS+=("$layer")
done

echo
printf '%-17s %9s %9s | %9s %9s %9s | %7s %7s | %9s %9s %7s | %7s %7s\n' \
    layer "points" "peer pts" "DVD 1thr" "DVD all" pygeoops "ratio1" "ratioN" \
    "wall DVD" "wall peer" "ratio" "RSS MB" "peer MB"
for layer in "${ROWS[@]}"; do
    o1="$WORK/$layer-ours-1"; on="$WORK/$layer-ours-all"; pe="$WORK/$layer-peer"
    s1=$(field "$o1.out" seconds); sn=$(field "$on.out" seconds); sp=$(field "$pe.out" seconds)
    w1=$(wall "$o1.time"); wp=$(wall "$pe.time")
    printf '%-17s %9s %9s | %8.3fs %8.3fs %8.3fs | %6.1fx %6.1fx | %8.2fs %8.2fs %6.1fx | %7s %7s\n' \
        "$layer" "$(field "$o1.out" points)" "$(field "$pe.out" points)" "$s1" "$sn" "$sp" \
        "$(div "$sp" "$s1")" "$(div "$sp" "$sn")" \
        "$w1" "$wp" "$(div "$wp" "$w1")" "$(rss "$o1.time")" "$(rss "$pe.time")"
done
echo
echo "DVD 1thr / DVD all / pygeoops: seconds of the skeleton step alone (reading excluded);"
echo "ratio1, ratioN: pygeoops time over ours on 1 thread and on all $(nproc) cores."
echo "wall, RSS: the whole process under /usr/bin/time -v (reading, start-up, Python imports), ours on 1 thread."
