"""`skeletonise.apply_layers`: a pipeline with the collapse or partition step on GeoDataFrames,
every layer of the output, row for row the command line's GeoPackage."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely

import skeletonise
from conftest import ROOT, TRAIN, run_cli

COVERAGE = ROOT / "tests" / "data" / "coverage-train.gpkg"


def same_rows(got, gpkg, layer, tol=1e-9, skip=()):
    """Every column (but ``skip``) and geometry of the command line's layer, in its order within a
    src_fid."""
    want = pyogrio.read_dataframe(gpkg, layer=layer).drop(columns=list(skip))
    assert len(got) == len(want), (layer, len(got), len(want))
    geometry = want.geometry.name if hasattr(want, "geometry") else None
    key = "src_fid" if "src_fid" in want.columns else want.columns[0]
    got = got.sort_values(key, kind="stable").reset_index(drop=True)
    want = want.sort_values(key, kind="stable").reset_index(drop=True)
    for c in want.columns:
        if c == geometry:
            continue
        assert c in got.columns, (layer, c, list(got.columns))
        a, b = got[c], want[c]
        if pd.api.types.is_float_dtype(b):
            a, b = a.to_numpy(float), b.to_numpy(float)
            assert np.allclose(a, b, rtol=tol, atol=tol, equal_nan=True), (layer, c)
        else:
            norm = lambda v: None if pd.isna(v) else (int(v) if isinstance(v, (int, np.integer)) else v)  # noqa: E731
            assert [norm(v) for v in a] == [norm(v) for v in b], (layer, c)
    if geometry is not None:
        assert shapely.equals_exact(got.geometry.values, want.geometry.values, tolerance=0).all(), layer


def test_collapse_gives_the_command_lines_lines_and_kept_areas(tmp_path):
    out = run_cli("collapse-rivers.yaml", tmp_path / "c.gpkg")
    lena = pyogrio.read_dataframe(TRAIN, layer="river_lena", fid_as_index=True)
    layers = skeletonise.apply_layers(lena, ROOT / "pipelines" / "collapse-rivers.yaml")
    assert set(layers) == {"skeletons", "areas"}
    skel = layers["skeletons"]
    assert skel["collapsed"].notna().all()
    same_rows(skel.drop(columns=["rejected"]), out, "skeletons")
    # The source's `kind` keeps its name: no layer of a collapse has a column of that name (the
    # partition's `areas` has, and there it is written `src_kind`).
    assert len(layers["areas"]) > 3 and set(layers["areas"]["kind"]) <= set(lena["kind"])
    same_rows(layers["areas"], out, "areas")


def test_partition_gives_the_command_lines_coverage_and_boundaries(tmp_path):
    import os
    import subprocess

    from conftest import cli_binary

    out = tmp_path / "p.gpkg"
    subprocess.run(
        [str(cli_binary()), "run", str(ROOT / "pipelines" / "partition-rivers.yaml"), "-o", str(out), "-q"],
        check=True, cwd=ROOT, env=dict(os.environ, SKELETONISE_SRC=str(COVERAGE)),
    )
    rivers = pyogrio.read_dataframe(COVERAGE, layer="rivers_danube", fid_as_index=True)
    units = pyogrio.read_dataframe(COVERAGE, layer="units_danube", fid_as_index=True)
    layers = skeletonise.apply_layers(rivers, ROOT / "pipelines" / "partition-rivers.yaml", neighbours=units)
    assert {"skeletons", "areas", "coverage", "boundaries", "given"} <= set(layers)
    # The four reaches merged into one river, as the command line's reader merges them.
    assert len(layers["skeletons"]) == 1
    same_rows(layers["skeletons"].drop(columns=["rejected"]), out, "skeletons")
    cov = layers["coverage"]
    assert "landuse" in cov and cov["received"].gt(0).sum() > 5
    same_rows(cov, out, "coverage")
    same_rows(layers["boundaries"], out, "boundaries")
    assert shapely.coverage_is_valid(cov.geometry.values)
    total = units.area.sum() + rivers.area.sum()
    assert abs(cov.area.sum() + layers["areas"].area.sum() - total) <= 1e-9 * total


def test_units_that_cover_a_lake_give_the_command_lines_rows_and_take_the_snap(tmp_path):
    # Real countries covering a real lake (tests/data/border-waters.gpkg): the overlap is cut as
    # on the command line, with the same options; `neighbour_snap` is input.neighbours.snap.
    import os
    import subprocess

    from conftest import cli_binary

    border = ROOT / "tests" / "data" / "border-waters.gpkg"
    pipeline = ROOT / "pipelines" / "partition-border-waters.yaml"
    out = tmp_path / "p.gpkg"
    subprocess.run(
        [str(cli_binary()), "run", str(pipeline), "-o", str(out), "-q", "--set", "input.layer=waters_titicaca",
         "--set", "input.neighbours.layer=units_titicaca"],
        check=True, cwd=ROOT, env=dict(os.environ, SKELETONISE_SRC=str(border)),
    )
    waters = pyogrio.read_dataframe(border, layer="waters_titicaca", fid_as_index=True)
    units = pyogrio.read_dataframe(border, layer="units_titicaca", fid_as_index=True)
    layers = skeletonise.apply_layers(waters, pipeline, neighbours=units)
    cov = layers["coverage"]
    assert cov["held"].gt(0).all()
    same_rows(cov, out, "coverage")
    given = pyogrio.read_dataframe(out, layer="given", read_geometry=False).sort_values(["src_fid", "unit_fid"])
    got = layers["given"].sort_values(["src_fid", "unit_fid"])
    assert list(got.unit_fid) == list(given.unit_fid)
    assert np.allclose(got["area"], given["area"], rtol=1e-12) and np.allclose(got["held"], given["held"], rtol=1e-12)
    assert shapely.coverage_is_valid(cov.geometry.values)
    # `overlap: reject` refuses the lakes the countries cover, as the command line does.
    rejected = skeletonise.apply_layers(waters, pipeline, neighbours=units, overrides=["steps.partition.overlap=reject"])
    assert rejected["skeletons"]["rejected"].str.contains("overlaps unit").sum() >= 1
    # The same units from another source in longitude/latitude (reprojected by GeoPandas): the
    # same areas to 1e-6, with the default snap and with one given.
    lonlat = pyogrio.read_dataframe(border, layer="units_titicaca_4326", fid_as_index=True)
    for snap in (None, 0.01):
        other = skeletonise.apply_layers(waters, pipeline, neighbours=lonlat, neighbour_snap=snap)["coverage"]
        assert shapely.coverage_is_valid(other.geometry.values)
        assert np.allclose(other.area.values, cov.area.values, rtol=1e-6)
    with pytest.raises(skeletonise.PipelineError, match="neighbour_snap"):
        skeletonise.apply_layers(waters, pipeline, neighbours=units, neighbour_snap=-1.0)


def test_a_partition_without_neighbours_says_what_to_give():
    rivers = pyogrio.read_dataframe(COVERAGE, layer="rivers_danube", fid_as_index=True)
    with pytest.raises(skeletonise.PipelineError, match="neighbours"):
        skeletonise.apply_layers(rivers, ROOT / "pipelines" / "partition-rivers.yaml")


def test_bad_second_inputs_are_clear_errors():
    rivers = pyogrio.read_dataframe(COVERAGE, layer="rivers_danube", fid_as_index=True)
    units = pyogrio.read_dataframe(COVERAGE, layer="units_danube", fid_as_index=True)
    lines = units.copy()
    lines.geometry = units.boundary
    with pytest.raises(skeletonise.PipelineError, match="not a polygon"):
        skeletonise.apply_layers(rivers, ROOT / "pipelines" / "partition-rivers.yaml", neighbours=lines)
    with pytest.raises(skeletonise.PipelineError, match="no features"):
        skeletonise.apply_layers(rivers, ROOT / "pipelines" / "partition-rivers.yaml", neighbours=units.iloc[:0])
    with pytest.raises(skeletonise.PipelineError, match="no lines"):
        skeletonise.apply_layers(rivers, ROOT / "pipelines" / "collapse-rivers.yaml", connect=rivers.centroid)


def cli_refusal(*args: str) -> str:
    """The message of a command line that refuses its pipeline file (exit status 78)."""
    import subprocess

    from conftest import cli_binary

    p = subprocess.run([str(cli_binary()), *args], cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 78, p.stderr
    return p.stderr.strip().splitlines()[-1].split(" ERROR ", 1)[1]


def lakes_pipeline(tmp_path, prune: str) -> str:
    """A pipeline file on the training lakes with the prune step ``prune`` (no ``input.connect``)."""
    path = tmp_path / "p.yaml"
    path.write_text(
        f"input:\n  source: {TRAIN}\n  layer: lakes_scotland\nsteps:\n  - skeleton: {{ methods: [MA] }}\n"
        f"  - prune: {prune}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\n"
        f"output:\n  path: {tmp_path / 'o.gpkg'}\n"
    )
    return str(path)


def test_network_pruning_without_lines_is_refused_with_the_command_lines_message(tmp_path):
    """`prune: {mode: network}` without the lines of `input.connect`: the command line refuses
    the file (exit 78); apply_layers, apply and the keyword API refuse the run with its
    message (PipelineError), rather than prune every lake with the fallback."""
    lakes = pyogrio.read_dataframe(TRAIN, layer="lakes_scotland", fid_as_index=True)
    path = lakes_pipeline(tmp_path, "{ mode: network }")
    want = cli_refusal("validate", path)
    assert "`steps[1].prune.mode`" in want and "input.connect" in want
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.apply_layers(lakes, path)
    assert str(e.value) == want
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.apply(lakes, path)
    assert str(e.value) == want
    # An empty frame is refused all the same: the file is wrong, not the data.
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.apply_layers(lakes.iloc[:0], path)
    assert str(e.value) == want
    # Set by an override: the override is named, as on the command line.
    plain = lakes_pipeline(tmp_path, "{}")
    want = cli_refusal("validate", plain, "--set", "steps.prune.mode=network")
    assert want.startswith("--set steps.prune.mode=network: ")
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.apply_layers(lakes, plain, overrides=["steps.prune.mode=network"])
    assert str(e.value) == want
    # The keyword API names its keyword.
    with pytest.raises(skeletonise.PipelineError, match=r"`prune\.mode`: `mode: network` keeps .*input\.connect"):
        skeletonise.skeletonise(lakes.geometry, methods=["MA"], prune={"mode": "network"})
    # With the lines it runs.
    network = pyogrio.read_dataframe(ROOT / "tests" / "data" / "network-train.gpkg", layer="lines_lakes_scotland")
    out = skeletonise.apply_layers(lakes, path, connect=network, snap=1.0)
    assert out["skeletons"]["method"].notna().sum() > 0


def test_a_prune_fallback_outside_network_mode_is_refused_as_on_the_command_line(tmp_path):
    """`prune.fallback` only means something with `mode: network`: elsewhere the command line's
    validation refuses it, and so do load_pipeline and the keyword API, with its message."""
    path = lakes_pipeline(tmp_path, "{ mode: significance, fallback: trunk }")
    want = cli_refusal("validate", path)
    assert "`steps[1].prune.fallback`" in want and "only with `mode: network`" in want
    with pytest.raises(skeletonise.PipelineError) as e:
        skeletonise.load_pipeline(path)
    assert str(e.value) == want
    lakes = pyogrio.read_dataframe(TRAIN, layer="lakes_scotland", fid_as_index=True)
    with pytest.raises(skeletonise.PipelineError, match=r"`prune\.fallback`: .*only with `mode: network`"):
        skeletonise.skeletonise(lakes.geometry, prune={"mode": "trunk", "fallback": "drop"})
    # With `mode: network` it is taken.
    skeletonise.load_pipeline(lakes_pipeline(tmp_path, "{ mode: network, fallback: trunk }"))


def test_columns_named_as_the_tools_are_renamed_as_on_the_command_line(tmp_path):
    # A previous run's output as input (`src_fid` beside `src_src_fid`, `kind` beside `src_kind`)
    # and units with `received`/`src_received`: `src_` is repeated until the name is free, in every
    # layer as the command line's writer names the fields (each was renamed once before, and
    # `kind`'s new name clashed with the existing `src_kind`).
    import os
    import subprocess

    from conftest import cli_binary

    rivers = pyogrio.read_dataframe(COVERAGE, layer="rivers_danube", fid_as_index=True)
    units = pyogrio.read_dataframe(COVERAGE, layer="units_danube", fid_as_index=True)
    for c in ("src_fid", "src_src_fid", "kind", "src_kind", "method"):
        rivers[c] = c
    for c in ("received", "src_received", "held"):
        units[c] = c
    src = tmp_path / "in.gpkg"
    pyogrio.write_dataframe(rivers, src, layer="rivers_danube")
    pyogrio.write_dataframe(units, src, layer="units_danube")
    out = tmp_path / "p.gpkg"
    subprocess.run(
        [str(cli_binary()), "run", str(ROOT / "pipelines" / "partition-rivers.yaml"), "-o", str(out), "-q"],
        check=True, cwd=ROOT, env=dict(os.environ, SKELETONISE_SRC=str(src)),
    )
    layers = skeletonise.apply_layers(rivers, ROOT / "pipelines" / "partition-rivers.yaml", neighbours=units)
    for name in ("skeletons", "areas", "coverage"):
        want = pyogrio.read_dataframe(out, layer=name)
        got = layers[name].drop(columns=["rejected"], errors="ignore")
        assert list(got.columns) == list(want.columns), name
        same_rows(got, out, name)
    skel = layers["skeletons"]
    assert list(skel["src_src_src_fid"]) == ["src_fid"] and list(skel["src_src_kind"]) == ["kind"]
    assert list(skel["src_kind"]) == ["src_kind"] and list(skel["src_method"]) == ["method"]
    assert {"src_src_received", "src_received"} <= set(layers["coverage"].columns)
