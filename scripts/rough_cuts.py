#!/usr/bin/env python3
"""Street ends on rough cuts: the generated city quarter of `make_streets.py` cut by a rough edge
(a vertex every STEP m along the quarter's box, moved across it by up to ±AMP m, seeded) instead of
the straight box, through `prune: {junctions: merge}` — for each binary given, how many variants have
exactly the reference's line ends (15, one within 16 m of each) and junctions (12).

usage: rough_cuts.py BINARY [BINARY...]      e.g. an older build and target/release/skeletonise
needs: geopandas, shapely (PyPI)
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from collections import Counter

import geopandas as gpd
import shapely
from shapely import affinity
from shapely.geometry import Point

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_streets as ms  # noqa: E402

AMPS = (0.5, 1.0, 1.5, 2.0)
STEPS = (1.0, 2.0, 4.0)
SEEDS = range(1, 8)
PIPELINE = """input: {{ source: {src}, layer: quarter }}
steps:
  - skeleton: {{}}
  - prune: {{ junctions: merge }}
  - extend: {{}}
  - score: {{}}
  - select: {{}}
output: {{ path: {out}, overwrite: true }}
"""


def nodes(path):
    """Line ends and junctions of the skeleton, without components shorter than 5 m (slivers the
    teeth cut off where a street leaves by a corner)."""
    lines = [p for g in gpd.read_file(path, layer="skeletons").geometry for p in getattr(g, "geoms", [g])]
    key = [(tuple(l.coords[0]), tuple(l.coords[-1])) for l in lines]
    parent = {}

    def find(x):
        while parent.setdefault(x, x) != x:
            x = parent[x]
        return x

    for a, b in key:
        parent[find(a)] = find(b)
    length = Counter()
    for (a, _), line in zip(key, lines):
        length[find(a)] += line.length
    degree = Counter()
    for a, b in key:
        if length[find(a)] >= 5.0:
            degree[a] += 1
            degree[b] += 1
    return [Point(p) for p, d in degree.items() if d == 1], [Point(p) for p, d in degree.items() if d >= 3]


def main(binaries):
    ref = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "streets.gpkg")
    ref_ends = list(gpd.read_file(ref, layer="quarter_ends").geometry)
    ref_junctions = list(gpd.read_file(ref, layer="quarter_junctions").geometry)
    right = Counter()
    with tempfile.TemporaryDirectory() as d:
        src, out, yaml = (os.path.join(d, n) for n in ("q.gpkg", "o.gpkg", "p.yaml"))
        with open(yaml, "w") as f:
            f.write(PIPELINE.format(src=src, out=out))
        for amp in AMPS:
            for step in STEPS:
                for seed in SEEDS:
                    space, _, _ = ms.quarter(ms.ragged_box(0, -40, 600, 370, amp, step, seed))
                    space = affinity.translate(space, ms.X0, ms.Y0)
                    gpd.GeoDataFrame({"name": ["quarter"]}, geometry=[space], crs=32633).to_file(src, layer="quarter")
                    for b in binaries:
                        subprocess.run([b, "run", yaml, "-q"], check=True)
                        ends, junctions = nodes(out)
                        ok = (len(ends) == len(ref_ends) and len(junctions) == len(ref_junctions)
                              and all(sum(e.distance(r) <= 16.0 for e in ends) == 1 for r in ref_ends))
                        right[(b, amp)] += ok
    print("| rough edge | variants | " + " | ".join(f"`{b}`: ends and junctions right" for b in binaries) + " |")
    print("|---|--:|" + "--:|" * len(binaries))
    for amp in AMPS:
        n = len(STEPS) * len(SEEDS)
        print(f"| ±{amp} m | {n} | " + " | ".join(str(right[(b, amp)]) for b in binaries) + " |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
