#!/usr/bin/env python3
"""Roundabouts on a real road network, for `prune: {roundabouts: D}`.

Adds to DATA.gpkg (written by `make_streets.py`) the layers `roundabouts` (one polygon of street
space), `roundabouts_lines`, `roundabouts_junctions` and `roundabouts_ends`: the `roads` layer's
network (`roads_lines`: real rivers buffered as 16 m roads) with a roundabout at each of its
junctions inside the road space that lies at least 80 m from every other junction — a ring road 16 m
wide around a round island of radius 12 m centred on the junction (the ring's centreline 20 m from
it), the roads meeting the ring. The reference is the roads' own lines, which run through the
junctions: with the roundabouts made one node, each junction has one node, at the island's centre.
`roundabouts_junctions` has the junctions with a roundabout (`arms`: their degree, `island`: 1) and
the other junctions of the network (`island`: 0).

    scripts/make_roundabouts.py tests/data/streets.gpkg
    scripts/make_roundabouts.py DATA.gpkg SOURCE NAME ISLAND HALF APART
        # any other street layer of DATA (SOURCE, with SOURCE_lines, _junctions, _ends) into
        # NAME, NAME_lines, …: islands of radius ISLAND, ring roads 2 × HALF wide
needs: geopandas, shapely (PyPI)
"""

import sys

import geopandas as gpd
import shapely
from shapely.geometry import Point

ISLAND = 12.0  # the island's radius (m)
HALF = 8.0  # half the width of the roads and the ring (m)
APART = 80.0  # least distance from a roundabout's junction to any other junction (m)


def main(data: str, source: str = "roads", name: str = "roundabouts", island: float = ISLAND,
         half: float = HALF, apart: float = APART) -> None:
    space = shapely.union_all(list(gpd.read_file(data, layer=source).geometry))
    lines = gpd.read_file(data, layer=source + "_lines")
    junctions = gpd.read_file(data, layer=source + "_junctions")
    ends = gpd.read_file(data, layer=source + "_ends")
    crs = lines.crs
    pts = list(junctions.geometry)
    ringed = [
        i for i, p in enumerate(pts)
        if junctions.arms[i] >= 3 and all(p.distance(q) >= apart for j, q in enumerate(pts) if j != i)
    ]
    for i in ringed:
        c = pts[i]
        ring = c.buffer(island + 2 * half, quad_segs=32).difference(c.buffer(island, quad_segs=32))
        space = space.union(ring).difference(c.buffer(island, quad_segs=32))
    parts = list(getattr(space, "geoms", [space]))
    frames = {
        name: gpd.GeoDataFrame({"name": [f"{source} with roundabouts"] * len(parts)}, geometry=parts, crs=crs),
        name + "_lines": lines,
        name + "_junctions": gpd.GeoDataFrame(
            {"arms": list(junctions.arms), "island": [int(i in ringed) for i in range(len(pts))]},
            geometry=pts, crs=crs),
        name + "_ends": ends,
    }
    for layer, frame in frames.items():
        frame.to_file(data, layer=layer, driver="GPKG")
    print(f"{len(ringed)} roundabouts of {len(pts)} junctions; {len(parts)} polygons")


if __name__ == "__main__":
    if len(sys.argv) not in (2, 7):
        sys.exit(__doc__)
    main(sys.argv[1], *sys.argv[2:4], *map(float, sys.argv[4:7]))
