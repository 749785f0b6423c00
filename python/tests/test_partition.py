"""The `partition` step through the real binary: a collapsed polygon's area given to the
units around it. Every output is checked as a coverage with GEOS (shapely's
coverage_is_valid), for conserved area, units unchanged bit for bit where they received
nothing, units that only grow, and — on the training rivers with their generated
coverages (tests/data/coverage-train.gpkg, made by scripts/make_coverage.py) — that random
points lie in the unit whose bank is nearest and that the new boundaries are centred,
against GEOS CoverageCleaner on the same data (scripts/partition_quality.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import geopandas as gpd
import numpy as np
import pyogrio
import pytest
import shapely
from shapely.geometry import Polygon, box

from conftest import ROOT, cli_binary

sys.path.insert(0, str(ROOT / "scripts"))
import partition_quality as pq  # noqa: E402

COVERAGE = ROOT / "tests" / "data" / "coverage-train.gpkg"
RIVERS = ("danube", "lena", "st_lawrence")


def run(pipeline: Path | str, out: Path, *sets: str, src: Path = COVERAGE, check=True):
    args = [str(cli_binary()), "run", str(pipeline), "-o", str(out), "-q"]
    for s in sets:
        args += ["--set", s]
    env = dict(os.environ, SKELETONISE_SRC=str(src))
    return subprocess.run(args, cwd=ROOT, env=env, capture_output=True, text=True, check=check)


def run_river(name: str, out: Path, *sets: str):
    return run(ROOT / "pipelines" / "partition-rivers.yaml", out,
               f"input.layer=rivers_{name}", f"input.neighbours.layer=units_{name}", *sets)


# --- the training rivers ---------------------------------------------------------------


@pytest.fixture(scope="module")
def partitioned(tmp_path_factory):
    d = tmp_path_factory.mktemp("partition")
    out = {}
    for name in RIVERS:
        run_river(name, d / f"{name}.gpkg")
        out[name] = d / f"{name}.gpkg"
    return out


@pytest.mark.parametrize("name", RIVERS)
def test_a_training_river_gives_its_area_to_the_nearest_banks_units(partitioned, name):
    m = pq.measure_ours(COVERAGE, f"rivers_{name}", f"units_{name}", partitioned[name], samples=20000)
    assert m["coverage_valid"] and m["all_valid"], m
    assert m["area_rel"] <= 1e-9, m
    assert m["given_rel"] <= 1e-9, m
    assert m["unchanged_bit_for_bit"] and m["shrunk"] == 0 and m["same_order"], m
    assert m["grown"] > 10, m
    assert m["nearest"] >= 0.999, m
    assert m["z_mean"] <= 0.001, m


def test_the_peer_gives_the_whole_river_to_one_neighbour(partitioned):
    # GEOS CoverageCleaner (longest shared border) on the same data: valid, but the new
    # boundaries run along a bank (z = 1) and most of the river goes to a far unit.
    m = pq.measure_peer(COVERAGE, "rivers_danube", "units_danube")
    ours = pq.measure_ours(COVERAGE, "rivers_danube", "units_danube", partitioned["danube"], samples=5000)
    assert m["coverage_valid"]
    assert m["z_mean"] > 0.9 and ours["z_mean"] < 0.001
    assert m["nearest"] < 0.5 < ours["nearest"]


@pytest.mark.parametrize("name,width", [("danube", 1200), ("lena", 4000), ("st_lawrence", 3000)])
def test_with_width_the_wide_parts_stay_and_the_rest_is_given(tmp_path, name, width):
    out = tmp_path / "w.gpkg"
    run_river(name, out, f"steps.partition.width={width}")
    m = pq.measure_ours(COVERAGE, f"rivers_{name}", f"units_{name}", out, samples=0)
    assert m["coverage_valid"] and m["all_valid"] and m["area_rel"] <= 1e-9, m
    assert m["unchanged_bit_for_bit"] and m["shrunk"] == 0 and m["grown"] > 5, m
    areas = pyogrio.read_dataframe(out, layer="areas")
    assert set(areas["kind"]) == {"wide"} and (areas["cuts"] > 0).all()
    rivers = pyogrio.read_dataframe(COVERAGE, layer=f"rivers_{name}")
    given = pyogrio.read_dataframe(out, layer="given", read_geometry=False)["area"].sum()
    total = rivers.geometry.area.sum()
    assert 0.05 * total < given < 0.95 * total
    assert abs(given + areas.geometry.area.sum() - total) <= 1e-9 * total
    # The wide parts are wide: their inscribed circle is more than width·(1 − tolerance).
    radius = shapely.maximum_inscribed_circle(areas.geometry.values, tolerance=width / 100)
    assert (shapely.length(radius) * 2 > width * 0.8).all()


# --- constructed cases -----------------------------------------------------------------


def write_case(path: Path, rivers: list, units: list):
    """rivers and units as layers of a GeoPackage, FIDs from 1 in the order given."""
    rg = gpd.GeoDataFrame({"name": [f"r{i + 1}" for i in range(len(rivers))]}, geometry=rivers, crs="EPSG:3857")
    ug = gpd.GeoDataFrame({"name": [f"u{i + 1}" for i in range(len(units))]}, geometry=units, crs="EPSG:3857")
    pyogrio.write_dataframe(rg, path, layer="rivers", driver="GPKG", dataset_options={"VERSION": "1.2"})
    pyogrio.write_dataframe(ug, path, layer="units", driver="GPKG")
    return path


def partition_case(tmp_path, rivers, units, options="{}"):
    src = write_case(tmp_path / "case.gpkg", rivers, units)
    yaml = tmp_path / "case.yaml"
    yaml.write_text(f"""name: case
