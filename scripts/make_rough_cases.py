"""Writes the constructed rough-boundary cases of tests/data/rough-cases.gpkg
(layer `cases`, EPSG:32633, one polygon per case, field `name`):

* `slot_spike_river`: a gently curving river reach 12 km long and 1.5 km wide (cut
  square at both ends) with
  seeded bank noise (±5 m every 50 m), a 250 m slot 2 m wide into its north
  bank and a 300 m V-spike 60 m wide at its base into its south bank. The
  medial axis has a leg into each; neither is an arm of the river.
* `tip_lake`: a compact lake, a disc of radius 2 km whose east side is a
  broad flat shore and whose south end runs out into a tip 2.5 km long. Its
  line should end in the south tip, not at the middle of the east shore.
* `crescent`: a crescent lake (the difference of two discs), horns north and
  south; its line should reach both horns.

usage: make_rough_cases.py OUT.gpkg
needs: shapely, geopandas, pyogrio, numpy (PyPI)
"""

import sys

import geopandas as gpd
import numpy as np
import shapely

X0, Y0 = 500_000.0, 6_000_000.0


def slot_spike_river():
    rng = np.random.default_rng(20261205)
    length, half = 12_000.0, 750.0
    xs = np.arange(0.0, length + 1.0, 50.0)

    def centre(x):  # level at both ends: the reach ends square to its course
        return 600.0 * np.cos(x / length * 2 * np.pi)

    north = [(x, centre(x) + half + rng.uniform(-5, 5)) for x in xs]
    south = [(x, centre(x) - half + rng.uniform(-5, 5)) for x in xs]
    # The slot: 250 m deep, 2 m wide, straight into the north bank at 4 km.
    k = int(4000 / 50)
    x, y = north[k]
    north[k:k + 1] = [(x - 1, y), (x - 1, y + 250), (x + 1, y + 250), (x + 1, y)]
    # The V-spike: 300 m deep, 60 m wide at its base, into the south bank at 8 km.
    k = int(8000 / 50)
    x, y = south[k]
    south[k:k + 1] = [(x - 30, y), (x + 2, y - 300), (x + 30, y)]
    ring = south + north[::-1]
    return shapely.Polygon([(X0 + a, Y0 + b) for a, b in ring])


def tip_lake():
    # A disc of radius 2 km, its east side cut flat at x = 1.6 km, and a
    # tip tapering from 1.2 km wide to 60 m over 2.5 km south of the disc.
    disc = shapely.Point(0, 0).buffer(2000, quad_segs=32)
    flat = shapely.box(-3000, -3000, 1600, 3000)
    tip = shapely.Polygon([(-600, -1800), (-30, -4300), (30, -4300), (600, -1800)])
    lake = shapely.union(shapely.intersection(disc, flat), tip)
    return shapely.affinity.translate(lake, X0 + 10_000, Y0 + 20_000)


def crescent():
    outer = shapely.Point(0, 0).buffer(3000, quad_segs=48)
    inner = shapely.Point(1400, 0).buffer(2500, quad_segs=48)
    return shapely.affinity.translate(shapely.difference(outer, inner), X0 + 20_000, Y0 + 20_000)


cases = {"slot_spike_river": slot_spike_river(), "tip_lake": tip_lake(), "crescent": crescent()}
for name, g in cases.items():
    assert g.is_valid and g.geom_type == "Polygon", name
gpd.GeoDataFrame({"name": list(cases)}, geometry=list(cases.values()), crs="EPSG:32633").to_file(
    sys.argv[1], layer="cases", driver="GPKG"
)
print(f"{sys.argv[1]}: {len(cases)} cases")
