#!/usr/bin/env bash
# Network pruning at scale: one lake (a wavy strip 100 km × 2 km, 2 002 vertices) crossed N times
# by one zig-zag line, `prune: {mode: network}` with MA alone — the through-lines between
# N connection points. Prints a markdown table: crossings, wall seconds (median of 3) and peak
# resident MB of BIN, and of BEFORE (another binary, e.g. one built before a change) when given,
# side by side with their ratio. A run of BEFORE past TIMEOUT seconds (default 300) is stopped and
# shown as ">TIMEOUT".
#
#   scripts/bench-network.sh                        # 2 000, 10 000, 20 000 crossings
#   BEFORE=/path/to/old/skeletonise SIZES="2000 5000" scripts/bench-network.sh
#
# Needs gdal-bin (ogr2ogr), python3, /usr/bin/time, and a built target/release/skeletonise.
# Writes target/bench/network/zz-N.gpkg (the data), the outputs beside them, and the table to
# target/bench/network.md.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
BIN=${BIN:-$ROOT/target/release/skeletonise}
BEFORE=${BEFORE:-}
SIZES=${SIZES:-2000 10000 20000}
TIMEOUT=${TIMEOUT:-300}
OUT=$ROOT/target/bench/network
mkdir -p "$OUT"
cat > "$OUT/p.yaml" <<'YAML'
name: bench-network
input:
  source: ${ZZ}
  layer: lake
  connect:
    source: ${ZZ}
    layer: lines
steps:
  - skeleton:
      methods: [MA]
      timeout_s: 0
  - prune:    { mode: network }
  - score:    {}
  - select:   { by: distortion }
output:
  path: ${OUT}
  overwrite: true
on_error: reject
YAML
make_data() { # crossings → the GeoPackage
  local n=$1 f=$OUT/zz-$1.gpkg
  [ -f "$f" ] && { echo "$f"; return; }
  python3 - "$n" "$OUT/zz-$n" <<'PY'
import math, sys
n, out = int(sys.argv[1]), sys.argv[2]
L, W, m = 100000.0, 2000.0, 1000
top = [(L * i / m, W / 2 + 150 * math.sin(i / 37.0)) for i in range(m + 1)]
bottom = [(L * i / m, -W / 2 + 150 * math.cos(i / 23.0)) for i in range(m, -1, -1)]
ring = top + bottom + [top[0]]
k = n // 2
line = [(500 + (L - 1000) * i / k, 2 * W if i % 2 == 0 else -2 * W) for i in range(k + 1)]
text = lambda pts: ",".join(f"{x} {y}" for x, y in pts)
open(out + ".lake.csv", "w").write(f'id,WKT\n1,"POLYGON(({text(ring)}))"\n')
open(out + ".lines.csv", "w").write(f'id,WKT\n1,"LINESTRING({text(line)})"\n')
PY
  local opts=(-a_srs EPSG:32633 -oo GEOM_POSSIBLE_NAMES=WKT -oo KEEP_GEOM_COLUMNS=NO)
  ogr2ogr -q -f GPKG "$f" "$OUT/zz-$n.lake.csv" -nln lake "${opts[@]}"
  ogr2ogr -q -update "$f" "$OUT/zz-$n.lines.csv" -nln lines "${opts[@]}"
  rm -f "$OUT/zz-$n".*.csv
  echo "$f"
}
# Median wall seconds and peak MB of 3 runs of binary $1 on data $2 ("> TIMEOUT" when stopped).
measure() {
  local bin=$1 data=$2 t=() m=() i line
  for i in 1 2 3; do
    if ! line=$(ZZ=$data OUT=$OUT/out.gpkg timeout "$TIMEOUT" /usr/bin/time -f "%e %M" \
        "$bin" run "$OUT/p.yaml" -q 2>&1 >/dev/null | tail -n 1); then
      echo ">$TIMEOUT -"; return
    fi
    t+=("${line% *}"); m+=("${line#* }")
  done
  printf '%s %s\n' "$(printf '%s\n' "${t[@]}" | sort -g | sed -n 2p)" \
    "$(( $(printf '%s\n' "${m[@]}" | sort -g | sed -n 2p) / 1024 ))"
}
{
  if [ -n "$BEFORE" ]; then
    echo "| crossings | s | MB | s before | MB before | ratio |"
    echo "|---:|---:|---:|---:|---:|---:|"
  else
    echo "| crossings | s | MB |"
    echo "|---:|---:|---:|"
  fi
  for n in $SIZES; do
    data=$(make_data "$n")
    read -r s mb <<<"$(measure "$BIN" "$data")"
    if [ -n "$BEFORE" ]; then
      read -r bs bmb <<<"$(measure "$BEFORE" "$data")"
      ratio=$(python3 -c "import sys; a, b = sys.argv[1:]; print(f'< {float(a) / float(b[1:]):.3f}' if b.startswith('>') else f'{float(a) / float(b):.3f}')" "$s" "$bs")
      echo "| $n | $s | $mb | $bs | $bmb | $ratio |"
    else
      echo "| $n | $s | $mb |"
    fi
  done
} | tee "$OUT/network.md"
cp "$OUT/network.md" "$ROOT/target/bench/network.md"
