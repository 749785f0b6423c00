"""The package gives the command line's output row for row on the training data."""

from __future__ import annotations

import skeletonise
from conftest import ROOT, assert_same_as_cli, read_layer, run_cli


def test_islands_pipeline_equals_the_command_line(islands, cli_islands):
    out = skeletonise.apply(islands, ROOT / "pipelines" / "islands.yaml")
    assert len(out) == len(islands)
    assert out.index.equals(islands.index)
    assert_same_as_cli(out, cli_islands)


def test_rivers_pipeline_equals_the_command_line(tmp_path):
    for layer in ("river_danube", "river_lena", "lakes_scotland"):
        gpkg = run_cli("rivers.yaml", tmp_path / f"{layer}.gpkg", f"input.layer={layer}")
        out = skeletonise.apply(read_layer(layer), ROOT / "pipelines" / "rivers.yaml")
        assert_same_as_cli(out, gpkg)


def test_keyword_options_equal_the_pipeline_file(islands, cli_islands):
    # pipelines/islands.yaml as keywords: the pipeline file's defaults are the keywords' defaults.
    out = skeletonise.skeletonise(islands.geometry, prune={"mode": "significance", "ratio": 1.0}, select={"min_coverage": 0.9})
    assert_same_as_cli(out, cli_islands)


def test_explode_equals_the_command_line(tmp_path):
    gpkg = run_cli("islands.yaml", tmp_path / "x.gpkg", "output.explode=true", "steps.skeleton.methods=[MA, CDT]")
    out = skeletonise.apply(read_layer("islands_hebrides"), ROOT / "pipelines" / "islands.yaml",
                            overrides=["output.explode=true", "steps.skeleton.methods=[MA, CDT]"])
    assert_same_as_cli(out, gpkg)