input:
  source: {src}
  layer: rivers
  neighbours: {{ source: {src}, layer: units }}
steps:
  - skeleton: {{ methods: [MA] }}
  - partition: {options}
output: {{ path: {tmp_path / 'out.gpkg'}, overwrite: true }}
on_error: reject
""")
    out = tmp_path / "out.gpkg"
    run(yaml, out)
    m = pq.measure_ours(src, "rivers", "units", out, samples=4000)
    assert m["coverage_valid"] and m["all_valid"] and m["area_rel"] <= 1e-9, m
    assert m["unchanged_bit_for_bit"] and m["shrunk"] == 0, m
    layers = {n for n, _ in pyogrio.list_layers(out)}

    def read(layer):
        """The layer's rows, or None when it has none."""
        frame = pyogrio.read_dataframe(out, layer=layer) if layer in layers else None
        return frame if frame is not None and len(frame) else None

    return m, read("coverage"), read("boundaries"), read("areas")


def boundary(bnd, a, b):
    """The boundary line between units a and b (FIDs), whichever side each is on."""
    rows = bnd[((bnd.left_fid == a) & (bnd.right_fid == b)) | ((bnd.left_fid == b) & (bnd.right_fid == a))]
    assert len(rows) == 1, bnd[["left_fid", "right_fid"]]
    return rows.geometry.iloc[0]


CANAL = box(0, 0, 100, 10)
BELOW = box(0, -20, 100, 0)
ABOVE = box(0, 10, 100, 30)
LEFT_END = box(-20, 0, 0, 10)
RIGHT_END = box(100, 0, 120, 10)


def test_a_straight_canal_is_split_on_its_centre_line(tmp_path):
    m, cov, bnd, areas = partition_case(tmp_path, [CANAL], [BELOW, ABOVE, LEFT_END, RIGHT_END])
    assert areas is None and m["nearest"] == 1.0
    line = boundary(bnd, 1, 2)
    assert np.allclose(shapely.get_coordinates(line)[:, 1], 5.0, atol=1e-9)
    assert abs(line.length - 90.0) < 1e-9  # from (5, 5) to (95, 5): the ends' bisectors
    got = dict(zip(cov.src_fid, cov.geometry.area))
    assert abs(got[1] - (2000 + 475)) < 1e-9 and abs(got[3] - (200 + 25)) < 1e-9


