#!/usr/bin/env bash
# Side-by-side benchmark of method MA (this crate, boostvoronoi) against
# PostGIS ST_ApproximateMedialAxis (SFCGAL), in one run, on the same layers.
#
#   scripts/bench-ma.sh [layer ...]        (default: river_lena river_st_lawrence river_danube islands_hebrides)
#
# Environment:
#   DATA=tests/data/gshhg-train.gpkg   input GeoPackage
#   RUNS=3                                 runs of our MA per layer (the fastest is reported)
#   PG_TIMEOUT=3600                        seconds allowed per PostGIS query
#   PG_PORT=54329                          loopback port of the throw-away cluster
#   OUT=target/bench-ma                    where the report (bench-ma.md) and raw logs go
#
# Needs (Debian): postgresql postgis postgresql-15-postgis-3 gdal-bin, and root
# (the cluster runs as user `postgres`). It initdb's a cluster in a temporary
# directory, listens on 127.0.0.1 only, and stops and removes it on exit.
#
# Times: ours is the skeletonisation of every polygon of the layer after
# reading (`ma_s` of examples/ma_layer, serial and with rayon over features);
# PostGIS's is the wall time of
#   SELECT ... ST_ApproximateMedialAxis(geom) ... FROM layer
# on the already loaded table, measured by psql's \timing. Peak memory:
# /usr/bin/time -v (max RSS) for our process, VmHWM of the PostgreSQL backend
# that ran the query for PostGIS.
set -euo pipefail

cd "$(dirname "$0")/.."
DATA=${DATA:-tests/data/gshhg-train.gpkg}
RUNS=${RUNS:-3}
PG_TIMEOUT=${PG_TIMEOUT:-3600}
PG_PORT=${PG_PORT:-54329}
OUT=${OUT:-target/bench-ma}
if [ $# -gt 0 ]; then LAYERS=("$@"); else LAYERS=(river_lena river_st_lawrence river_danube islands_hebrides); fi
DATA=$(realpath "$DATA")
mkdir -p "$OUT"
OUT=$(realpath "$OUT")

PGBIN=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -1)
for tool in "$PGBIN/initdb" "$PGBIN/pg_ctl" psql ogr2ogr runuser /usr/bin/time; do
  command -v "$tool" >/dev/null || { echo "missing $tool: apt-get install -y postgresql postgis postgresql-15-postgis-3 gdal-bin time" >&2; exit 1; }
done

echo "== building examples/ma_layer (release)"
cargo build --release --example ma_layer >/dev/null
MA=target/release/examples/ma_layer

# ---- throw-away PostgreSQL cluster ----------------------------------------
PGTMP=$(mktemp -d /tmp/bench-ma-pg.XXXXXX)
chown postgres: "$PGTMP"
as_pg() { runuser -u postgres -- "$@"; }
cleanup() {
  as_pg "$PGBIN/pg_ctl" -D "$PGTMP/data" stop -m immediate >/dev/null 2>&1 || true
  rm -rf "$PGTMP"
}
trap cleanup EXIT
echo "== starting a throw-away cluster in $PGTMP on 127.0.0.1:$PG_PORT"
as_pg "$PGBIN/initdb" -D "$PGTMP/data" -U postgres -A trust >/dev/null
as_pg "$PGBIN/pg_ctl" -D "$PGTMP/data" -l "$PGTMP/log" -w start \
  -o "-c listen_addresses=127.0.0.1 -p $PG_PORT -k $PGTMP -c shared_buffers=256MB -c work_mem=256MB -c statement_timeout=${PG_TIMEOUT}s" >/dev/null
export PGHOST=127.0.0.1 PGPORT=$PG_PORT PGUSER=postgres
psql -qAt -d postgres -c "CREATE DATABASE bench" >/dev/null
psql -qAt -d bench -c "CREATE EXTENSION postgis; CREATE EXTENSION postgis_sfcgal;" >/dev/null
PG_VERSIONS=$(psql -qAt -d bench -c "SELECT 'PostgreSQL ' || current_setting('server_version') || ', PostGIS ' || postgis_lib_version() || ', SFCGAL ' || postgis_sfcgal_version() || ', GEOS ' || postgis_geos_version()")
echo "   $PG_VERSIONS"
# One feature's failure must not abort the whole layer's query.
psql -qAt -d bench >/dev/null <<'SQL'
CREATE FUNCTION safe_ama(g geometry) RETURNS geometry LANGUAGE plpgsql AS $$
BEGIN
  RETURN ST_ApproximateMedialAxis(g);
EXCEPTION WHEN others THEN
  RETURN NULL;
END $$;
SQL

ms() { awk '/^Time: /{print $2}' "$1" | tail -1; }

REPORT="$OUT/bench-ma.md"
{
  echo "# MA vs PostGIS ST_ApproximateMedialAxis"
  echo
  echo "$(date -u +%Y-%m-%dT%H:%MZ), $(nproc) CPUs ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')), load before start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "$PG_VERSIONS; skeletonise MA $(git rev-parse --short HEAD 2>/dev/null || echo '?') with boostvoronoi 0.12, default arc_tolerance (relative 0.001)"
  echo
  echo "| layer | features | vertices | MA serial (s) | MA rayon (s) | PostGIS (s) | PostGIS failed | ratio serial | ratio rayon | MA peak RSS (MB) | PostGIS backend peak (MB) |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
} >"$REPORT"

