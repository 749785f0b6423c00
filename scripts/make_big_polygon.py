"""Writes one large polygon for scale runs: a noisy circle of N vertices
(radius 10 km, two slow waves on the radius, and every vertex moved
radially by a seeded random amount up to a quarter of the vertex spacing,
so the boundary is rough at every scale but never crosses itself).

usage: make_big_polygon.py N OUT.gpkg
needs: shapely, geopandas, pyogrio, numpy (PyPI)
"""

import sys

import geopandas as gpd
import numpy as np
import shapely

n, out = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(20261201)
t = np.arange(n) / n * 2 * np.pi
radius = 10_000.0
spacing = 2 * np.pi * radius / n
r = radius * (1 + 0.05 * np.sin(7 * t) + 0.02 * np.sin(53 * t))
r += rng.uniform(-0.25, 0.25, n) * spacing
x = 500_000 + r * np.cos(t)
y = 6_000_000 + r * np.sin(t)
ring = np.column_stack([x, y])
poly = shapely.Polygon(ring)
assert poly.is_valid, shapely.is_valid_reason(poly)
gpd.GeoDataFrame({"name": [f"noisy circle {n}"]}, geometry=[poly], crs="EPSG:32633").to_file(
    out, layer="big", driver="GPKG"
)
print(f"{out}: 1 polygon, {n} vertices")