def test_a_third_unit_on_one_bank_starts_its_boundary_at_the_meeting_point(tmp_path):
    # The bottom bank split at x = 40: the normal at x = 40 up to the centre line.
    m, cov, bnd, _ = partition_case(
        tmp_path, [CANAL], [box(0, -20, 40, 0), box(40, -20, 100, 0), ABOVE, LEFT_END, RIGHT_END])
    line = boundary(bnd, 1, 2)
    xy = shapely.get_coordinates(line)
    assert np.allclose(xy[:, 0], 40.0, atol=1e-9) and set(np.round(xy[:, 1], 9)) == {0.0, 5.0}
    assert m["nearest"] >= 0.999


def test_a_t_junction_of_channels_between_three_units(tmp_path):
    # A horizontal channel and one running north from its middle; three units around.
    t = shapely.union(box(0, 0, 100, 10), box(45, 10, 55, 60))
    sw = Polygon([(0, -20), (100, -20), (100, 0), (0, 0)])
    nw = Polygon([(0, 10), (45, 10), (45, 60), (0, 60)])
    ne = Polygon([(55, 10), (100, 10), (100, 60), (55, 60)])
    t = shapely.set_precision(t, 0)
    m, cov, bnd, areas = partition_case(tmp_path, [t], [sw, nw, ne])
    # Three boundaries meet at one point inside the junction; the channel's ends belong
    # to no unit (kept apart).
    assert {(min(a, b), max(a, b)) for a, b in zip(bnd.left_fid.fillna(0), bnd.right_fid.fillna(0))} >= {(1, 2), (1, 3), (2, 3)}
    ends = [shapely.get_coordinates(boundary(bnd, a, b)) for a, b in [(1, 2), (1, 3), (2, 3)]]
    meets = [set(map(tuple, e[[0, -1]])) for e in ends]
    assert meets[0] & meets[1] & meets[2], meets
    # The north channel is split on its centre line x = 50.
    assert np.allclose(ends[2][:, 0], 50.0, atol=1e-9)
    assert m["nearest"] >= 0.999 and set(areas["kind"]) == {"unowned"}


def test_an_island_that_is_a_unit_grows_to_the_middle_of_both_channels(tmp_path):
    river = Polygon(box(0, 0, 100, 30).exterior.coords, [box(40, 10, 60, 20).exterior.coords[::-1]])
    island = box(40, 10, 60, 20)
    m, cov, bnd, _ = partition_case(tmp_path, [river], [box(0, -20, 100, 0), box(0, 30, 100, 50), island,
                                                         box(-20, 0, 0, 30), box(100, 0, 120, 30)])
    # Half way to each bank, and east and west to where both banks are as near.
    grown = cov.set_index("src_fid").geometry[3]
    assert np.allclose(grown.bounds, (25.0, 5.0, 75.0, 25.0), atol=1e-6), grown.bounds
    assert m["nearest"] >= 0.999


def test_a_polygon_whose_whole_bank_is_one_units_goes_to_it_whole(tmp_path):
    lake = box(10, 10, 30, 20)
    commune = Polygon(box(0, 0, 40, 30).exterior.coords, [lake.exterior.coords[::-1]])
    m, cov, bnd, areas = partition_case(tmp_path, [lake], [commune, box(40, 0, 60, 30)])
    assert bnd is None
    assert areas is None
    grown = cov.set_index("src_fid").geometry[1]
    assert shapely.equals(grown, box(0, 0, 40, 30)) and grown.area == 1200.0


def test_a_river_to_the_sea_keeps_or_gives_the_area_nearest_the_mouth(tmp_path):
    # The river's east end is the coverage's edge (the sea): bank no unit owns.
    river = box(0, 0, 100, 10)
    units = [BELOW, ABOVE, LEFT_END]
    m, cov, bnd, areas = partition_case(tmp_path, [river], units)
    assert list(areas["kind"]) == ["unowned"] and abs(areas.geometry.area.iloc[0] - 25.0) < 1e-9
    m, cov, bnd, areas = partition_case(tmp_path, [river], units, "{ unowned: nearest }")
    assert areas is None
    assert abs(cov.geometry.area.sum() - (2000 + 2000 + 200 + 1000)) < 1e-9


