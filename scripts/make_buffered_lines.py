"""Writes buffered lines — the polygons a road or river layer becomes when its
centrelines are buffered: random walks of 2-14 segments (40 % snapped to a
10 m grid, so many edges are parallel), buffered 3-40 m with round, flat or
square caps and round, mitre or bevel joins at 1-16 segments per quarter
circle, a fifth with a disc at one end. Their edges come in antiparallel
pairs tangent to common circles, and GEOS leaves near-duplicate vertices
(3e-15 m apart): many events of the straight skeleton fall at one time and
point.

usage: make_buffered_lines.py OUT.gpkg [--seed S] [--count N] [--only I,J,...] [--append]
  --only keeps the polygons with those indices (of the N made), in order;
  --append adds them to the layer `buffers` instead of replacing it.
needs: shapely, geopandas, pyogrio, numpy (PyPI)
"""

import argparse

import geopandas as gpd
import numpy as np
from shapely.geometry import LineString, Point


def buffered_lines(seed, count):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        k = rng.integers(2, 15)
        pts = np.cumsum(rng.normal(0, 100, (k, 2)), axis=0)
        if rng.random() < 0.4:
            pts = np.round(pts / 10) * 10
        width = float(rng.choice([3, 5, 10, 20, 40]))
        cap = rng.choice(["round", "flat", "square"])
        join = rng.choice(["round", "mitre", "bevel"])
        quad = int(rng.choice([1, 2, 4, 8, 16]))
        g = LineString(pts).buffer(width, quad_segs=quad, cap_style=cap, join_style=join)
        if rng.random() < 0.2:
            g = g.union(Point(pts[-1]).buffer(2 * width, quad_segs=8))
        if g.geom_type == "Polygon" and g.is_valid and not g.is_empty:
            out.append(g)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--count", type=int, default=3000)
    ap.add_argument("--only", default=None)
    ap.add_argument("--append", action="store_true", help="add to the layer instead of replacing it")
    a = ap.parse_args()
    geoms = buffered_lines(a.seed, a.count)
    index = list(range(len(geoms)))
    if a.only:
        index = [int(i) for i in a.only.split(",")]
        geoms = [geoms[i] for i in index]
    gdf = gpd.GeoDataFrame({"seed": a.seed, "index": index}, geometry=geoms, crs="EPSG:3857")
    gdf.to_file(a.out, layer="buffers", mode="a" if a.append else "w")
    print(f"{a.out}: {len(geoms)} polygons")


if __name__ == "__main__":
    main()
