#!/usr/bin/env python3
"""Street space between real blocks: 21 US states of GMT's DCW (Debian `gmt-dcw`, public domain) as
blocks scaled to a city quarter, their shared borders 10 m wide streets.

The states CO UT AZ NM WY NE KS OK TX ID MT SD ND NV IA MO AR LA MN WI IL, in EPSG:5070: for each pair
of neighbours the part of one's boundary within 2 km of the other is their shared border; the borders'
ends within 15 km of each other meet at their mean (the junctions; where three states meet, or four at
Four Corners). Scaled by 1/5000 (a state ~100 m wide), simplified to 0.5 m, each border is the centre
line of a street 10 m wide (flat ends, mitred joins, limit 2; a disc of that width at each junction),
clipped to the states' outline: the
borders that reach the outline are cut there. Real blocks' irregular shapes and skewed junctions,
river borders as meandering streets.

Writes OUT (EPSG:32633, metres): `states` (the street space), `states_lines` (the borders, the
reference centrelines), `states_junctions` (the reference's junctions inside the space, with `arms`)
and `states_ends` (the borders' ends on the outline).

    scripts/make_state_streets.py OUT.gpkg
needs: gmt, gmt-dcw (Debian); geopandas, shapely (PyPI)
"""

from __future__ import annotations

import os
import sys
from collections import Counter

import geopandas as gpd
import shapely
from shapely import affinity
from shapely.geometry import LineString, Point, Polygon


STATES = "CO UT AZ NM WY NE KS OK TX ID MT SD ND NV IA MO AR LA MN WI IL".split()
NEAR = 2_000.0  # metres (EPSG:5070): a shared border lies within this of the neighbour
MEET = 15_000.0  # border ends this close meet at one junction
SCALE, WIDTH = 1 / 5000, 10.0
X0, Y0 = 500_000.0, 6_650_000.0


def gmt_segments(*args: str) -> list[list[tuple[float, float]]]:
    """The segments (lists of lon/lat points, longitudes in −180…180) GMT prints with `-M` for `args`."""
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as d:  # GMT leaves gmt.history behind
        text = subprocess.run(["gmt", *args], check=True, capture_output=True, text=True, cwd=d).stdout
    segments, cur = [], []
    for line in text.splitlines() + [">"]:
        if line.startswith(">"):
            if cur:
                segments.append(cur)
            cur = []
        else:
            x, y = map(float, line.split()[:2])
            cur.append((x - 360 if x > 180 else x, y))
    return segments


def state(code: str) -> Polygon:
    rings = [Polygon(c) for c in gmt_segments("coast", f"-EUS.{code}", "-M", "-Df") if len(c) > 3]
    return max(rings, key=lambda p: p.area)


def borders(units):
    out = []
    for i in range(len(units)):
        for j in range(i + 1, len(units)):
            if units[i].distance(units[j]) >= NEAR:
                continue
            shared = units[i].boundary.intersection(units[j].buffer(NEAR))
            if shared.geom_type == "MultiLineString":
                shared = shapely.line_merge(shared)
            out += [g for g in getattr(shared, "geoms", [shared]) if g.geom_type == "LineString" and g.length > 3 * NEAR]
    # Border ends close together meet at their mean.
    ends = [Point(l.coords[k]) for l in out for k in (0, -1)]
    root = list(range(len(ends)))

    def find(x):
        while root[x] != x:
            x = root[x]
        return x

    for a in range(len(ends)):
        for b in range(a + 1, len(ends)):
            if ends[a].distance(ends[b]) < MEET:
                root[find(a)] = find(b)
    groups = {}
    for a in range(len(ends)):
        groups.setdefault(find(a), []).append(ends[a])
    mean = {r: (sum(p.x for p in g) / len(g), sum(p.y for p in g) / len(g)) for r, g in groups.items()}
    return [LineString([mean[find(2 * k)], *l.coords[1:-1], mean[find(2 * k + 1)]]) for k, l in enumerate(out)]


def frames() -> dict[str, gpd.GeoDataFrame]:
    """The four layers, by name."""
    units = list(gpd.GeoSeries([state(s) for s in STATES], crs=4326).to_crs(5070).values)
    lines = borders(units)
    outline = shapely.union_all(units).buffer(NEAR).buffer(-NEAR)
    b = shapely.total_bounds(units)

    def scaled(g):
        return affinity.translate(affinity.scale(g, SCALE, SCALE, origin=(b[0], b[1])), X0 - b[0], Y0 - b[1])

    lines = [scaled(l).simplify(0.5) for l in lines]
    degree = Counter(c for l in lines for c in (l.coords[0], l.coords[-1]))
    # Where three borders meet, their flat ends leave a notch on the outer side of the widest angle:
    # a disc of the street's width fills the junction as a street's corner is.
    discs = [Point(p).buffer(WIDTH / 2) for p, d in degree.items() if d >= 3]
    space = shapely.union_all([l.buffer(WIDTH / 2, cap_style="flat", join_style="mitre", mitre_limit=2.0)
                               for l in lines] + discs).intersection(scaled(outline))
    junctions = [(Point(p), d) for p, d in degree.items() if d >= 3 and space.contains(Point(p))]
    ends = [Point(p) for p, d in degree.items() if d == 1]
    crs = "EPSG:32633"
    return {
        "states": gpd.GeoDataFrame({"name": ["states"]}, geometry=[space], crs=crs),
        "states_lines": gpd.GeoDataFrame({"width": [WIDTH] * len(lines)}, geometry=lines, crs=crs),
        "states_junctions": gpd.GeoDataFrame({"arms": [d for _, d in junctions]},
                                             geometry=[p for p, _ in junctions], crs=crs),
        "states_ends": gpd.GeoDataFrame({"kind": ["end"] * len(ends)}, geometry=ends, crs=crs),
    }


def main(path: str) -> None:
    if os.path.exists(path):
        os.remove(path)
    layers = frames()
    for name, frame in layers.items():
        frame.to_file(path, layer=name, driver="GPKG")
    print(f"{path}: {len(layers['states_lines'])} streets, {len(layers['states_junctions'])} junctions, "
          f"{len(layers['states_ends'])} ends")

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