def test_a_reflex_meeting_point_splits_its_cell_on_the_bisector(tmp_path):
    # An L-shaped channel; on its inner bank two units meet at the reflex corner (50, 10).
    ell = Polygon([(0, 0), (60, 0), (60, 60), (50, 60), (50, 10), (0, 10)])
    a = Polygon([(0, 10), (50, 10), (0, 60)])  # owns the edge (0,10)–(50,10)
    b = Polygon([(50, 10), (50, 60), (0, 60)])  # owns the edge (50,10)–(50,60)
    outer = Polygon([(0, -20), (80, -20), (80, 60), (60, 60), (60, 0), (0, 0)])
    m, cov, bnd, _ = partition_case(tmp_path, [ell], [a, b, outer])
    line = boundary(bnd, 1, 2)
    xy = shapely.get_coordinates(line)
    s = 10 / (1 + 2 ** 0.5)  # where the bisector meets the medial axis
    # From the corner along (1, −1) to where the corner is as near as the outer bank.
    assert len(xy) == 2
    start, end = sorted(map(tuple, xy), key=lambda c: -c[1])
    assert start == (50.0, 10.0)
    assert np.allclose(end, (50 + s, 10 - s), atol=1e-6), end
    assert m["nearest"] >= 0.999


def test_a_polygon_over_a_unit_is_rejected_and_its_neighbours_are_unchanged(tmp_path):
    src = write_case(tmp_path / "case.gpkg", [CANAL], [BELOW, box(50, 2, 60, 20)])
    yaml = tmp_path / "case.yaml"
    yaml.write_text(f"""name: case
input: {{ source: {src}, layer: rivers, neighbours: {{ source: {src}, layer: units }} }}
steps: [ {{ skeleton: {{ methods: [MA] }} }}, {{ partition: {{}} }} ]
output: {{ path: {tmp_path / 'out.gpkg'} }}
on_error: reject
""")
    r = run(yaml, tmp_path / "out.gpkg", check=False)
    out = tmp_path / "out.gpkg"
    rejected = pyogrio.read_dataframe(out, layer="rejected")
    assert list(rejected.src_fid) == [1]
    assert "overlaps the interior of unit 2" in rejected.reason.iloc[0]
    cov = pyogrio.read_dataframe(out, layer="coverage")
    units = pyogrio.read_dataframe(src, layer="units")
    assert shapely.equals_exact(cov.geometry.values, pq.as_multi(units.geometry.values), tolerance=0).all()
    assert r.returncode == 0 and "overlaps the interior of unit 2" in r.stderr
    # Under `on_error: fail` the run stops with exit code 65 and writes nothing.
    (tmp_path / "out.gpkg").unlink()
    r = run(yaml, tmp_path / "out.gpkg", "on_error=fail", check=False)
    assert r.returncode == 65 and "overlaps the interior of unit 2" in r.stderr, r.stderr
    assert not (tmp_path / "out.gpkg").exists()


def test_a_raster_staircase_river_is_partitioned_like_a_smooth_one(tmp_path):
    # The Danube reach as a raster of 40 m cells makes it (staircase banks: reflex and
    # straight-angle vertices everywhere, unit boundaries meeting the bank on a step), with a
    # generated coverage around it.
    import make_coverage
    import make_partition_bench

    danube = pyogrio.read_dataframe(ROOT / "tests" / "data" / "gshhg-train.gpkg", layer="river_danube")
    stairs = make_partition_bench.staircase(danube.geometry.iloc[0], 40.0)
    rivers, units = make_coverage.coverage(stairs, 40, 3000.0, 0.01, np.random.default_rng(7), 1)
    m, cov, bnd, areas = partition_case(tmp_path, rivers, units)
    assert m["nearest"] >= 0.999 and m["z_mean"] <= 0.001 and m["grown"] >= 10, m
