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


def partition_case(tmp_path, rivers, units, options="{}", covering=False):
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
    m = pq.measure_ours(src, "rivers", "units", out, samples=4000, covering=covering)
    assert m["coverage_valid"] and m["all_valid"] and m["area_rel"] <= 1e-9, m
    assert m["unchanged_bit_for_bit"] and (covering or m["shrunk"] == 0), m
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


def test_a_polygon_over_a_unit_is_rejected_with_overlap_reject_and_its_neighbours_are_unchanged(tmp_path):
    src = write_case(tmp_path / "case.gpkg", [CANAL], [BELOW, box(50, 2, 60, 20)])
    yaml = tmp_path / "case.yaml"
    yaml.write_text(f"""name: case
input: {{ source: {src}, layer: rivers, neighbours: {{ source: {src}, layer: units }} }}
steps: [ {{ skeleton: {{ methods: [MA] }} }}, {{ partition: {{ overlap: reject }} }} ]
output: {{ path: {tmp_path / 'out.gpkg'} }}
on_error: reject
""")
    r = run(yaml, tmp_path / "out.gpkg", check=False)
    out = tmp_path / "out.gpkg"
    rejected = pyogrio.read_dataframe(out, layer="rejected")
    assert list(rejected.src_fid) == [1]
    assert "overlaps unit 2 of `input.neighbours` (80 CRS units² of it lie inside the unit)" in rejected.reason.iloc[0]
    cov = pyogrio.read_dataframe(out, layer="coverage")
    units = pyogrio.read_dataframe(src, layer="units")
    assert shapely.equals_exact(cov.geometry.values, pq.as_multi(units.geometry.values), tolerance=0).all()
    assert r.returncode == 0 and "overlaps unit 2" in r.stderr
    # Under `on_error: fail` the run stops with exit code 65 and writes nothing.
    (tmp_path / "out.gpkg").unlink()
    r = run(yaml, tmp_path / "out.gpkg", "on_error=fail", check=False)
    assert r.returncode == 65 and "overlaps unit 2" in r.stderr, r.stderr
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


# --- real administrative units that cover the water (overlap: cut) ----------------------

BORDER = ROOT / "tests" / "data" / "border-waters.gpkg"
BORDER_CASES = ("geneva", "constance", "erie", "titicaca", "parana", "victoria")


def run_border(name: str, out: Path, units: str | None = None, *sets: str):
    return run(ROOT / "pipelines" / "partition-border-waters.yaml", out, f"input.layer=waters_{name}",
               f"input.neighbours.layer={units or 'units_' + name}", *sets, src=BORDER)


@pytest.fixture(scope="module")
def border(tmp_path_factory):
    d = tmp_path_factory.mktemp("border")
    out = {}
    for name in BORDER_CASES:
        run_border(name, d / f"{name}.gpkg")
        run_border(name, d / f"{name}-4326.gpkg", f"units_{name}_4326")
        out[name] = d / f"{name}.gpkg"
    return out


@pytest.mark.parametrize("name", BORDER_CASES)
def test_units_that_cover_a_real_border_water_share_it_down_the_middle(border, name):
    # DCW countries and states around GSHHG lakes and river-lakes (scripts/make_border_waters.py):
    # the legal boundary inside the water, the units' coasts not the water's shore.
    out = border[name]
    layers = {n for n, _ in pyogrio.list_layers(out)}
    assert "rejected" not in layers or len(pyogrio.read_dataframe(out, layer="rejected")) == 0
    m = pq.measure_ours(BORDER, f"waters_{name}", f"units_{name}", out, samples=20000, covering=True)
    assert m["coverage_valid"] and m["all_valid"], m
    # Area: what the units and the waters covered, but for vertices moved within the snap.
    assert m["area_rel"] <= 1e-8, m
    assert m["unchanged_bit_for_bit"] and m["same_order"], m
    assert m["nearest"] >= 0.999, m
    assert m["z_mean"] <= 0.001, m
    given = pyogrio.read_dataframe(out, layer="given", read_geometry=False)
    waters = pyogrio.read_dataframe(BORDER, layer=f"waters_{name}")
    # The units held (nearly) all the water before; what they are given now is the same water.
    water = waters.geometry.area.sum()
    assert 0.9 * water < given.held.sum() <= (1 + 1e-9) * water
    assert 0.9 * water < given.area.sum() <= (1 + 1e-9) * water


@pytest.mark.parametrize("name", BORDER_CASES)
def test_the_same_units_in_longitude_latitude_give_the_same_areas(border, name):
    a = pyogrio.read_dataframe(border[name], layer="coverage")
    other = border[name].with_name(f"{name}-4326.gpkg")
    b = pyogrio.read_dataframe(other, layer="coverage")
    assert "rejected" not in {n for n, _ in pyogrio.list_layers(other)} or \
        len(pyogrio.read_dataframe(other, layer="rejected")) == 0
    assert shapely.coverage_is_valid(b.geometry.values) and shapely.is_valid(b.geometry.values).all()
    assert list(a.src_fid) == list(b.src_fid)
    rel = np.abs(a.geometry.area.values - b.geometry.area.values) / a.geometry.area.values
    assert rel.max() <= 1e-6, rel


