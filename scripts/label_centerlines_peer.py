"""Label lines of one polygon layer made by the peer tool label_centerlines, for benchmarks.

Runs label_centerlines.get_centerline (PyPI label-centerlines 2022.6.0) with the defaults its own
CLI uses (segmentize_maxlen=0.5, max_points=3000, simplification=0.05, smooth_sigma=5,
max_paths=5; all in map units) on every polygon of LAYER, on the largest part of a MultiPolygon,
and times each call with time.perf_counter. Writes OUT.gpkg layer `lines` (LINESTRING, the source
CRS) with columns:
  src_fid  the source feature's FID (for `skeletonise score --skeleton-key src_fid`)
  seconds  time of the get_centerline call
  error    why get_centerline raised, else empty; such rows have no geometry, so no polygon
           is dropped silently
Prints one summary line (key=value): layer, lakes, lines, errors, total_seconds,
median_seconds (per polygon).

usage: label_centerlines_peer.py SRC.gpkg LAYER OUT.gpkg [N]
       N: do only the first N features (in FID order)
needs: a Python with label-centerlines==2022.6.0, numpy<2 (the package calls np.math, gone in
       numpy 2), geopandas, pyogrio and shapely; scripts/bench-labels.sh makes one at
       target/lc-venv. OUT.gpkg is overwritten.
"""

import os
import statistics
import sys
import time
import warnings

import geopandas as gpd
import pyogrio
from label_centerlines import get_centerline

# np.math is deprecated in numpy 1.25+; label_centerlines still calls it.
warnings.filterwarnings("ignore", category=DeprecationWarning)

DEFAULTS = dict(  # as label_centerlines' CLI
    segmentize_maxlen=0.5, max_points=3000, simplification=0.05, smooth_sigma=5, max_paths=5
)


def largest_part(geom):
    if geom is not None and geom.geom_type == "MultiPolygon":
        return max(geom.geoms, key=lambda g: g.area)
    return geom


def main(argv):
    if len(argv) not in (4, 5):
        sys.exit(__doc__)
    src, layer, out = argv[1:4]
    limit = int(argv[4]) if len(argv) == 5 else None

    polys = gpd.read_file(src, layer=layer, engine="pyogrio", fid_as_index=True)
    polys = polys.sort_index()
    if limit is not None:
        polys = polys.iloc[:limit]

    rows = []  # (src_fid, seconds, error, geometry)
    times = []
    for fid, geom in zip(polys.index, polys.geometry):
        poly = largest_part(geom)
        t0 = time.perf_counter()
        try:
            if poly is None or poly.is_empty:
                raise ValueError("empty or missing geometry")
            line = get_centerline(poly, **DEFAULTS)
            err = None
        except Exception as e:  # CenterlineError, TypeError, anything: keep a row
            line, err = None, f"{type(e).__name__}: {e}"
        dt = time.perf_counter() - t0
        times.append(dt)
        if dt >= 10:
            print(f"  fid {fid}: {dt:.1f}s", file=sys.stderr, flush=True)
        if line is not None and line.geom_type == "MultiLineString":
            rows += [(int(fid), dt, None, part) for part in line.geoms]
        else:
            rows.append((int(fid), dt, err, line))

    gdf = gpd.GeoDataFrame(
        {
            "src_fid": [r[0] for r in rows],
            "seconds": [r[1] for r in rows],
            "error": [r[2] for r in rows],
        },
        geometry=[r[3] for r in rows],
        crs=polys.crs,
    )
    gdf["src_fid"] = gdf["src_fid"].astype("int64")
    gdf["error"] = gdf["error"].astype(object)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    if os.path.exists(out):
        os.remove(out)
    pyogrio.write_dataframe(gdf, out, layer="lines", driver="GPKG", geometry_type="LineString")

    errors = sum(r[2] is not None for r in rows)
    lines = len(rows) - errors
    med = statistics.median(times) if times else float("nan")
    print(
        f"layer={layer} lakes={len(polys)} lines={lines} errors={errors} "
        f"total_seconds={sum(times):.3f} median_seconds={med:.3f}"
    )


if __name__ == "__main__":
    main(sys.argv)
