#!/usr/bin/env python3
"""Makes real cases of administrative units that *cover* border waters, as real
administrative data have them: GMT's DCW country and state polygons (full
resolution) clipped to a box around a border lake or river, and the GSHHG
lakes or river-lakes in the box as the waters. The units contain their share
of the water (the legal boundary runs inside it), come from another source
than the shorelines, and their shores do not match the water's.

    scripts/make_border_waters.py [OUT.gpkg]     # default tests/data/border-waters.gpkg
    scripts/make_border_waters.py --scale OUT.gpkg   # Finland's 194 lakes (not kept in the repository)

Layers per case NAME: `waters_NAME` (the GSHHG polygons in the box of at least
MIN km², in the case's UTM zone), `units_NAME` (the DCW units clipped to the
box, in that zone) and `units_NAME_4326` (the same units in longitude/latitude,
before projection: for the test that units in another CRS give the same
result). Needs the Debian packages gmt, gmt-gshhg-full and gmt-dcw, and
shapely ≥ 2.1, pyogrio and pyproj (scripts/python-env.sh makes such an
environment). GSHHG: Wessel & Smith, LGPL-3.0; DCW: the Digital Chart of the
World as GMT's DCW-gmt distributes it (public domain, LGPL-3.0 packaging).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

import numpy as np
import pyogrio
import pyproj
import shapely

# name, box (lon0, lon1, lat0, lat1), DCW codes, GSHHG kind (l lakes, r
# river-lakes), smallest water (km²), UTM EPSG code.
CASES = [
    ("geneva", (5.95, 7.0, 46.15, 46.6), "CH,FR", "l", 1.0, 32632),
    ("constance", (8.85, 9.85, 47.35, 47.85), "DE,AT,CH", "l", 1.0, 32632),
    ("erie", (-83.7, -78.7, 41.2, 43.1), "US.MI,US.OH,US.PA,US.NY,CA.ON", "l", 20.0, 32617),
    ("titicaca", (-70.2, -68.5, -16.7, -15.1), "PE,BO", "l", 5.0, 32719),
    ("parana", (-58.95, -55.8, -27.9, -27.0), "AR,PY", "r", 0.5, 32721),
    ("victoria", (31.4, 35.0, -3.2, 0.7), "UG,KE,TZ", "l", 20.0, 32736),
]

# `--scale`: a larger case, not kept in the repository: Finland's lakes of at least 0.1 km²
# (194 of them, 35 000 vertices), most inside one country, some on its borders.
SCALE = [("finland", (19.0, 32.0, 59.7, 70.2), "FI,SE,NO,RU,EE", "l", 0.1, 32635)]


def segments(text: str):
    """GMT multisegment text as (header, [(x, y), …]) pieces."""
    out, head, pts = [], None, []
    for line in text.splitlines():
        if line.startswith(">"):
            if pts:
                out.append((head, pts))
            head, pts = line, []
        elif line and not line.startswith("#"):
            x, y = line.split()[:2]
            pts.append((float(x), float(y)))
    if pts:
        out.append((head, pts))
    return out


def gmt(*args: str) -> str:
    with tempfile.TemporaryDirectory() as d:  # GMT leaves gmt.history behind
        return subprocess.run(["gmt", *args], check=True, capture_output=True, text=True, cwd=d).stdout


def lon(pts, box):
    """Longitudes shifted by 360° into the box's range (DCW has 0–360)."""
    mid = (box[0] + box[1]) / 2
    return [(x - 360 if x - mid > 180 else x + 360 if mid - x > 180 else x, y) for x, y in pts]


def unit(code: str, box):
    """One DCW unit as a (multi)polygon, its holes (-Ph) in the shells that
    hold them, clipped to the box."""
    shells, holes = [], []
    for head, pts in segments(gmt("coast", f"-E{code}", "-M", "-Df")):
        ring = lon(pts, box)
        if len(ring) < 4:
            continue
        (holes if "-Ph" in head else shells).append(shapely.Polygon(ring))
    polys = []
    for s in shells:
        inner = [h.exterior.coords for h in holes if s.contains(h.representative_point())]
        polys.append(shapely.make_valid(shapely.Polygon(s.exterior.coords, inner)))
    g = shapely.intersection(shapely.union_all(polys), shapely.box(box[0], box[2], box[1], box[3]))
    parts = [p for p in shapely.get_parts(g) if p.geom_type == "Polygon"]
    return shapely.MultiPolygon(parts) if parts else shapely.MultiPolygon()


