"""`skeletonise.skeletonise` and `skeletonise.apply` on small shapes: columns, options,
rejected rows, repairs, candidates, explode, exchange formats and the GIL."""

from __future__ import annotations

import os
import threading
import time

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest
import shapely
from shapely.geometry import MultiPolygon, Point, Polygon, box

import skeletonise
from conftest import ROOT

RIVER = box(0, 0, 100, 10)
BOW_TIE = Polygon([(0, 0), (4, 4), (4, 0), (0, 6)])


def test_columns_are_the_skeletons_layer_then_rejected_and_the_geometry():
    names = [n for n, _ in skeletonise.columns("skeletons")]
    assert names == [
        "src_fid", "method", "bars", "hits", "coverage", "deviation", "deviation_parts",
        "distortion_sum", "distortion", "components", "legs", "repaired", "note",
    ]
    assert "polygon_part" in [n for n, _ in skeletonise.columns("skeletons", explode=True)]
    out = skeletonise.skeletonise(gpd.GeoSeries([RIVER]))
    assert list(out.columns) == names + ["rejected", "geometry"]
    assert str(out["legs"].dtype) == "Int32" and str(out["src_fid"].dtype) == "Int64"
    assert out["coverage"].dtype == np.float64 and str(out["method"].dtype) == "string"


def test_a_rectangle_gets_the_centre_line_from_ma():
    out = skeletonise.skeletonise([RIVER])
    row = out.iloc[0]
    assert row["method"] == "MA" and row["legs"] == 1 and pd.isna(row["rejected"])
    assert row["distortion"] < 1e-9 and row["coverage"] > 0.9
    assert row.geometry.equals(shapely.MultiLineString([[(0, 5), (100, 5)]]))


def test_every_row_comes_back_with_its_index_and_reason():
    geoms = gpd.GeoSeries(
        [RIVER, None, Point(1, 2), shapely.Polygon(), box(0, 0, 0.1, 0.1), BOW_TIE],
        index=pd.Index([10, 11, 12, 13, 14, 15]),
        crs="EPSG:3035",
    )
    out = skeletonise.skeletonise(geoms, min_area=1.0)
    assert list(out.index) == [10, 11, 12, 13, 14, 15] and out.crs == geoms.crs
    assert list(out["src_fid"]) == [10, 11, 12, 13, 14, 15]
    r = out["rejected"]
    assert pd.isna(r[10]) and out["method"][10] == "MA"
    assert r[11].startswith("NULL geometry")
    assert r[12] == "point geometry: only polygons and multipolygons can be skeletonised"
    assert r[13].startswith("empty geometry")
    # filtered by min_area: no skeleton, no reason
    assert pd.isna(r[14]) and pd.isna(out["method"][14]) and out.geometry[14] is None
    # repaired by make_valid (the default), as GDAL's MakeValid does in the command line
    assert pd.isna(r[15]) and out["repaired"][15] == 1 and out["repaired"][10] == 0
    assert out.attrs["skeletonise"]["counts"] == {"read": 6, "written": 2, "rejected": 3, "filtered": 1}


def test_missing_and_empty_polygons_give_the_same_reasons_in_either_exchange():
    geoms = gpd.GeoSeries([RIVER, None, shapely.Polygon(), MultiPolygon([RIVER])])
    a = skeletonise.skeletonise(geoms, exchange="geoarrow")
    b = skeletonise.skeletonise(geoms)
    assert a.attrs["skeletonise"]["exchange"] == "geoarrow" and b.attrs["skeletonise"]["exchange"] == "wkb"
    assert list(a["rejected"].isna()) == [True, False, False, True]
    assert a["rejected"][1].startswith("NULL geometry") and a["rejected"][2].startswith("empty geometry")
    pd.testing.assert_frame_equal(a.drop(columns="geometry"), b.drop(columns="geometry"))


def test_without_make_valid_an_invalid_polygon_is_rejected_with_the_reason():
    out = skeletonise.skeletonise([BOW_TIE], make_valid=False)
    assert "invalid polygon" in out["rejected"][0] and "make_valid" in out["rejected"][0]
    assert out.geometry[0] is None


def test_on_error_fail_raises_the_command_line_text():
    with pytest.raises(skeletonise.RejectedError) as e:
        skeletonise.skeletonise(gpd.GeoSeries([RIVER, Point(0, 0)], index=[5, 7]), on_error="fail")
    assert str(e.value) == (
        "feature 7 was rejected: point geometry: only polygons and multipolygons can be skeletonised "
        "(on_error: fail stops the run; no output was written; use `on_error: reject` to list such "
        "features in the `rejected` layer instead)"
    )


