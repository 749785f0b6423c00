#!/usr/bin/env bash
# The scale benchmark as one table, paired against another binary: each input run by BEFORE and
# by this checkout's release binary in turn (B A B A …, RUNS pairs, default 3), wall time and
# peak resident memory from /usr/bin/time -v of each whole process, medians and the median of
# the pairs' ratios A/B, and whether both wrote the same skeletons (their WKT compared). Inputs:
#   - the rough 1 000 000-vertex polygon through MA alone (scripts/make_rough_polygon.py);
#   - the rough 200 000-vertex polygon through the default pipeline (all five methods);
#   - every GSHHG island under 1 000 km² (KIND=islands scripts/make-gshhg-lakes.sh: 179 870
#     islands, 4.39 M vertices) through the default pipeline, and through MA alone.
# The partition step has its own benchmark (scripts/bench-partition.sh).
#
#   BEFORE=/path/to/old/skeletonise scripts/bench-scale.sh
#   BEFORE=… RUNS=1 ONLY="islands islands-MA" scripts/bench-scale.sh
#
# Writes target/bench/scale.md and target/bench/scale-*.{time,gpkg}. The inputs are generated
# once into target/bench (never committed): the rough polygons need the Python venv
# (scripts/python-env.sh), the islands the Debian packages gmt gmt-gshhg-full. Takes about
# 25 minutes on 2 cores with RUNS=3.
set -euo pipefail
cd "$(dirname "$0")/.."
BEFORE=${BEFORE:?give BEFORE=/path/to/the/other/skeletonise}
RUNS=${RUNS:-3}
ONLY=" ${ONLY:-rough-1M-MA rough-200k islands islands-MA} "
WORK=$PWD/target/bench
mkdir -p "$WORK"
[ -x /usr/bin/time ] || { apt-get update -qq && apt-get install -y -qq --no-install-recommends time >/dev/null; }
PY=$PWD/target/py-venv/bin/python
cargo build --release --quiet
AFTER=$PWD/target/release/skeletonise

rough() { # N: the rough polygon's file
  local f=$WORK/rough-input-$1.gpkg
  [ -f "$f" ] || { [ -x "$PY" ] || scripts/python-env.sh --no-wheel >/dev/null; "$PY" scripts/make_rough_polygon.py "$1" "$f" >/dev/null; }
  echo "$f"
}
islands() {
  local f=$WORK/gshhg-islands.gpkg
  [ -f "$f" ] || KIND=islands scripts/make-gshhg-lakes.sh "$f" >/dev/null
  echo "$f"
}

wall() { sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$1" |
  awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; printf "%.2f", s }'; }
rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1" | awk '{ printf "%.0f", $1 / 1024 }'; }
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else printf "%.3f\n", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
wkt() { ogr2ogr -f CSV /vsistdout/ "$1" skeletons -lco GEOMETRY=AS_WKT -select src_fid,method 2>/dev/null | md5sum | cut -c1-12; }

echo "| run | pairs | wall B → A (s) | A/B wall (median of pairs) | peak RSS B → A (MiB) | same skeletons |" >"$WORK/scale.md"
echo "|---|--:|--:|--:|--:|---|" >>"$WORK/scale.md"

case_() { # NAME INPUT [--set …]
  local name=$1 input=$2; shift 2
  [[ $ONLY == *" $name "* ]] || return 0
  local wa=() wb=() ra=() rb=() q=()
  for i in $(seq "$RUNS"); do
    for who in B A; do
      local bin=$AFTER; [ "$who" = B ] && bin=$BEFORE
      local out=$WORK/scale-$name-$who.gpkg
      rm -f "$out"
      /usr/bin/time -v "$bin" run -i "$input" -o "$out" -q "$@" >/dev/null 2>"$WORK/scale-$name-$who.time" ||
        { echo "$name: $who failed (see $WORK/scale-$name-$who.time)" >&2; exit 1; }
      if [ "$who" = B ]; then wb+=("$(wall "$WORK/scale-$name-B.time")"); rb+=("$(rss "$WORK/scale-$name-B.time")")
      else wa+=("$(wall "$WORK/scale-$name-A.time")"); ra+=("$(rss "$WORK/scale-$name-A.time")"); fi
    done
    q+=("$(awk -v a="${wa[-1]}" -v b="${wb[-1]}" 'BEGIN { printf "%.3f", a / b }')")
  done
  local same=no
  [ "$(wkt "$WORK/scale-$name-A.gpkg")" = "$(wkt "$WORK/scale-$name-B.gpkg")" ] && same=yes
  printf '| %s | %d | %s → %s | %s× | %s → %s | %s |\n' "$name" "$RUNS" \
    "$(printf '%s\n' "${wb[@]}" | median)" "$(printf '%s\n' "${wa[@]}" | median)" \
    "$(printf '%s\n' "${q[@]}" | median)" \
    "$(printf '%s\n' "${rb[@]}" | median)" "$(printf '%s\n' "${ra[@]}" | median)" "$same" >>"$WORK/scale.md"
  tail -1 "$WORK/scale.md"
}

[[ $ONLY == *" rough-1M-MA "* ]] && case_ rough-1M-MA "$(rough 1000000)" --set 'steps.skeleton.methods=[MA]'
[[ $ONLY == *" rough-200k "* ]] && case_ rough-200k "$(rough 200000)"
[[ $ONLY == *" islands "* ]] && case_ islands "$(islands)"
[[ $ONLY == *" islands-MA "* ]] && case_ islands-MA "$(islands)" --set 'steps.skeleton.methods=[MA]'
{
  echo
  echo "B: $BEFORE; A: $AFTER ($(git rev-parse --short HEAD)); $(nproc) cores, $(date -u +%F)."
} >>"$WORK/scale.md"
echo "wrote $WORK/scale.md"