for layer in "${LAYERS[@]}"; do
  echo "== $layer"
  # -- ours --
  best_serial=""; best_par=""; rss_kb=0
  for _ in $(seq "$RUNS"); do
    for mode in --serial ""; do
      /usr/bin/time -v "$MA" "$DATA" "$layer" $mode >"$OUT/$layer.ma.out" 2>"$OUT/$layer.ma.time"
      t=$(grep -o 'ma_s=[0-9.]*' "$OUT/$layer.ma.out" | cut -d= -f2)
      r=$(awk -F': ' '/Maximum resident set size/{print $2}' "$OUT/$layer.ma.time")
      [ "$r" -gt "$rss_kb" ] && rss_kb=$r
      if [ -n "$mode" ]; then
        best_serial=$(printf '%s\n%s\n' "$t" "$best_serial" | grep . | sort -g | head -1)
      else
        best_par=$(printf '%s\n%s\n' "$t" "$best_par" | grep . | sort -g | head -1)
      fi
    done
  done
  line=$(cat "$OUT/$layer.ma.out")
  features=$(grep -o 'features=[0-9]*' <<<"$line" | cut -d= -f2)
  vertices=$(grep -o 'vertices=[0-9]*' <<<"$line" | cut -d= -f2)
  rejected=$(grep -o 'rejected=[0-9]*' <<<"$line" | cut -d= -f2)
  echo "   MA: serial ${best_serial}s, rayon ${best_par}s, rejected $rejected, peak RSS $((rss_kb / 1024)) MB"

  # -- PostGIS --
  ogr2ogr -f PostgreSQL "PG:host=127.0.0.1 port=$PG_PORT user=postgres dbname=bench" "$DATA" "$layer" \
    -nln "$layer" -lco GEOMETRY_NAME=geom -lco OVERWRITE=YES -nlt PROMOTE_TO_MULTI >/dev/null
  psql -qAt -d bench -c "VACUUM ANALYZE \"$layer\"" >/dev/null
  set +e
  psql -qAt -d bench -v ON_ERROR_STOP=1 >"$OUT/$layer.pg.out" 2>&1 <<SQL
SELECT pg_backend_pid() AS pid \gset
\timing on
SELECT count(*) AS features, count(m) AS ok, sum(ST_NPoints(m)) AS points
FROM (SELECT safe_ama(geom) AS m FROM "$layer") t;
\timing off
\setenv BACKEND_PID :pid
\! grep VmHWM /proc/\$BACKEND_PID/status
SQL
  status=$?
  set -e
  pg_ms=$(ms "$OUT/$layer.pg.out")
  pg_hwm=$(awk '/VmHWM/{print $2}' "$OUT/$layer.pg.out")
  counts=$(grep -E '^[0-9]+\|[0-9]+\|' "$OUT/$layer.pg.out" || true)
  pg_failed="?"
  if [ -n "$counts" ]; then
    pg_failed=$(( $(cut -d'|' -f1 <<<"$counts") - $(cut -d'|' -f2 <<<"$counts") ))
  fi
  if [ $status -ne 0 ] || [ -z "$pg_ms" ]; then
    if grep -q "statement timeout" "$OUT/$layer.pg.out"; then
      pg_s=">$PG_TIMEOUT"; pg_cmp=$PG_TIMEOUT; pre=">"
    else
      pg_s="error"; pg_cmp=""; pre=""
    fi
    echo "   PostGIS: $(tail -2 "$OUT/$layer.pg.out" | tr '\n' ' ')"
  else
    pg_s=$(awk -v m="$pg_ms" 'BEGIN{printf "%.3f", m/1000}')
    pg_cmp=$pg_s; pre=""
  fi
  ratio() { [ -n "$pg_cmp" ] && awk -v a="$pg_cmp" -v b="$1" -v p="$pre" 'BEGIN{printf "%s%.0f×", p, a/b}' || echo "–"; }
  r_serial=$(ratio "$best_serial"); r_par=$(ratio "$best_par")
  echo "   PostGIS: ${pg_s}s (failed features: $pg_failed), backend peak $(( ${pg_hwm:-0} / 1024 )) MB; ratio serial $r_serial, rayon $r_par"
  echo "| $layer | $features | $vertices | $best_serial | $best_par | $pg_s | $pg_failed | $r_serial | $r_par | $((rss_kb / 1024)) | $(( ${pg_hwm:-0} / 1024 )) |" >>"$REPORT"
done

{
  echo
  echo "MA times exclude reading the GeoPackage (examples/ma_layer prints it separately, ~0.05 s);"
  echo "PostGIS times exclude loading the table. Ratio = PostGIS time / MA time."
} >>"$REPORT"
echo
cat "$REPORT"
