"""Writes tests/data/network-train.gpkg: line networks meeting the training lakes and rivers
(for `prune: {mode: network}` and the `network` layer), and constructed cases.

Generated from tests/data/gshhg-train.gpkg (GSHHG, Wessel & Smith, LGPL-3.0), seeded:

* `lines_<layer>` for `lakes_scotland`, `river_st_lawrence`, `river_danube`, `river_lena`
  (same CRS as the layer): for each polygon, straight lines from outside to its two farthest
  tips (the ends of its longest vertex-to-vertex span; a third, the vertex farthest from both,
  on every third lake), and on rivers also lines from outside to seeded random bank points
  (tributaries). Every line ends exactly on a boundary vertex, runs outward from it and meets
  no polygon elsewhere (a candidate that would is skipped). Field `polygon` (the polygon's FID),
  `role` (`tip` or `bank`).
* `cases` (EPSG:32633, field `name`) with `cases_lines`:
  - `bays_lake`: a lake 10 km long with three long bays; inflow and outflow at its two ends;
  - `y_lake`: a three-armed lake with a line at each arm's end;
  - `island_river`: a river reach with an island; lines at both ends and one on each bank
    beside the island (each channel serves one);
  - `lonely_lake`: a lake no line meets;
  - `spring_lake`: an elongated lake 8 km long with one line, at its west end (its line runs to
    the far, east tip).

usage: make_network.py SRC.gpkg OUT.gpkg
needs: shapely, geopandas, pyogrio, numpy (PyPI)
"""

import os
import subprocess
import sys

import geopandas as gpd
import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon

SEED = 20261205


def farthest_pair(coords):
    """Indices of the two hull vertices farthest apart."""
    pts = np.asarray(coords)
    hull = shapely.convex_hull(shapely.MultiPoint(pts))
    h = np.asarray(hull.exterior.coords)[:-1]
    d = np.linalg.norm(h[:, None, :] - h[None, :, :], axis=2)
    i, j = np.unravel_index(np.argmax(d), d.shape)
    a, b = h[i], h[j]
    ia = int(np.argmin(np.linalg.norm(pts - a, axis=1)))
    ib = int(np.argmin(np.linalg.norm(pts - b, axis=1)))
    return ia, ib


def outward_line(poly, others, v, length):
    """A straight line from outside to boundary vertex `v`, meeting `poly` only at `v` and no
    other polygon: tried along the vertex's outward bisector and a few turns of it."""
    ring = np.asarray(poly.exterior.coords)[:-1]
    k = int(np.argmin(np.linalg.norm(ring - v, axis=1)))
    prev, nxt = ring[k - 1], ring[(k + 1) % len(ring)]
    # Outward: away from the polygon's inside near v.
    centre = np.asarray(poly.representative_point().coords[0])
    e1, e2 = prev - v, nxt - v
    bis = -(e1 / np.linalg.norm(e1) + e2 / np.linalg.norm(e2))
    if np.linalg.norm(bis) < 1e-9:
        bis = v - centre
    bis = bis / np.linalg.norm(bis)
    for turn in [0, 20, -20, 40, -40, 60, -60, 80, -80]:
        t = np.radians(turn)
        d = np.array([bis[0] * np.cos(t) - bis[1] * np.sin(t), bis[0] * np.sin(t) + bis[1] * np.cos(t)])
        far = v + d * length
        line = LineString([tuple(far), tuple(v)])
        meet = line.intersection(poly)
        if not meet.equals(Point(v)) and not (meet.geom_type == "Point" and meet.distance(Point(v)) < 1e-6):
            continue
        if any(line.intersects(o) for o in others):
            continue
        return line
    return None


def lines_for(layer, polys, rng, banks):
    rows = []
    for fid, poly in polys.items():
        others = [p for f, p in polys.items() if f != fid]
        coords = np.asarray(poly.exterior.coords)[:-1]
        ia, ib = farthest_pair(coords)
        span = np.linalg.norm(coords[ia] - coords[ib])
        tips = [ia, ib]
        if layer.startswith("lakes") and fid % 3 == 0:
            da = np.linalg.norm(coords - coords[ia], axis=1)
            db = np.linalg.norm(coords - coords[ib], axis=1)
            tips.append(int(np.argmax(np.minimum(da, db))))
        chosen = [(i, "tip") for i in tips]
        for _ in range(banks):
            chosen.append((int(rng.integers(len(coords))), "bank"))
        for i, role in chosen:
            line = outward_line(poly, others, coords[i], max(0.1 * span, 200.0))
            if line is not None:
                rows.append({"polygon": int(fid), "role": role, "geometry": line})
    return rows


def train(src, out):
    rng = np.random.default_rng(SEED)
    for layer, banks in [("lakes_scotland", 0), ("river_st_lawrence", 6), ("river_danube", 4), ("river_lena", 6)]:
        df = gpd.read_file(src, layer=layer, fid_as_index=True)
        polys = {int(f): g for f, g in zip(df.index, df.geometry)}
        rows = lines_for(layer, polys, rng, banks)
        gpd.GeoDataFrame(rows, crs=df.crs).to_file(out, layer=f"lines_{layer}", driver="GPKG")