@pytest.mark.parametrize("name", RIVERS)
def test_a_clean_coverage_given_in_longitude_latitude_gives_the_same_result(partitioned, tmp_path, name):
    # Reprojection moves the shared bank vertices by round-off; the snap puts them back.
    lonlat = tmp_path / "units.gpkg"
    units = pyogrio.read_dataframe(COVERAGE, layer=f"units_{name}", fid_as_index=True).to_crs(4326)
    pyogrio.write_dataframe(units, lonlat, layer=f"units_{name}")
    out = tmp_path / "o.gpkg"
    run_river(name, out, f"input.neighbours.source={lonlat}")
    layers = {n for n, _ in pyogrio.list_layers(out)}
    assert "rejected" not in layers or len(pyogrio.read_dataframe(out, layer="rejected")) == 0
    a = pyogrio.read_dataframe(partitioned[name], layer="coverage")
    b = pyogrio.read_dataframe(out, layer="coverage")
    rel = np.abs(a.geometry.area.values - b.geometry.area.values) / a.geometry.area.values
    assert rel.max() <= 1e-6, rel
    assert shapely.coverage_is_valid(b.geometry.values)


def test_units_that_cover_the_canal_with_the_legal_line_inside_give_the_middle(tmp_path):
    m, cov, bnd, areas = partition_case(
        tmp_path, [CANAL], [box(0, -20, 100, 3), box(0, 3, 100, 30), LEFT_END, RIGHT_END], covering=True)
    assert areas is None and m["nearest"] == 1.0
    assert np.allclose(shapely.get_coordinates(boundary(bnd, 1, 2))[:, 1], 5.0, atol=1e-9)
    got = dict(zip(cov.src_fid, zip(cov.geometry.area, cov.held)))
    assert got[1] == (2475.0, 300.0) and got[2] == (2475.0, 700.0)


def test_a_unit_equal_to_the_river_keeps_its_row_with_no_area(tmp_path):
    m, cov, bnd, areas = partition_case(tmp_path, [CANAL], [CANAL, BELOW, ABOVE, LEFT_END, RIGHT_END], covering=True)
    first = cov[cov.src_fid == 1].iloc[0]
    assert first.geometry is None or first.geometry.is_empty
    assert first.held == 1000.0 and first.received == 0.0
    assert np.allclose(shapely.get_coordinates(boundary(bnd, 2, 3))[:, 1], 5.0, atol=1e-9)
    r = subprocess.run([str(cli_binary()), "run", str(tmp_path / "case.yaml")], cwd=ROOT, capture_output=True,
                       text=True, check=True)
    assert "1 units lie wholly in the collapsed polygons (FIDs 1)" in r.stderr, r.stderr


def test_a_unit_covering_the_river_with_collinear_sides_is_cut(tmp_path):
    # Its top side runs along the canal's far bank, its ends along the canal's ends.
    m, cov, bnd, _ = partition_case(tmp_path, [CANAL], [box(0, -20, 100, 10), ABOVE, LEFT_END, RIGHT_END],
                                    covering=True)
    got = dict(zip(cov.src_fid, zip(cov.geometry.area, cov.held)))
    assert got[1] == (2475.0, 1000.0) and got[2] == (2475.0, 0.0)
    r = run(tmp_path / "case.yaml", tmp_path / "out.gpkg", "steps.partition.overlap=reject")
    rejected = pyogrio.read_dataframe(tmp_path / "out.gpkg", layer="rejected")
    assert "overlaps unit 1 of `input.neighbours` (1000 CRS units²" in rejected.reason.iloc[0], r.stderr


def test_a_lake_inside_a_unit_not_cut_out_goes_back_to_it(tmp_path):
    lake = box(10, 10, 30, 20)
    m, cov, bnd, areas = partition_case(tmp_path, [lake], [box(0, 0, 40, 30), box(40, 0, 60, 30)], covering=True)
    assert areas is None and bnd is None
    grown = cov.set_index("src_fid").geometry[1]
    assert shapely.equals(grown, box(0, 0, 40, 30)) and grown.area == 1200.0 and len(grown.geoms) == 1


def test_a_unit_wholly_inside_the_water_keeps_its_row_and_the_run_goes_on(tmp_path):
    m, cov, bnd, _ = partition_case(tmp_path, [CANAL], [BELOW, ABOVE, LEFT_END, RIGHT_END, box(40, 4, 60, 6)],
                                    covering=True)
    last = cov[cov.src_fid == 5].iloc[0]
    assert (last.geometry is None or last.geometry.is_empty) and last.held == 40.0
    assert np.allclose(shapely.get_coordinates(boundary(bnd, 1, 2))[:, 1], 5.0, atol=1e-9)


