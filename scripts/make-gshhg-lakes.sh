#!/usr/bin/env bash
# Makes a GeoPackage of ALL lakes of the GSHHG world shoreline data (level 2, full resolution) for
# scale benchmarks: layer `lakes`, one POLYGON per lake (islands in lakes, level 3, are not cut out),
# reprojected to EPSG:8857 (Equal Earth, metres; EPSG:6933 if this PROJ lacks 8857).
# Attributes: id, level (always 2), riverlake (1 = GSHHG "river-lake", the fat part of a river),
# dateline_half (1 for the two halves of the one lake cut at 180 degrees, see below), area_km2
# (planar area in the equal-area CRS).
# With KIND=islands: layer `islands`, every island of level 1 (land; lakes in it not cut out) whose
# area is under MAX_KM2 (default 1000) km², riverlake always 0 — the many small polygons of a
# world run (175 730 islands, 3.84 M vertices).
#
#   scripts/make-gshhg-lakes.sh [OUTPUT.gpkg]    # default: target/bench/gshhg-lakes.gpkg
#   KIND=islands scripts/make-gshhg-lakes.sh     # default: target/bench/gshhg-islands.gpkg
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
kind=${KIND:-lakes}
case "$kind" in
    lakes) level=2; shores=(l r); max_km2=;;
    islands) level=1; shores=(l); max_km2=${MAX_KM2:-1000};;
    *) echo "error: KIND is lakes or islands, not '$kind'" >&2; exit 1;;
esac
out=$(realpath -m "${1:-$root/target/bench/gshhg-$kind.gpkg}")

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

# 1. Dump the level's shorelines (for lakes: lakes, then river-lakes) in -180/180 as bin pieces,
#    join the pieces.
rings=()
for s in "${shores[@]}"; do
    gmt coast -Rd -Df -A0/$level/$level+$s -W -M > "pieces-$s.txt"
    gmt connect "pieces-$s.txt" -T1e-9 > "rings-$s.txt"   # Cartesian: no join across 180
    rings+=("rings-$s.txt")
done

# 2. One CSV row per ring. A ring left open by `gmt connect` must have both
#    ends on the dateline (a half lake); it is closed along the meridian. Anything else is an error.
#    Columns: id,level,riverlake,dateline_half,wkt.
awk -v OFS=, -v level=$level -v max_km2="$max_km2" '
    function flush() {
        if (n == 0) return
        if (x[1] != x[n] || y[1] != y[n]) {
            if ((x[1] == 180 || x[1] == -180) && x[n] == -x[1] && level == 1) {
                # A ring around the globe (Antarctica, the one level-1 ring not closed): no polygon
                # in longitude and latitude, and no island.
                printf "skipped a ring around the globe (%d points, from %s %s)\n", n, x[1], y[1] > "/dev/stderr"
                n = 0
                return
            }
            if ((x[1] != 180 && x[1] != -180) || x[n] != x[1]) {
                printf "open ring not on the dateline: %s %s .. %s %s\n", x[1], y[1], x[n], y[n] > "/dev/stderr"
                bad = 1
            }
            n++; x[n] = x[1]; y[n] = y[1]; split_halves++; half = 1
        }
        if (max_km2 != "" && approx_km2() > 2 * max_km2) { big++; n = 0; half = 0; return }
        # Printed vertex by vertex: joining one string of a continent of a million vertices is quadratic.
        printf "%d%s%d%s%d%s%d%s\"POLYGON((%s %s", ++id, OFS, level, OFS, river, OFS, half, OFS, x[1], y[1]
        for (i = 2; i <= n; i++) printf ",%s %s", x[i], y[i]
        print "))\""
        pts += n; n = 0; half = 0
    }
    # The area in km², roughly (degrees scaled at the ring'"'"'s mean latitude): rings far over MAX_KM2
    # are left out here (a continent'"'"'s line is longer than the CSV reader takes); the exact
    # filter is in the equal-area CRS below.
    function approx_km2(   i, a, lat) {
        a = 0; lat = 0
        for (i = 1; i < n; i++) { a += x[i] * y[i + 1] - x[i + 1] * y[i]; lat += y[i] }
        lat = lat / (n - 1) * 3.14159265 / 180
        return (a < 0 ? -a : a) / 2 * 111.32 * 110.57 * cos(lat)
    }
    FNR == 1 { flush(); river = (FILENAME ~ /rings-r/) }
    /^>/ { flush(); next }
    /^#/ { next }
    { n++; x[n] = $1; y[n] = $2 }
    END {
        flush()
        printf "%d rings, %d points with closing points, %d dateline halves", id, pts, split_halves > "/dev/stderr"
        printf "%s\n", (max_km2 != "" ? sprintf(", %d rings over %s km² left out", big, 2 * max_km2) : "") > "/dev/stderr"
        exit bad
    }
    BEGIN { print "id,level,riverlake,dateline_half,wkt" }
' "${rings[@]}" > lakes.csv

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
where=${max_km2:+"WHERE ST_Area(geom) < $max_km2 * 1e6"}
ogr2ogr -f GPKG "$out" stage.gpkg -nln "$kind" -nlt POLYGON "${makevalid[@]}" -dialect SQLite \
    -sql "SELECT id, level, riverlake, dateline_half, ST_Area(geom) / 1e6 AS area_km2, geom
          FROM lakes $where ORDER BY id" 2> >(quiet_proj)

ogrinfo -so "$out" "$kind" | grep -E 'Feature Count|Extent|^PROJCRS'
ogrinfo -q "$out" -dialect SQLite -sql "SELECT COUNT(*) AS features, SUM(ST_NPoints(geom)) AS vertices,
    SUM(riverlake) AS riverlakes, SUM(dateline_half) AS dateline_halves,
    SUM(NOT ST_IsValid(geom)) AS invalid FROM $kind" | grep ' = '
echo "wrote $out"