def disc(cx, cy, r, n=64):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return Polygon(np.c_[cx + r * np.cos(t), cy + r * np.sin(t)])


def cases(out):
    x0, y0 = 500_000.0, 6_000_000.0
    rows, lines = [], []
    # A lake 10 km long, 1.2 km wide, with three bays 2.5–3 km long, 400 m wide.
    body = shapely.buffer(LineString([(x0, y0), (x0 + 10_000, y0)]), 600, cap_style="round", quad_segs=16)
    bays = [LineString([(x0 + 2500, y0), (x0 + 2800, y0 + 3000)]),
            LineString([(x0 + 5000, y0), (x0 + 5400, y0 - 2800)]),
            LineString([(x0 + 7500, y0), (x0 + 7300, y0 + 2600)])]
    lake = shapely.union_all([body] + [shapely.buffer(b, 200, quad_segs=8) for b in bays])
    lake = shapely.set_precision(lake, 0.01)
    rows.append({"name": "bays_lake", "geometry": lake})
    west = min(lake.exterior.coords, key=lambda c: c[0])
    east = max(lake.exterior.coords, key=lambda c: c[0])
    lines.append({"name": "bays_lake_in", "geometry": LineString([(west[0] - 3000, west[1] + 500), west])})
    lines.append({"name": "bays_lake_out", "geometry": LineString([east, (east[0] + 3000, east[1] - 400)])})
    # A Y: three arms 4 km long, 800 m wide, from one centre.
    cx, cy = x0, y0 + 15_000
    arms = [LineString([(cx, cy), (cx + 4000 * np.cos(a), cy + 4000 * np.sin(a))])
            for a in np.radians([90, 210, 330])]
    y_lake = shapely.set_precision(shapely.union_all([shapely.buffer(a, 400, quad_segs=16) for a in arms]), 0.01)
    rows.append({"name": "y_lake", "geometry": y_lake})
    for k, a in enumerate(np.radians([90, 210, 330])):
        d = np.array([np.cos(a), np.sin(a)])
        tip = max(y_lake.exterior.coords, key=lambda c: np.dot(np.asarray(c) - (cx, cy), d))
        lines.append({"name": f"y_lake_{k}", "geometry": LineString([tip, tuple(np.asarray(tip) + d * 2000)])})
    # A river reach 12 km long, 1 km wide, with an island 3 km long in its middle.
    ry = y0 + 30_000
    outer = Polygon([(x0, ry - 500), (x0 + 12_000, ry - 500), (x0 + 12_000, ry + 500), (x0, ry + 500)])
    outer = shapely.segmentize(outer, 100)
    island = shapely.buffer(LineString([(x0 + 4500, ry), (x0 + 7500, ry)]), 150, quad_segs=8)
    river = shapely.set_precision(outer.difference(island), 0.01)
    rows.append({"name": "island_river", "geometry": river})
    lines.append({"name": "island_river_in", "geometry": LineString([(x0 - 3000, ry), (x0, ry)])})
    lines.append({"name": "island_river_out", "geometry": LineString([(x0 + 12_000, ry), (x0 + 15_000, ry)])})
    lines.append({"name": "island_river_north", "geometry": LineString([(x0 + 6000, ry + 500), (x0 + 6000, ry + 3500)])})
    lines.append({"name": "island_river_south", "geometry": LineString([(x0 + 6500, ry - 3500), (x0 + 6500, ry - 500)])})
    # A lake no line meets.
    rows.append({"name": "lonely_lake", "geometry": shapely.set_precision(disc(x0 + 20_000, y0, 1500), 0.01)})
    # An ellipse 8 km × 1.6 km with one line at its west end.
    t = np.linspace(0, 2 * np.pi, 128, endpoint=False)
    sx, sy = x0 + 20_000, y0 + 15_000
    spring = shapely.set_precision(Polygon(np.c_[sx + 4000 * np.cos(t), sy + 800 * np.sin(t)]), 0.01)
    rows.append({"name": "spring_lake", "geometry": spring})
    west = min(spring.exterior.coords, key=lambda c: c[0])
    lines.append({"name": "spring_lake_out", "geometry": LineString([west, (west[0] - 3000, west[1])])})
    gpd.GeoDataFrame(rows, crs="EPSG:32633").to_file(out, layer="cases", driver="GPKG")
    gpd.GeoDataFrame(lines, crs="EPSG:32633").to_file(out, layer="cases_lines", driver="GPKG")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    tmp = out + ".tmp.gpkg"
    train(src, tmp)
    cases(tmp)
    # Re-written by the system's GDAL, so that the file's GeoPackage version is one it reads
    # without a warning.
    subprocess.run(["ogr2ogr", "-f", "GPKG", out, tmp], check=True)
    os.remove(tmp)