def test_a_unit_corner_a_hair_off_a_river_vertex_gives_a_valid_coverage(tmp_path):
    off = (100 + 1e-7, 1e-7)
    m, cov, bnd, _ = partition_case(
        tmp_path, [CANAL],
        [Polygon([(0, -20), (100, -20), off, (0, 0)]), Polygon([off, (120, 0), (120, 10), (100, 10)]), ABOVE, LEFT_END],
        covering=True)
    assert shapely.is_valid(cov.geometry.values).all() and m["nearest"] >= 0.999


def test_a_sliver_of_a_unit_along_the_others_bank_narrower_than_snap_owns_nothing(tmp_path):
    # Unit 1 has a 1e-9 wide strip between unit 2 and the canal's top bank (snap: 1e-5 here).
    w = 1e-9
    m, cov, bnd, _ = partition_case(
        tmp_path, [CANAL], [shapely.MultiPolygon([BELOW, box(0, 10, 100, 10 + w)]), box(0, 10 + w, 100, 30),
                            LEFT_END, RIGHT_END], covering=True)
    assert np.allclose(shapely.get_coordinates(boundary(bnd, 1, 2))[:, 1], 5.0, atol=1e-9)
    got = dict(zip(cov.src_fid, cov.geometry.area))
    assert abs(got[1] - 2475.0) < 1e-6 and abs(got[2] - 2475.0) < 1e-6


def test_two_reaches_overlapping_by_a_millimetre_are_dissolved_first(tmp_path):
    reaches = [box(0, 0, 50.001, 10), box(50, 0, 100, 10)]
    src = write_case(tmp_path / "case.gpkg", reaches, [BELOW, ABOVE, LEFT_END, RIGHT_END])
    yaml = tmp_path / "case.yaml"
    yaml.write_text(f"""name: case
input: {{ source: {src}, layer: rivers, neighbours: {{ source: {src}, layer: units }} }}
steps: [ {{ skeleton: {{ methods: [MA] }} }}, {{ partition: {{}} }} ]
output: {{ path: {tmp_path / 'out.gpkg'} }}
""")
    r = run(yaml, tmp_path / "out.gpkg")
    assert "features 1, 2 overlap each other" in r.stderr
    cov = pyogrio.read_dataframe(tmp_path / "out.gpkg", layer="coverage")
    assert shapely.coverage_is_valid(cov.geometry.values) and shapely.is_valid(cov.geometry.values).all()
    assert abs(cov.geometry.area.sum() - (2000 + 2000 + 200 + 200 + 1000)) < 1e-6
    # Every ring readable: at least four points.
    for g in cov.geometry:
        for p in g.geoms:
            assert len(p.exterior.coords) >= 4 and all(len(i.coords) >= 4 for i in p.interiors)


def test_a_rejected_group_of_reaches_lists_every_member_with_its_geometry(tmp_path):
    reaches = [box(0, 0, 50, 10), box(50, 0, 100, 10)]
    src = write_case(tmp_path / "case.gpkg", reaches, [box(0, -20, 100, 10), ABOVE, LEFT_END, RIGHT_END])
    yaml = tmp_path / "case.yaml"
    yaml.write_text(f"""name: case
input: {{ source: {src}, layer: rivers, neighbours: {{ source: {src}, layer: units }} }}
steps: [ {{ skeleton: {{ methods: [MA] }} }}, {{ partition: {{ overlap: reject }} }} ]
output: {{ path: {tmp_path / 'out.gpkg'} }}
""")
    run(yaml, tmp_path / "out.gpkg")
    rejected = pyogrio.read_dataframe(tmp_path / "out.gpkg", layer="rejected")
    assert list(rejected.src_fid) == [1, 2]
    assert shapely.equals(rejected.geometry.iloc[0], reaches[0]) and shapely.equals(rejected.geometry.iloc[1], reaches[1])
    assert rejected.reason.str.contains("merged features 1,2").all()


def test_a_unit_with_a_nan_coordinate_stops_the_run_with_its_fid_and_an_empty_one_is_a_null_one(tmp_path):
    nan = Polygon([(0, 10), (100, 10), (100, 30), (float("nan"), 30)])
    src = write_case(tmp_path / "case.gpkg", [CANAL], [BELOW, nan, LEFT_END, RIGHT_END])
    yaml = tmp_path / "case.yaml"
    yaml.write_text(f"""name: case
input: {{ source: {src}, layer: rivers, neighbours: {{ source: {src}, layer: units }} }}
steps: [ {{ skeleton: {{ methods: [MA] }} }}, {{ partition: {{}} }} ]
output: {{ path: {tmp_path / 'out.gpkg'} }}
""")
    r = run(yaml, tmp_path / "out.gpkg", check=False)
    assert r.returncode not in (0, 101) and "feature 2 has a coordinate that is not a finite number" in r.stderr, r.stderr
    assert "panicked" not in r.stderr and not (tmp_path / "out.gpkg").exists()
    m, cov, bnd, _ = partition_case(tmp_path, [CANAL], [BELOW, ABOVE, Polygon(), LEFT_END, RIGHT_END])
    empty = cov[cov.src_fid == 3].iloc[0]
    assert (empty.geometry is None or empty.geometry.is_empty) and empty.received == 0.0