@pytest.mark.parametrize(
    "kwargs, text",
    [
        ({"prune": {"ratoi": 1}}, "skeletonise(): `prune.ratoi`: unknown field `ratoi`, expected one of"),
        ({"methods": ["MA", "XX"]}, "skeletonise(): `methods[1]`: unknown method `XX`; expected one of VD, DVD, CDT, StSk, MA"),
        ({"min_area": -1}, "skeletonise(): `min_area`: min_area must be ≥ 0 (CRS units²)"),
        ({"select": {"min_coverage": 2}}, "skeletonise(): `select.min_coverage`:"),
        ({"on_error": "ignore"}, "skeletonise(): `on_error`: unknown variant `ignore`"),
        ({"prune": 3}, "skeletonise(): `prune`: expected a mapping"),
    ],
)
def test_options_are_validated_with_the_pipeline_file_messages(kwargs, text):
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.skeletonise([RIVER], **kwargs)
    assert str(e.value).startswith(text), str(e.value)


def test_option_messages_equal_the_pipeline_files(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("steps:\n  - skeleton: {methods: [CDT]}\n  - prune: {ratoi: 1}\n")
    with pytest.raises(skeletonise.PipelineError) as from_file:
        skeletonise.apply(gpd.GeoDataFrame(geometry=[RIVER]), bad)
    with pytest.raises(skeletonise.PipelineError) as from_kwargs:
        skeletonise.skeletonise([RIVER], methods=["CDT"], prune={"ratoi": 1})
    file_text, kw_text = str(from_file.value), str(from_kwargs.value)
    assert file_text.startswith(f"{bad}:3:13: `steps[1].prune.ratoi`: ")
    assert file_text.split("`: ", 1)[1] == kw_text.split("`: ", 1)[1]


def test_a_collapse_pipeline_is_refused_with_the_reason():
    # The collapse step's kept areas are a layer of their own, which only the command line writes.
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.apply(gpd.GeoDataFrame(geometry=[RIVER]), ROOT / "pipelines" / "collapse-rivers.yaml")
    assert "`collapse` step" in str(e.value) and "skeletonise run" in str(e.value), str(e.value)


def test_a_partition_pipeline_is_refused_with_the_reason():
    # The partition step reads a second source and writes the grown coverage at the end of a run.
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.apply(gpd.GeoDataFrame(geometry=[RIVER]), ROOT / "pipelines" / "partition-rivers.yaml")
    assert "`partition` step" in str(e.value) and "skeletonise run" in str(e.value), str(e.value)


def test_step_options_reach_the_steps():
    wavy = shapely.buffer(shapely.LineString([(0, 0), (50, 20), (100, 0), (150, 20)]), 5)
    trunk = skeletonise.skeletonise([wavy], prune="trunk", methods=["CDT", "MA"])
    assert trunk["legs"][0] == 1 and trunk["method"][0] in ("CDT", "MA")
    raw = skeletonise.skeletonise([wavy], prune=False, extend=False, methods=["CDT"])
    assert raw["legs"][0] > 1
    unscored = skeletonise.skeletonise([wavy], score=False, select=False, methods=["CDT"])
    assert pd.isna(unscored["distortion"][0]) and unscored["method"][0] == "CDT"


def test_candidates_give_every_method_one_row_and_one_chosen():
    out = skeletonise.skeletonise(gpd.GeoSeries([RIVER, box(0, 0, 30, 20)], index=["a", "b"]), candidates=True)
    assert list(out.columns) == [n for n, _ in skeletonise.columns("candidates")] + ["rejected", "geometry"]
    assert list(out.index) == ["a"] * 5 + ["b"] * 5
    assert list(out["method"][:5]) == ["MA", "StSk", "DVD", "CDT", "VD"]
    assert out.groupby(level=0)["chosen"].sum().tolist() == [1, 1]
    # a non-integer index: src_fid is the position
    assert list(out["src_fid"]) == [0] * 5 + [1] * 5


def test_explode_gives_one_row_per_polygon_part():
    two = MultiPolygon([RIVER, box(200, 0, 260, 10)])
    out = skeletonise.skeletonise(gpd.GeoSeries([two, RIVER], index=[3, 4]), explode=True)
    assert list(out.index) == [3, 3, 4]
    assert list(out["polygon_part"]) == [0, 1, 0]
    whole = skeletonise.skeletonise([two])
    assert len(whole) == 1 and whole.geometry[0].geom_type == "MultiLineString"


def test_geoarrow_and_wkb_exchange_give_the_same_frame(islands):
    with pytest.raises(ValueError, match="polygons and multipolygons only"):
        skeletonise.skeletonise([RIVER, Point(0, 0)], exchange="geoarrow")
    sample = islands.geometry.iloc[:200]
    a = skeletonise.skeletonise(sample, methods=["CDT", "MA"], exchange="geoarrow", output="geoarrow")
    b = skeletonise.skeletonise(sample, methods=["CDT", "MA"], exchange="wkb", output="wkb")
    assert a.attrs["skeletonise"]["exchange"] == "geoarrow" and b.attrs["skeletonise"]["exchange"] == "wkb"
    pd.testing.assert_frame_equal(a.drop(columns="geometry"), b.drop(columns="geometry"))
    assert shapely.equals_exact(a.geometry.values, b.geometry.values, tolerance=0).all()


def test_the_result_frame_is_the_one_geopandas_builds(islands, monkeypatch):
    # The frame is assembled without GeoDataFrame's checks and copies: it must be
    # the frame the public constructor gives, and behave as one.
    from skeletonise import _geo_frame, _public_geo_frame, _strings

    sample = islands.geometry.iloc[:50]
    out = skeletonise.skeletonise(sample, candidates=True)
    tool = {c: out[c].array for c in out.columns}
    pd.testing.assert_frame_equal(_public_geo_frame(tool, out.index), out, check_exact=True)
    assert isinstance(out, gpd.GeoDataFrame) and out.geometry.name == "geometry" and out.crs == islands.crs
    moved = out.to_crs("EPSG:4326")
    assert moved.crs == "EPSG:4326" and isinstance(out.iloc[:3], gpd.GeoDataFrame)
    out["extra"] = 1
    assert "extra" not in skeletonise.skeletonise(sample).columns
    # Text columns come from Rust as Arrow buffers: the same arrays as
    # pandas' own, on the Arrow path and on the fallback that decodes them.
    for strings in (["CDT", None, "é"], [None, None], ["MA", "StSk"], []):
        encoded = [b"" if v is None else v.encode() for v in strings]
        offsets = np.cumsum([0] + [len(e) for e in encoded], dtype=np.int64)
        mask = np.array([v is None for v in strings]) if None in strings else None
        # NULLs as Rust marks them: None (no NULL), True (all), else a mask.
        nulls = [mask] + ([True] if strings and mask is not None and mask.all() else [])
        public = pd.array(strings, dtype="string")
        for probed in (skeletonise._arrow_strings(), False):
            monkeypatch.setattr(skeletonise, "_ARROW_STRINGS", probed)
            for null in nulls:
                made = _strings(offsets, b"".join(encoded), null)
                assert type(made) is type(public) and made.dtype == public.dtype and made.equals(public)
        monkeypatch.undo()
    assert skeletonise._arrow_strings() is not False, "pandas' strings are Arrow's on the pandas tested with"
    assert _geo_frame(tool, out.index).crs == islands.crs
    # The blocks are made directly on this pandas (not by the fallbacks), and
    # a frame with NULLs (a rejected row) is the public constructor's too.
    from skeletonise import _blocks, _column_index

    values = {c: out[c].values for c in out.columns if c != "extra"}
    direct = _blocks(list(values.values()), _column_index(tuple(values)), out.index)
    assert direct.nblocks == _public_geo_frame(values, out.index)._mgr.nblocks
    mixed = skeletonise.skeletonise([sample.iloc[0], Point(0, 0), None, sample.iloc[1]])
    assert mixed["rejected"].notna().tolist() == [False, True, True, False]
    assert mixed["method"].isna().tolist() == [False, True, True, False]
    mixed_tool = {c: mixed[c].array for c in mixed.columns}
    pd.testing.assert_frame_equal(_public_geo_frame(mixed_tool, mixed.index), mixed, check_exact=True)
    # A frame's columns are its own: changing one result changes no other.
    first = skeletonise.skeletonise(sample.iloc[:2])
    first.loc[first.index[0], "bars"] = -1
    first.loc[first.index[0], "rejected"] = "edited"
    again = skeletonise.skeletonise(sample.iloc[:2])
    assert again["bars"].iloc[0] > 0 and pd.isna(again["rejected"].iloc[0])


def test_wkb_in_any_byte_order_and_dimension():
    z = shapely.force_3d(RIVER, 7.0)
    for g in (z, shapely.from_wkb(shapely.to_wkb(RIVER, byte_order=0))):
        out = skeletonise.skeletonise([g, Point(0, 0)])
        assert out["method"][0] == "MA" and out["rejected"][1].startswith("point geometry")


def test_threads_give_identical_results(islands):
    sample = islands.geometry.iloc[:300]
    one = skeletonise.skeletonise(sample, threads=1, methods=["MA", "StSk"])
    two = skeletonise.skeletonise(sample, threads=2, methods=["MA", "StSk"])
    pd.testing.assert_frame_equal(one.drop(columns="geometry"), two.drop(columns="geometry"))


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores to tell one from two")
def test_one_thread_keeps_the_work_on_one_core(islands):
    # A Dask worker asks for one thread per task: the methods of a polygon,
    # run in parallel otherwise, must not spread to rayon's global pool.
    time.sleep(0.1)  # idle pool threads from earlier tests fall asleep
    cpu, wall = time.process_time(), time.perf_counter()
    for _ in range(2):
        skeletonise.skeletonise(islands.geometry, threads=1)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    assert wall > 0.2 and cpu < 1.2 * wall, (cpu, wall)


def test_the_gil_is_released_during_the_work(islands):
    ticks = 0
    done = threading.Event()

    def work():
        skeletonise.skeletonise(islands.geometry, methods=["MA", "StSk", "DVD"], threads=1)
        done.set()

    t = threading.Thread(target=work)
    start = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - start
    # With the GIL held for the whole run the loop would hardly move.
    assert elapsed > 0.05 and ticks > 0.1 * elapsed / 0.001, (ticks, elapsed)


def test_apply_keeps_columns_index_and_geometry_name(tmp_path):
    gdf = gpd.GeoDataFrame(
        {"name": ["a", "b"], "method": ["x", "y"], "area": [1.5, 2.5]},
        geometry=[RIVER, Point(0, 0)],
        index=pd.Index([100, 200], name="fid"),
        crs="EPSG:3035",
    ).rename_geometry("shape")
    p = tmp_path / "steps.yaml"
    p.write_text("steps:\n  - skeleton: {methods: [MA, CDT]}\n  - prune: {}\n  - extend: {}\n  - score: {}\n  - select: {}\n")
    out = skeletonise.apply(gdf, p)
    assert out.index.equals(gdf.index) and out.geometry.name == "shape" and out.crs == gdf.crs
    assert list(out.columns[:3]) == ["name", "src_method", "area"]
    assert list(out["name"]) == ["a", "b"] and list(out["src_method"]) == ["x", "y"]
    assert out["method"][100] == "MA" and out["rejected"][200].startswith("point geometry")
    assert list(out["src_fid"]) == [100, 200]


def test_apply_on_an_empty_frame_gives_the_typed_empty_frame():
    empty = gpd.GeoDataFrame({"k": pd.Series([], dtype="int64")}, geometry=gpd.GeoSeries([]), crs="EPSG:3035")
    out = skeletonise.apply(empty, ROOT / "pipelines" / "islands.yaml")
    assert len(out) == 0 and "method" in out.columns and "k" in out.columns
    assert str(out["legs"].dtype) == "Int32"


def test_describe_and_schema():
    assert "MA    medial axis" in skeletonise.describe()
    assert "steps" in skeletonise.schema()["properties"]


def test_a_nan_or_infinite_coordinate_rejects_its_feature_alone():
    # GEOS cannot repair such a polygon (it raises for the whole array): the
    # feature is rejected with the reason, the others are skeletonised.
    nan = Polygon([(0, 0), (10, 0), (float("nan"), 5), (0, 10)])
    inf = Polygon([(0, 0), (10, 0), (float("inf"), 5), (0, 10)])
    geoms = gpd.GeoSeries([RIVER, nan, BOW_TIE, inf], crs="EPSG:3035")
    out = skeletonise.skeletonise(geoms)
    assert list(out["method"].isna()) == [False, True, False, True]
    for i in (1, 3):
        assert "non-finite coordinate" in out["rejected"][i], out["rejected"][i]
    assert out["repaired"][2] == 1 and pd.isna(out["rejected"][2])
    frame = gpd.GeoDataFrame({"name": ["a", "b", "c", "d"]}, geometry=geoms)
    applied = skeletonise.apply(frame, ROOT / "pipelines" / "demo.yaml")
    assert list(applied["rejected"].notna()) == [False, True, False, True]


def test_a_geographic_crs_and_threads_out_of_range_are_refused_as_on_the_command_line():
    lonlat = gpd.GeoSeries([box(10, 50, 10.1, 50.01)], crs="EPSG:4326")
    with pytest.raises(ValueError, match="geographic CRS .*projected CRS: reproject first"):
        skeletonise.skeletonise(lonlat)
    with pytest.raises(ValueError, match="geographic CRS"):
        skeletonise.apply(gpd.GeoDataFrame(geometry=lonlat), ROOT / "pipelines" / "demo.yaml")
    for bad in (-1, 0, 257, 2.5, True):
        with pytest.raises(ValueError, match="give between 1 and 256 worker threads"):
            skeletonise.skeletonise([RIVER], threads=bad)
    assert skeletonise.skeletonise([RIVER], threads=1)["method"][0] == "MA"


def test_labels_give_every_lake_part_a_line_or_its_largest_disc():
    """``skeletonise.labels`` is the ``label`` step of the command line: the same rows
    as ``skeletonise run pipelines/lake-labels.yaml`` on the training lochs."""
    import subprocess
    import tempfile
    from pathlib import Path

    from conftest import cli_binary

    src = ROOT / "tests" / "data" / "gshhg-train.gpkg"
    lakes = gpd.read_file(src, layer="lakes_scotland", fid_as_index=True)
    got = skeletonise.labels(lakes)
    assert got.crs == lakes.crs
    assert (got.index.value_counts().sort_index() == 1).all()
    assert set(got.index) == set(lakes.index)
    assert "kind" in lakes.columns and "src_kind" in got.columns
    assert (got.kind == "line").sum() >= 15
    # Lines lie inside their lake; a point is the centre of the largest disc.
    for fid, row in got.iterrows():
        poly = lakes.geometry[fid]
        assert poly.contains(row.geometry)
        if row.kind == "point":
            r = poly.exterior.distance(row.geometry)
            assert abs(2 * r - row.max_width) <= 1e-6 * row.max_width
    # The same rows as the command line's `labels` layer.
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "l.gpkg"
        subprocess.run(
            [str(cli_binary()), "run", str(ROOT / "pipelines" / "lake-labels.yaml"), "-o", str(out), "-q"],
            cwd=ROOT, check=True,
        )
        cli = gpd.read_file(out, layer="labels").set_index("src_fid")
    assert list(cli.kind) == list(got.kind)
    assert list(cli.minzoom) == [int(z) for z in got.minzoom]
    assert got.minzoom.notna().all() and got.minzoom.between(0, 24).all()
    assert shapely.equals_exact(np.asarray(cli.geometry.values), np.asarray(got.geometry.values), 1e-9).all()
    # Options: `parts`, and a wrong option is the command line's message.
    islands = gpd.read_file(src, layer="islands_hebrides", fid_as_index=True).head(50)
    parts = shapely.get_parts(np.asarray(islands.geometry.values))[:3]
    multi = gpd.GeoDataFrame(geometry=[shapely.MultiPolygon(list(parts))], crs=lakes.crs)
    assert len(skeletonise.labels(multi)) == 3
    assert len(skeletonise.labels(multi, parts="largest")) == 1
    with pytest.raises(skeletonise.PipelineError, match="smooth"):
        skeletonise.labels(lakes, smooth=0)
    # Nothing is dropped: a NULL and a line get a row with the reason.
    odd = gpd.GeoSeries([None, shapely.LineString([(0, 0), (1, 1)])], crs=lakes.crs)
    rows = skeletonise.labels(odd)
    assert len(rows) == 2 and rows.rejected.notna().all()


def test_labels_keep_the_source_columns_row_by_row_under_their_own_names():
    """The source columns come with every label row, repeated for each part of a
    multipolygon, in the frame's order; one named like a label column (or ``geometry``
    while the active geometry is another) becomes ``src_<name>``, and never overwrites
    another source column."""
    src = ROOT / "tests" / "data" / "gshhg-train.gpkg"
    islands = gpd.read_file(src, layer="islands_hebrides", fid_as_index=True).head(40)
    parts = shapely.get_parts(np.asarray(islands.geometry.values))
    frame = gpd.GeoDataFrame(
        {
            "name": ["one part", "three parts", None],
            "kind": ["a", "b", "c"],
            "src_kind": [1.5, 2.5, 3.5],
            "geometry": ["x", "y", "z"],
            "rank": pd.array([1, None, 3], dtype="Int64"),
            "shape": [parts[0], shapely.MultiPolygon(list(parts[1:4])), parts[4]],
        },
        geometry="shape",
        crs=islands.crs,
        index=pd.Index([10, 20, 30], name="id"),
    )
    got = skeletonise.labels(frame)
    # `kind` becomes `src_src_kind`: `src_kind` is another source column's (the command line's rule).
    assert list(got.columns) == [
        "name", "src_src_kind", "src_kind", "src_geometry", "rank",
        "polygon_part", "kind", "length", "max_width", "elongation", "minzoom", "rejected", "geometry",
    ]
    assert got.geometry.name == "geometry" and got.crs == islands.crs
    assert list(got.index) == [10, 20, 20, 20, 30] and got.index.name == "id"
    assert list(got.polygon_part) == [0, 0, 1, 2, 0]
    assert list(got.src_src_kind) == ["a", "b", "b", "b", "c"]
    assert list(got.src_kind) == [1.5, 2.5, 2.5, 2.5, 3.5]
    assert list(got.src_geometry) == ["x", "y", "y", "y", "z"]
    assert got["name"].isna().tolist() == [False, False, False, False, True]
    assert str(got["rank"].dtype) == "Int64" and got["rank"].isna().tolist() == [False, True, True, True, False]
    assert {str(got[c].dtype) for c in ("length", "max_width", "elongation")} == {"Float64"}
    assert str(got.minzoom.dtype) == "Int32" and str(got.polygon_part.dtype) == "Int32"
    assert set(got.kind) <= {"line", "point"}
    # Each label lies in its own part.
    for (_, row), part in zip(got.iterrows(), parts[:5]):
        assert part.contains(row.geometry)


def test_labels_of_a_polygon_with_a_spike_are_the_command_lines(tmp_path):
    """MakeValid turns a polygon with a zero-width spike into a polygon and a line (a
    GeometryCollection): the command line's `label` step labels its polygon, and so does
    ``skeletonise.labels`` (a point for the square, a line for the long strip), row for row;
    without make_valid the feature is rejected with the reason."""
    import subprocess

    import pyogrio

    from conftest import cli_binary

    spiked = gpd.GeoDataFrame(
        {"name": ["square", "strip"]},
        geometry=shapely.from_wkt([
            "POLYGON((0 0,10 0,10 5,20 5,10 5,10 10,0 10,0 0))",
            "POLYGON((0 20,100 20,100 25,120 25,100 25,100 30,0 30,0 20))",
        ]),
        crs="EPSG:32630",
    )
    assert not shapely.is_valid(spiked.geometry.values).any()
    assert (shapely.get_type_id(shapely.make_valid(spiked.geometry.values)) == 7).all()
    src = tmp_path / "spiked.gpkg"
    pyogrio.write_dataframe(spiked, src, layer="spiked")
    pipeline = tmp_path / "labels.yaml"
    out = tmp_path / "out.gpkg"
    pipeline.write_text(
        f"input: {{ source: {src}, layer: spiked }}\nsteps:\n  - prepare: {{ make_valid: true }}\n"
        "  - skeleton: { methods: [MA] }\n  - label: {}\n  - prune: { mode: trunk }\n  - extend: {}\n"
        f"  - score: {{}}\n  - select: {{}}\noutput: {{ path: {out} }}\n"
    )
    subprocess.run([str(cli_binary()), "run", str(pipeline), "-q"], cwd=ROOT, check=True)
    cli = gpd.read_file(out, layer="labels")
    assert list(cli.kind) == ["point", "line"]
    got = skeletonise.labels(spiked)
    assert got.rejected.isna().all(), list(got.rejected)
    assert list(got.kind) == list(cli.kind)
    assert list(got.polygon_part) == list(cli.polygon_part)
    assert list(got.minzoom) == list(cli.minzoom)
    assert shapely.equals_exact(np.asarray(cli.geometry.values), np.asarray(got.geometry.values), 1e-9).all()
    for fid, row in got.iterrows():
        assert shapely.make_valid(spiked.geometry[fid]).contains(row.geometry)
    # Without make_valid the spike is the prepare step's reason, as on the command line.
    plain = skeletonise.labels(spiked, make_valid=False)
    assert plain.rejected.str.contains("make_valid").all(), list(plain.rejected)
