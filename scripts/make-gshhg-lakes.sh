#!/usr/bin/env bash
# Makes a GeoPackage of ALL lakes of the GSHHG world shoreline data (level 2, full resolution) for
# scale benchmarks: layer `lakes`, one POLYGON per lake (islands in lakes, level 3, are not cut out),
# reprojected to EPSG:8857 (Equal Earth, metres; EPSG:6933 if this PROJ lacks 8857).
# Attributes: id, level (always 2), riverlake (1 = GSHHG "river-lake", the fat part of a river),
# dateline_half (1 for the two halves of the one lake cut at 180 degrees, see below), area_km2
# (planar area in the equal-area CRS).
#
#   scripts/make-gshhg-lakes.sh [OUTPUT.gpkg]    # default: target/bench/gshhg-lakes.gpkg
#
# Needs the Debian packages `gmt gmt-gshhg-full` and GDAL (`gdal-bin`: ogr2ogr, ogrinfo); installs
# nothing itself. Takes about half a minute.
#
# How: GMT only ships GSHHG in its binned netCDF form, and `gmt coast -M -W` dumps each lake as
# pieces cut at the bin edges. `gmt connect` joins the pieces again (their end points match
# exactly), awk writes one WKT polygon per lake, ogr2ogr reprojects. The one lake that crosses the
# dateline (Chukotka, 65.3N) comes out as two polygons, its halves east and west of 180 closed along
# the meridian, as in GSHHG's own shapefiles: two features, marked dateline_half = 1. Rings that
# GEOS finds invalid after projection (one, where a vertex lies 1e-11 degrees from another edge of
# its own ring) are repaired with -makevalid. GDAL 3.6 prints "proj_as_wkt: Unsupported conversion
# method: Equal Earth" when writing the GeoPackage (no WKT1 form of the CRS; the EPSG code and WKT2
# are stored): that message is filtered out.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(realpath -m "${1:-$root/target/bench/gshhg-lakes.gpkg}")

for tool in gmt ogr2ogr ogrinfo; do
    if ! command -v "$tool" >/dev/null; then
        echo "error: '$tool' not found; install the Debian packages gmt gmt-gshhg-full gdal-bin" >&2
        exit 1
    fi
done
crs=EPSG:8857
gdalsrsinfo "$crs" >/dev/null 2>&1 || crs=EPSG:6933

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"   # GMT may leave gmt.history and the like in the working directory
if ! gmt coast -R0/1/50/51 -Df -W -M >/dev/null 2>&1; then
    echo "error: GMT has no full-resolution GSHHG data; install the Debian package gmt-gshhg-full" >&2
    exit 1
fi

# 1. Dump level-2 shorelines (lakes, then river-lakes) in -180/180 as bin pieces, join the pieces.
for kind in l r; do
    gmt coast -Rd -Df -A0/2/2+$kind -W -M > "pieces-$kind.txt"
    gmt connect "pieces-$kind.txt" -T1e-9 > "rings-$kind.txt"   # Cartesian: no join across 180
done

# 2. One CSV row per ring. A ring left open by `gmt connect` must have both
#    ends on the dateline (a half lake); it is closed along the meridian. Anything else is an error.
#    Columns: id,level,riverlake,dateline_half,wkt.
awk -v OFS=, '
    function flush() {
        if (n == 0) return
        if (x[1] != x[n] || y[1] != y[n]) {
            if ((x[1] != 180 && x[1] != -180) || x[n] != x[1]) {
                printf "open ring not on the dateline: %s %s .. %s %s\n", x[1], y[1], x[n], y[n] > "/dev/stderr"
                bad = 1
            }
            n++; x[n] = x[1]; y[n] = y[1]; split_halves++; half = 1
        }
        w = x[1] " " y[1]
        for (i = 2; i <= n; i++) w = w "," x[i] " " y[i]
        print ++id, 2, river, half, "\"POLYGON((" w "))\""
        pts += n; n = 0; half = 0
    }
    FNR == 1 { flush(); river = (FILENAME ~ /rings-r/) }
    /^>/ { flush(); next }
    /^#/ { next }
    { n++; x[n] = $1; y[n] = $2 }
    END {
        flush()
        printf "%d rings, %d points with closing points, %d dateline halves\n", id, pts, split_halves > "/dev/stderr"
        exit bad
    }
    BEGIN { print "id,level,riverlake,dateline_half,wkt" }
' rings-l.txt rings-r.txt > lakes.csv

# 3. Reproject to the metric CRS; then add the area (and check validity) in a second pass.
quiet_proj() { grep -v 'proj_as_wkt: Unsupported conversion method' >&2 || true; }
ogr2ogr -f GPKG stage.gpkg lakes.csv -nln lakes -oo GEOM_POSSIBLE_NAMES=wkt -oo KEEP_GEOM_COLUMNS=NO \
    -oo AUTODETECT_TYPE=YES -s_srs EPSG:4326 -t_srs "$crs" -nlt POLYGON 2> >(quiet_proj)
invalid=$(ogrinfo -q stage.gpkg -dialect SQLite \
    -sql "SELECT COUNT(*) AS n FROM lakes WHERE NOT ST_IsValid(geom)" | sed -n 's/.*n (Integer) = //p')
makevalid=()
if [ "${invalid:-0}" != 0 ]; then
    echo "$invalid invalid polygons: repairing with -makevalid" >&2
    makevalid=(-makevalid)
fi
mkdir -p "$(dirname "$out")"
rm -f "$out"
ogr2ogr -f GPKG "$out" stage.gpkg -nln lakes -nlt POLYGON "${makevalid[@]}" -dialect SQLite \
    -sql "SELECT id, level, riverlake, dateline_half, ST_Area(geom) / 1e6 AS area_km2, geom
          FROM lakes ORDER BY id" 2> >(quiet_proj)

ogrinfo -so "$out" lakes | grep -E 'Feature Count|Extent|^PROJCRS'
ogrinfo -q "$out" -dialect SQLite -sql "SELECT COUNT(*) AS features, SUM(ST_NPoints(geom)) AS vertices,
    SUM(riverlake) AS riverlakes, SUM(dateline_half) AS dateline_halves,
    SUM(NOT ST_IsValid(geom)) AS invalid FROM lakes" | grep ' = '
echo "wrote $out"
