#!/usr/bin/env python3
"""How a run's skeleton matches a street layer's reference (the measure of `tests/all/streets.rs`, for
any layer made like `make_streets.py`'s or `make_state_streets.py`'s): for each reference junction the
output junctions (degree ≥ 3) within its local width (twice its distance to the street space's
boundary) — one, several or none —, how many reference junctions get a node of their own when each
output node serves at most one (nearest pairs first: a node between two junctions serves one), output
junctions near no reference junction, line ends against
the reference's ends (one within 16 m each), and the output lines' distance to the reference lines
(sampled every metre: median and 90th percentile).

usage: streets_match.py DATA.gpkg LAYER OUT.gpkg [OUT.gpkg...]   (OUT: a run's output, layer skeletons)
needs: geopandas, shapely (PyPI)
"""

import sys
from collections import Counter

import geopandas as gpd
import shapely
from shapely.geometry import Point


def main(data, layer, outs):
    space = shapely.union_all(list(gpd.read_file(data, layer=layer).geometry))
    junctions = list(gpd.read_file(data, layer=layer + "_junctions").geometry)
    ends = list(gpd.read_file(data, layer=layer + "_ends").geometry)
    reference = shapely.union_all(list(gpd.read_file(data, layer=layer + "_lines").geometry))
    print("| output | junctions | one node each / several / none (of n) | one to one | nodes near none "
          "| ends (reference) | one end each | distance to the reference: median, 90 % |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|")
    for out in outs:
        lines = [g for geom in gpd.read_file(out, layer="skeletons").geometry for g in getattr(geom, "geoms", [geom])]
        degree = Counter(c for line in lines for c in (line.coords[0], line.coords[-1]))
        nodes = [Point(p) for p, d in degree.items() if d >= 3]
        leaves = [Point(p) for p, d in degree.items() if d == 1]

        def width(p):
            return 2 * space.boundary.distance(p)

        each = [sum(1 for o in nodes if o.distance(r) <= width(r)) for r in junctions]
        pairs = sorted((o.distance(r), i, k) for i, r in enumerate(junctions) for k, o in enumerate(nodes)
                       if o.distance(r) <= width(r))
        served, used = set(), set()
        for _, i, k in pairs:
            if i not in served and k not in used:
                served.add(i)
                used.add(k)
        extra = sum(1 for o in nodes if all(o.distance(r) > width(r) for r in junctions))
        one_end = sum(1 for r in ends if sum(1 for e in leaves if e.distance(r) <= 16.0) == 1)
        union = shapely.union_all(lines)
        d = sorted(reference.distance(union.interpolate(t)) for t in range(int(union.length)))
        print(f"| {out} | {len(nodes)} | {each.count(1)} / {sum(1 for x in each if x > 1)} / {each.count(0)} "
              f"(of {len(junctions)}) | {len(served)} | {extra} | {len(leaves)} ({len(ends)}) | {one_end} | "
              f"{d[len(d) // 2]:.2f} m, {d[int(len(d) * 0.9)]:.2f} m |")


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
