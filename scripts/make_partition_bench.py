#!/usr/bin/env python3
"""Makes the `partition` benchmark's data: N collapsed polygons from the
training data, each with a coverage of units around it (scripts/make_coverage.py),
placed apart on a grid: the Scottish lochs and the Danube reach as they are, and
the lochs as a raster makes them (cells of CELL metres inside the loch, their
union: staircase banks), in turn.

    scripts/make_partition_bench.py OUT.gpkg [--rivers 1000] [--seeds 10]
        [--buffer 2000] [--cell 40] [--seed 1]

writes the layers `rivers` and `units` (as make_coverage.py does) in EPSG:32630.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import shapely

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_coverage import coverage  # noqa: E402

TRAIN = Path(__file__).resolve().parents[1] / "tests" / "data" / "gshhg-train.gpkg"


def staircase(polygon, cell):
    """The polygon as a raster of `cell` sees it: the union of the grid cells
    whose centre lies inside, exactly (shared cell edges, integer grid)."""
    minx, miny, maxx, maxy = polygon.bounds
    xs = np.arange(np.floor(minx / cell), np.ceil(maxx / cell)) * cell
    ys = np.arange(np.floor(miny / cell), np.ceil(maxy / cell)) * cell
    gx, gy = np.meshgrid(xs, ys)
    inside = shapely.contains_xy(polygon, gx + cell / 2, gy + cell / 2)
    boxes = shapely.box(gx[inside], gy[inside], gx[inside] + cell, gy[inside] + cell)
    merged = shapely.coverage_union_all(boxes)
    # The largest connected part (a raster can cut a narrow loch in two).
    return max(shapely.get_parts(merged), key=lambda g: g.area)


def base_shapes(cell):
    lakes = pyogrio.read_dataframe(TRAIN, layer="lakes_scotland").geometry.values
    danube = pyogrio.read_dataframe(TRAIN, layer="river_danube").geometry.values
    smooth = list(lakes) + list(danube)
    rough = [staircase(g, cell) for g in lakes]
    shapes = smooth + rough
    # Each moved to the origin.
    return [shapely.affinity.translate(g, -g.bounds[0], -g.bounds[1]) for g in shapes]


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("out")
    a.add_argument("--rivers", type=int, default=1000)
    a.add_argument("--seeds", type=int, default=10, help="units per river")
    a.add_argument("--buffer", type=float, default=2000.0)
    a.add_argument("--cell", type=float, default=40.0, help="raster cell of the staircase lochs (m)")
    a.add_argument("--seed", type=int, default=1)
    o = a.parse_args()
    import shapely.affinity  # noqa: F401

    shapes = base_shapes(o.cell)
    size = max(max(g.bounds[2], g.bounds[3]) for g in shapes) + 2 * o.buffer + 1000
    per_row = int(np.ceil(np.sqrt(o.rivers)))
    rng = np.random.default_rng(o.seed)
    rivers, units = [], []
    for i in range(o.rivers):
        g = shapely.affinity.translate(shapes[i % len(shapes)], (i % per_row) * size, (i // per_row) * size)
        r, u = coverage(g, o.seeds, o.buffer, 0.01, rng, 1)
        rivers += r
        units += u
    rg = gpd.GeoDataFrame(
        {"id": np.arange(1, len(rivers) + 1), "name": [f"river {i + 1}" for i in range(len(rivers))]},
        geometry=rivers, crs="EPSG:32630")
    landuse = np.array(["forest", "field", "town", "meadow"])
    ug = gpd.GeoDataFrame(
        {"id": np.arange(1, len(units) + 1), "landuse": landuse[np.arange(len(units)) % 4]},
        geometry=units, crs="EPSG:32630")
    pyogrio.write_dataframe(rg, o.out, layer="rivers", driver="GPKG", dataset_options={"VERSION": "1.2"})
    pyogrio.write_dataframe(ug, o.out, layer="units", driver="GPKG")
    v = int(shapely.get_num_coordinates(rg.geometry.values).sum())
    print(f"{o.out}: {len(rg)} polygons ({v} vertices), {len(ug)} units")


if __name__ == "__main__":
    main()
