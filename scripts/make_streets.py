#!/usr/bin/env python3
"""Street space and its reference centrelines, for `prune: {junctions: merge}`.

Writes OUT (GeoPackage, EPSG:32633, metres) with these layers:

- `quarter` / `quarter_lines`: a generated city quarter — streets 8 to 16 m wide on a skewed
  grid: four-way crossings, T-junctions, two five-arm junctions where a diagonal street meets a
  crossing, a street that crosses the grid at 70°, a dead end, every street cut straight by the
  data's edge — as the union of the streets' buffers (flat caps, mitred joins), clipped to the
  quarter's box; the lines buffered (clipped the same way) are the reference.
- `roads` / `roads_lines`: a real line network buffered as a road layer's centrelines are: the
  rivers of GMT's GSHHG/WDBII river layer in 8–12° E, 46–50° N (Wessel & Smith, LGPL-3.0; Debian
  `gmt gmt-gshhg-full`), joined where they meet, scaled by 1/20 and buffered by 8 m (16 m wide
  roads, round joins), the lines the reference.

Every polygon has the field `name`; the reference lines `name` and `width` (the street's). Beside
each pair, `<name>_junctions`: the reference's junctions inside the street space (points where three
or more lines meet, the lines noded where they cross), with `arms` (their degree); and
`<name>_ends`: the reference's line ends (dead ends, and where the data's edge cuts a line). The
quarter also has `quarter_blocks`: the blocks between its streets (the box minus the street space),
each with `block` (its number), for the street pieces' `left_fid` and `right_fid`, and
`quarter_ragged`: the same street space cut by a rough edge instead of the box (every side a vertex
each metre, moved across it by up to ±1 m, seeded), whose reference is the quarter's.
- `states` / `states_lines` / `states_junctions` / `states_ends`: street space between real blocks,
  21 US states of GMT's DCW as a quarter (`scripts/make_state_streets.py`, which writes these alone).

    scripts/make_streets.py tests/data/streets.gpkg
"""

from __future__ import annotations

import os
import sys

import geopandas as gpd
import shapely
import shapely.ops
from shapely import affinity
from shapely.geometry import LineString, box

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_state_streets import frames as state_frames, gmt_segments  # noqa: E402

X0, Y0 = 500_000.0, 6_650_000.0