def waters(box, kind: str):
    """The GSHHG level-2 polygons of `kind` in the box, clipped to it (pieces
    cut at the bins joined by `gmt connect`; river-lakes, which run out of any
    box, are taken from the whole world first)."""
    region = f"-R{box[0]}/{box[1]}/{box[2]}/{box[3]}" if kind == "l" else "-Rd"
    pieces = gmt("coast", region, "-Df", f"-A0/2/2+{kind}", "-W", "-M")
    if not pieces.strip():
        return []
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "pieces.txt")
        with open(path, "w") as f:
            f.write(pieces)
        # Nothing to join: GMT writes nothing when every piece is closed.
        rings = gmt("connect", path, "-T1e-9") or pieces
    out = []
    clip = shapely.box(box[0], box[2], box[1], box[3])
    for _, pts in segments(rings):
        if len(pts) >= 4 and pts[0] == pts[-1]:
            w = shapely.Polygon(lon(pts, box))
            if w.intersects(clip):
                out.append(shapely.intersection(shapely.make_valid(w), clip))
    parts = shapely.get_parts(shapely.union_all(out)) if out else []
    return [p for p in parts if p.geom_type == "Polygon"]


def write(path, layer, geoms, crs, **cols):
    import pandas as pd
    import geopandas as gpd

    frame = gpd.GeoDataFrame(pd.DataFrame(cols), geometry=list(geoms), crs=crs)
    # GeoPackage 1.2: what GDAL 3.6 (Debian's, QGIS 3.22's) reads without a warning.
    pyogrio.write_dataframe(frame, path, layer=layer, driver="GPKG", promote_to_multi=True,
                            dataset_options={"VERSION": "1.2"} if not os.path.exists(path) else None)


def main():
    args = [a for a in sys.argv[1:] if a != "--scale"]
    cases = SCALE if "--scale" in sys.argv else CASES
    out = args[0] if args else os.path.join(os.path.dirname(__file__), "..", "tests", "data", "border-waters.gpkg")
    if os.path.exists(out):
        os.remove(out)
    for name, box, codes, kind, min_km2, epsg in cases:
        codes = codes.split(",")
        units = [unit(c, box) for c in codes]
        # The units among themselves as one coverage: where two clipped
        # units overlap or leave a gap (DCW's state borders leave gaps of
        # some metres), GEOS's coverage cleaner fixes it, gaps up to 0.002°.
        units = list(shapely.coverage_clean(np.array(units), gap_width=0.002))
        keep = [i for i, u in enumerate(units) if not u.is_empty]
        units, codes = [units[i] for i in keep], [codes[i] for i in keep]
        to_utm = pyproj.Transformer.from_crs(4326, epsg, always_xy=True).transform
        land = shapely.union_all(units)
        ws = [shapely.transform(w, to_utm, interleaved=False) for w in waters(box, kind) if w.intersects(land)]
        ws = [shapely.make_valid(w) for w in ws if w.area >= min_km2 * 1e6]
        ws = [p for w in ws for p in shapely.get_parts(w) if p.geom_type == "Polygon"]
        units_utm = [shapely.transform(u, to_utm, interleaved=False) for u in units]
        write(out, f"waters_{name}", ws, f"EPSG:{epsg}", water_id=np.arange(1, len(ws) + 1))
        write(out, f"units_{name}", units_utm, f"EPSG:{epsg}", code=codes)
        # The same units as another source would give them: in longitude/latitude, rounded
        # to 1e-8° (about a millimetre), every vertex then off the UTM one by round-off.
        write(out, f"units_{name}_4326", shapely.set_precision(np.array(units), 1e-8), "EPSG:4326", code=codes)
        nv = sum(shapely.get_num_coordinates(w) for w in ws)
        nu = sum(shapely.get_num_coordinates(u) for u in units_utm)
        cover = shapely.area(shapely.intersection(shapely.union_all(ws), shapely.union_all(units_utm)))
        print(
            f"{name}: {len(ws)} waters ({nv} vertices, {sum(w.area for w in ws) / 1e6:.1f} km², "
            f"{cover / max(sum(w.area for w in ws), 1):.1%} inside units), {len(units)} units ({nu} vertices)"
        )


if __name__ == "__main__":
    main()
