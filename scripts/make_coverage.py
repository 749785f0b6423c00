#!/usr/bin/env python3
"""Makes a unit coverage around river polygons, for the `partition` step's
tests and benchmarks: the Voronoi cells of random seeds in a buffer around
each river, minus the river, noded so that units and river share every vertex
(one polygonization of all the boundaries, snapped to a grid, then each
river's and each unit's faces merged by shapely.coverage_union_all, which
keeps the vertices); every island of a river is a unit of its own. Units meet
the river on one bank, on both (a cell across the river gives a two-part
unit), or not at all.

    scripts/make_coverage.py SRC.gpkg LAYER OUT.gpkg [--seeds N] [--buffer M]
        [--grid G] [--seed S] [--reaches K] [--fids F,...] [--name NAME]

writes the layers `rivers` (fields: id, name) and `units` (fields: id,
landuse) to OUT.gpkg in the source's CRS (with --name, `rivers_NAME` and
`units_NAME`, added to OUT.gpkg beside the layers it holds). With --reaches K each river is cut
into K reaches across its length (polygons that share edges, as a river
network's reaches do).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import shapely


def seeds_around(river, buffer, n, rng):
    """n random points in the buffer around `river`, outside it."""
    minx, miny, maxx, maxy = buffer.bounds
    shapely.prepare(buffer)
    shapely.prepare(river)
    pts = []
    while len(pts) < n:
        xy = rng.uniform((minx, miny), (maxx, maxy), size=(4 * n, 2))
        cand = shapely.points(xy)
        ok = shapely.contains(buffer, cand) & ~shapely.contains(river, cand)
        pts.extend(cand[ok][: n - len(pts)])
    return pts


def reach_cuts(river, k):
    """Lines across `river` cutting it into k reaches (perpendicular to the
    longer side of its bounding box, evenly spaced)."""
    minx, miny, maxx, maxy = river.bounds
    cuts = []
    for i in range(1, k):
        if maxx - minx >= maxy - miny:
            x = minx + (maxx - minx) * i / k
            cuts.append(shapely.LineString([(x, miny - 1), (x, maxy + 1)]))
        else:
            y = miny + (maxy - miny) * i / k
            cuts.append(shapely.LineString([(minx - 1, y), (maxx + 1, y)]))
    return cuts


def coverage(river, n_seeds, buffer_m, grid, rng, reaches):
    river = shapely.set_precision(river, grid)
    buffer = shapely.set_precision(river.buffer(buffer_m), grid)
    cells = shapely.voronoi_polygons(
        shapely.MultiPoint(seeds_around(river, buffer, n_seeds, rng)), extend_to=buffer
    )
    cells = [shapely.intersection(c, buffer) for c in shapely.get_parts(cells)]
    cuts = [shapely.intersection(c, buffer) for c in reach_cuts(river, reaches)]
    lines = shapely.union_all(
        [river.boundary, buffer.boundary] + [c.boundary for c in cells] + cuts, grid_size=grid
    )
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(lines)))
    points = shapely.point_on_surface(faces)
    shapely.prepare(river)
    in_river = shapely.contains(river, points)
    hull = shapely.Polygon(river.exterior) if river.geom_type == "Polygon" else shapely.union_all(
        [shapely.Polygon(p.exterior) for p in river.geoms]
    )
    shapely.prepare(hull)
    in_hull = shapely.contains(hull, points)
    reach_parts = [shapely.Polygon(p.exterior) for p in shapely.get_parts(
        shapely.polygonize(shapely.get_parts(shapely.union_all([hull.boundary] + cuts, grid_size=grid))))]
    rivers = {}
    units = {}
    islands = []
    for f, q, r, h in zip(faces, points, in_river, in_hull):
        if r:
            k = next((i for i, p in enumerate(reach_parts) if p.contains(q)), 0)
            rivers.setdefault(k, []).append(f)
        elif h:
            islands.append([f])
        else:
            k = next(i for i, c in enumerate(cells) if c.contains(q))
            units.setdefault(k, []).append(f)
    river_polys = [shapely.coverage_union_all(fs) for _, fs in sorted(rivers.items())]
    unit_polys = [shapely.coverage_union_all(fs) for _, fs in sorted(units.items())] + [
        shapely.coverage_union_all(fs) for fs in islands
    ]
    return river_polys, unit_polys


def main(argv=None):
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("src")
    a.add_argument("layer")
    a.add_argument("out")
    a.add_argument("--seeds", type=int, default=200, help="seeds per river (units)")
    a.add_argument("--buffer", type=float, default=5000.0, help="buffer around each river (CRS units)")
    a.add_argument("--grid", type=float, default=0.01, help="coordinate grid (CRS units)")
    a.add_argument("--seed", type=int, default=1, help="random seed")
    a.add_argument("--reaches", type=int, default=1, help="reaches per river")
    a.add_argument("--fids", default=None, help="only these source FIDs, comma-separated")
    a.add_argument("--name", default=None, help="layers rivers_NAME and units_NAME, added to OUT")
    o = a.parse_args(argv)
    src = pyogrio.read_dataframe(o.src, layer=o.layer, fid_as_index=True)
    if o.fids:
        src = src.loc[[int(f) for f in o.fids.split(",")]]
    rng = np.random.default_rng(o.seed)
    rivers, units = [], []
    for fid, geom in zip(src.index, src.geometry):
        r, u = coverage(geom, o.seeds, o.buffer, o.grid, rng, o.reaches)
        rivers += [(fid, g) for g in r]
        units += u
    # Units of one river can overlap another river's buffer: keep the first
    # river's cells (the test layers hold one river each or far apart ones).
    rg = gpd.GeoDataFrame(
        {"id": np.arange(1, len(rivers) + 1), "name": [f"river {f}" for f, _ in rivers]},
        geometry=[g for _, g in rivers],
        crs=src.crs,
    )
    landuse = np.array(["forest", "field", "town", "meadow"])
    ug = gpd.GeoDataFrame(
        {"id": np.arange(1, len(units) + 1), "landuse": landuse[np.arange(len(units)) % 4]},
        geometry=units,
        crs=src.crs,
    )
    allg = np.concatenate([rg.geometry.values, ug.geometry.values])
    if not shapely.coverage_is_valid(allg):
        sys.exit("the generated coverage is not valid")
    # GeoPackage 1.2: what the GDAL of Debian stable reads without a warning.
    suffix = f"_{o.name}" if o.name else ""
    new_file = not o.name or not Path(o.out).exists()
    options = {"dataset_options": {"VERSION": "1.2"}} if new_file else {}
    pyogrio.write_dataframe(rg, o.out, layer="rivers" + suffix, driver="GPKG", **options)
    pyogrio.write_dataframe(ug, o.out, layer="units" + suffix, driver="GPKG")
    print(f"{o.out}: {len(rg)} river polygons, {len(ug)} units")


if __name__ == "__main__":
    main()
