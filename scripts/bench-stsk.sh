#!/usr/bin/env bash
# Side-by-side benchmark: our StSk (examples/stsk_layer, rayon) against
# PostGIS/SFCGAL ST_StraightSkeleton on the same layers, in one run.
# Needs: postgresql-15, postgresql-15-postgis-3 (with SFCGAL), gdal-bin, time.
# Usage: scripts/bench-stsk.sh [gpkg] [layers...]   (run from the crate root, as root)
set -euo pipefail
GPKG=$(realpath "${1:-tests/data/gshhg-train.gpkg}")
shift || true
LAYERS=("$@")
[ ${#LAYERS[@]} -eq 0 ] && LAYERS=(river_st_lawrence river_lena islands_hebrides)
PGBIN=$(ls -d /usr/lib/postgresql/*/bin | sort -V | tail -1)
PORT=${PORT:-54329}
TMP=$(mktemp -d)
chown postgres "$TMP"
cleanup() {
  su postgres -c "$PGBIN/pg_ctl -D $TMP/db -m immediate stop" >/dev/null 2>&1 || true
  rm -rf "$TMP"
}
trap cleanup EXIT
su postgres -c "$PGBIN/initdb -D $TMP/db -A trust -U postgres" >/dev/null
su postgres -c "$PGBIN/pg_ctl -D $TMP/db -o '-p $PORT -k $TMP -c listen_addresses=127.0.0.1' -l $TMP/log -w start" >/dev/null
PSQL=(psql -h 127.0.0.1 -p "$PORT" -U postgres -d postgres -qAt)
"${PSQL[@]}" -c "CREATE EXTENSION postgis; CREATE EXTENSION postgis_sfcgal;"
echo "postgis_sfcgal_version: $("${PSQL[@]}" -c 'SELECT postgis_sfcgal_version()')"
cargo build --release --example stsk_layer -q
OURS=target/release/examples/stsk_layer
printf '%-20s %10s %10s %8s %12s %12s\n' layer ours_s postgis_s ratio ours_maxrss_kB pg_failed
for L in "${LAYERS[@]}"; do
  ogr2ogr -f PostgreSQL "PG:host=127.0.0.1 port=$PORT user=postgres dbname=postgres" "$GPKG" "$L" \
    -nln "$L" -nlt PROMOTE_TO_MULTI -lco GEOMETRY_NAME=geom -overwrite
  /usr/bin/time -v "$OURS" "$GPKG" "$L" >"$TMP/ours.out" 2>"$TMP/ours.err" || true
  OURS_S=$(grep -o 'wall_s=[0-9.]*' "$TMP/ours.out" | cut -d= -f2)
  OURS_RSS=$(grep 'Maximum resident' "$TMP/ours.err" | awk '{print $NF}')
  START=$(date +%s.%N)
  PG_FAILED=$("${PSQL[@]}" -c "
    CREATE OR REPLACE FUNCTION pg_temp.sk(g geometry) RETURNS int AS \$\$
    BEGIN PERFORM ST_StraightSkeleton(g); RETURN 0;
    EXCEPTION WHEN OTHERS THEN RETURN 1; END \$\$ LANGUAGE plpgsql;
    SELECT sum(pg_temp.sk(d.geom)) FROM \"$L\", LATERAL ST_Dump(geom) d;")
  END=$(date +%s.%N)
  PG_S=$(echo "$END - $START" | bc -l)
  RATIO=$(echo "$PG_S / $OURS_S" | bc -l)
  printf '%-20s %10.3f %10.3f %8.1f %12s %12s\n' "$L" "$OURS_S" "$PG_S" "$RATIO" "$OURS_RSS" "$PG_FAILED"
  cat "$TMP/ours.out" "$TMP/ours.err" | grep -E '^layer=|^feature' | head -5
done
