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
* `lobe_lake`: a compact lake, a disc of radius 2 km drawn with 96 shallow
  bank vertices, with one rounded lobe 700 m wide running 1.6 km out to the
  north-east. Its line should end in the lobe, along the lobe's axis, not
  at a vertex of the broad shore.
* `corner_island`: a near-square island 2 km across whose north-east
  corner is drawn out into a sharp corner (about 30°). Its line should end
  in that corner.

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


def lobe_lake():
    disc = shapely.Point(0, 0).buffer(2000, quad_segs=24)
    # The lobe: a 700 m wide band along the north-east diagonal, ending in
    # a half disc 3.6 km from the centre.
    axis = shapely.LineString([(0, 0), (3600 / 2**0.5 - 350 / 2**0.5, 3600 / 2**0.5 - 350 / 2**0.5)])
    lobe = axis.buffer(350, quad_segs=8)
    return shapely.affinity.translate(shapely.union(disc, lobe), X0 + 30_000, Y0 + 20_000)


def corner_island():
    square = shapely.Polygon([(0, 0), (2000, 0), (2000, 1500), (2700, 2700), (1500, 2000), (0, 2000)])
    return shapely.affinity.translate(square, X0 + 40_000, Y0 + 20_000)


cases = {
    "slot_spike_river": slot_spike_river(),
    "tip_lake": tip_lake(),
    "crescent": crescent(),
    "lobe_lake": lobe_lake(),
    "corner_island": corner_island(),
}
for name, g in cases.items():
    assert g.is_valid and g.geom_type == "Polygon", name
gpd.GeoDataFrame({"name": list(cases)}, geometry=list(cases.values()), crs="EPSG:32633").to_file(
    sys.argv[1], layer="cases", driver="GPKG"
)
print(f"{sys.argv[1]}: {len(cases)} cases")
