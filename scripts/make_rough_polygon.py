"""Writes one rough polygon for scale runs: five lobes of radius 10 km with
up to 30 m of seeded random radial roughness at every vertex,
r = 10 000·(1 + 0.3 sin 5t) + U(0, 30) — at 100 000 vertices the roughness
is about five times the vertex spacing, so the boundary is spiky at the
scale of its own vertices (a rough bank, unlike make_big_polygon.py's
gentle noise). The ring may not be simple at every N; the polygon is
written as shapely.make_valid leaves it (the largest part).

usage: make_rough_polygon.py N OUT.gpkg
needs: shapely, geopandas, pyogrio, numpy (PyPI)
"""

import sys

import geopandas as gpd
import numpy as np
import shapely

n, out = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(20261204)
t = np.arange(n) / n * 2 * np.pi
r = 10_000.0 * (1 + 0.3 * np.sin(5 * t)) + rng.uniform(0.0, 30.0, n)
ring = np.column_stack([500_000 + r * np.cos(t), 6_000_000 + r * np.sin(t)])
poly = shapely.Polygon(ring)
if not poly.is_valid:
    poly = max(shapely.get_parts(shapely.make_valid(poly)), key=lambda g: g.area if g.geom_type == "Polygon" else 0)
gpd.GeoDataFrame({"name": [f"rough lobes {n}"]}, geometry=[poly], crs="EPSG:32633").to_file(
    out, layer="rough", driver="GPKG"
)
print(f"{out}: 1 polygon, {shapely.get_num_coordinates(poly)} vertices")