def ragged_box(x0, y0, x1, y1, amp, step, seed):
    """The box with a vertex every `step` m along its sides, each moved across its side by up to
    ±`amp` m (seeded): a cut that is not straight, as a digitised or rasterised boundary gives."""
    import random

    from shapely.geometry import Polygon

    rnd = random.Random(seed)

    def side(a, b):
        n = max(1, int(round(((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2) ** 0.5 / step)))
        out = []
        for i in range(n):
            t = i / n
            x, y = a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t
            if i > 0:
                d = rnd.uniform(-amp, amp)
                x, y = (x + d, y) if a[0] == b[0] else (x, y + d)
            out.append((x, y))
        return out

    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    ring = Polygon([c for a, b in zip(corners, corners[1:]) for c in side(a, b)])
    # Teeth longer than the step may cross near a corner.
    return ring if ring.is_valid else shapely.make_valid(ring)


def quarter(clip=None):
    streets = [
        # (name, line, width)
        ("first", [(-50, 0), (650, 0)], 12),
        ("second", [(-50, 160), (650, 160)], 10),
        ("third", [(-50, 330), (650, 330)], 16),
        ("a", [(100, -60), (100, 390)], 10),
        ("b", [(260, -60), (260, 390)], 14),
        ("c", [(420, -60), (420, 390)], 10),
        # Diagonal from the crossing b/first to the crossing c/second: five arms at both.
        ("diagonal", [(260, 0), (420, 160)], 9),
        # Crossing the grid at 70 degrees.
        ("skew", [(470, -60), (470 + 450 / 2.747, 390)], 8),
        # A dead end off `second`.
        ("dead end", [(180, 160), (180, 250)], 8),
    ]
    clip = box(0, -40, 600, 370) if clip is None else clip
    lines, polys = [], []
    for name, coords, width in streets:
        line = LineString(coords)
        polys.append(line.buffer(width / 2, cap_style="flat", join_style="mitre"))
        lines.append((name, line.intersection(clip), width))
    space = shapely.union_all(polys).intersection(clip)
    return space, lines, list(clip.difference(space).geoms)


def roads():
    """Rivers of GMT's GSHHG/WDBII river layer (all rivers, full resolution) in 8–12° E,
    46–50° N as a real line network: joined where they meet, in UTM 32N, scaled by 1/20 about the
    network's corner (a 15 × 22 km network of 10 junctions), buffered by 8 m."""
    from shapely.geometry import LineString

    segments = [LineString(c) for c in gmt_segments("coast", "-R8/12/46/50", "-Ia", "-Df", "-M") if len(c) > 1]
    utm = gpd.GeoSeries(segments, crs=4326).to_crs(32632)
    merged = shapely.line_merge(shapely.node(shapely.union_all(utm.values)))
    parts = list(getattr(merged, "geoms", [merged]))
    # A tributary's mouth stops short of its river in the data (up to ~300 m): joined to it, so
    # that the reference has the junction the roads' space shows.
    joined = []
    for i, part in enumerate(parts):
        others = shapely.union_all([q for j, q in enumerate(parts) if j != i])
        coords = list(part.coords)
        for k in (0, -1):
            end = shapely.Point(coords[k])
            if 0 < end.distance(others) <= 300.0:
                foot = shapely.ops.nearest_points(end, others)[1]
                coords.insert(0 if k == 0 else len(coords), (foot.x, foot.y))
        joined.append(LineString(coords))
    # A line that overshoots the one it meets leaves a dangle shorter than the road's width
    # (400 m here: 20 m once scaled), which is no arm of a junction: dropped.
    from collections import Counter

    noded = list(shapely.node(shapely.union_all(joined)).geoms)
    degree = Counter(c for p in noded for c in (p.coords[0], p.coords[-1]))
    # So is a small loop where a line crosses itself.
    kept = [p for p in noded
            if not (p.length < 400.0 and (1 in (degree[p.coords[0]], degree[p.coords[-1]]) or p.is_closed))]
    merged = shapely.line_merge(shapely.union_all(kept))
    parts = list(getattr(merged, "geoms", [merged]))
    b = shapely.total_bounds(parts)
    parts = [affinity.translate(affinity.scale(p, 0.05, 0.05, origin=(b[0], b[1])), X0 - b[0] + 2_000, Y0 - b[1] + 2_000)
             for p in parts]
    space = shapely.union_all([p.buffer(8, join_style="round") for p in parts])
    return space, [("river", p, 16) for p in parts]


def nodes(space, lines, crs):
    """The reference's junctions inside `space` and its line ends, as point frames."""
    from collections import Counter

    from shapely.geometry import Point

    noded = shapely.node(shapely.union_all(lines))
    degree = Counter()
    for part in getattr(noded, "geoms", [noded]):
        cs = list(part.coords)
        degree[cs[0]] += 1
        degree[cs[-1]] += 1
    junctions = [(p, d) for p, d in sorted(degree.items()) if d >= 3 and space.contains(Point(p))]
    ends = [p for p, d in sorted(degree.items()) if d == 1]
    return (
        gpd.GeoDataFrame({"arms": [d for _, d in junctions]}, geometry=[Point(p) for p, _ in junctions], crs=crs),
        gpd.GeoDataFrame({"kind": ["end"] * len(ends)}, geometry=[Point(p) for p in ends], crs=crs),
    )


def main(out: str) -> None:
    crs = "EPSG:32633"
    q_space, q_lines, q_blocks = quarter()
    q_space = affinity.translate(q_space, X0, Y0)
    frames = {
        "quarter": gpd.GeoDataFrame({"name": ["quarter"]}, geometry=[q_space], crs=crs),
        "quarter_lines": gpd.GeoDataFrame(
            {"name": [n for n, _, _ in q_lines], "width": [w for _, _, w in q_lines]},
            geometry=[affinity.translate(g, X0, Y0) for _, g, _ in q_lines], crs=crs),
    }
    blocks = [affinity.translate(b, X0, Y0) for b in q_blocks]
    frames["quarter_blocks"] = gpd.GeoDataFrame({"block": list(range(1, len(blocks) + 1))}, geometry=blocks, crs=crs)
    # The same quarter cut by a rough edge: ±1 m every metre (a tenth of a 10 m street's width).
    ragged, _, _ = quarter(ragged_box(0, -40, 600, 370, 1.0, 1.0, 3))
    # Where the skewed street leaves the quarter by a corner the teeth cut off slivers: dropped.
    ragged = max(getattr(ragged, "geoms", [ragged]), key=lambda g: g.area)
    frames["quarter_ragged"] = gpd.GeoDataFrame({"name": ["quarter"]}, geometry=[affinity.translate(ragged, X0, Y0)],
                                                crs=crs)
    r_space, r_lines = roads()
    frames["roads"] = gpd.GeoDataFrame({"name": ["lena roads"]}, geometry=[r_space], crs=crs)
    frames["roads_lines"] = gpd.GeoDataFrame(
        {"name": [n for n, _, _ in r_lines], "width": [w for _, _, w in r_lines]},
        geometry=[g for _, g, _ in r_lines], crs=crs)
    for name in ("quarter", "roads"):
        space = frames[name].geometry.values[0]
        junctions, ends = nodes(space, list(frames[name + "_lines"].geometry.values), crs)
        frames[name + "_junctions"], frames[name + "_ends"] = junctions, ends
    # Street space between real blocks (US states of GMT's DCW): scripts/make_state_streets.py.
    frames.update(state_frames())
    for layer, frame in frames.items():
        frame.to_file(out, layer=layer, driver="GPKG")


if __name__ == "__main__":
    main(sys.argv[1])
