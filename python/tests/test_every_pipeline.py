"""Every pipeline file of the repository through the command line and through
``skeletonise.apply_layers`` on the same data: every layer the Python call returns has the command
line's rows (every column, geometries exactly) — the one run driver, the same plan, the same
names — and it returns every layer the command line writes but those left out by name below, each
with the reason."""

from __future__ import annotations

import os
import re
import subprocess

import pyogrio
import pytest
import yaml

import skeletonise
from conftest import ROOT, cli_binary
from test_layers import same_rows

PIPELINES = sorted(p.name for p in (ROOT / "pipelines").glob("*.yaml"))
# Written by the command line only: the reasons of rejected features are the skeleton frame's
# `rejected` column in Python; bars, widths and the run record belong to the GeoPackage and the
# report.
CLI_ONLY = {"rejected", "bars", "widths", "skeletonise_runs"}


def _value(text: str) -> str:
    """``${VAR:-default}`` resolved as the command line resolves it (the variable, else the default)."""
    return re.sub(r"\$\{(\w+):-([^}]*)\}", lambda m: os.environ.get(m.group(1), m.group(2)), text)


def _frame(spec: dict):
    return pyogrio.read_dataframe(
        ROOT / _value(spec["source"]), layer=spec.get("layer"), fid_as_index=True, where=spec.get("where")
    )


@pytest.mark.parametrize("name", PIPELINES)
def test_every_pipeline_gives_the_command_lines_rows(name, tmp_path):
    path = ROOT / "pipelines" / name
    spec = yaml.safe_load(path.read_text())
    out = tmp_path / "cli.gpkg"
    subprocess.run(
        [str(cli_binary()), "run", str(path), "-o", str(out), "-q"],
        check=True, cwd=ROOT,
    )
    inp = spec["input"]
    kwargs = {"candidates": bool(spec.get("output", {}).get("candidates"))}
    if "connect" in inp:
        kwargs.update(connect=_frame(inp["connect"]), snap=float(inp["connect"].get("snap", 0.0)))
    if "neighbours" in inp:
        kwargs.update(neighbours=_frame(inp["neighbours"]))
    # A registered step's side input (an option naming a layer): given as a frame, as the Python
    # package opens no file.
    sides = {
        name: _frame(value)
        for step in spec["steps"]
        for name, options in step.items()
        for value in (options or {}).values()
        if isinstance(value, dict) and "source" in value
    }
    if sides:
        kwargs["sides"] = sides
    layers = skeletonise.apply_layers(_frame(inp), path, **kwargs)
    written = {name for name, _ in pyogrio.list_layers(out)}
    layer = spec.get("output", {}).get("layer", "skeletons")
    assert set(layers) - {"skeletons"} <= written, (set(layers), written)
    assert {"skeletons"} | (written - CLI_ONLY - {layer}) <= set(layers), (set(layers), written)
    for lname, frame in layers.items():
        cli_name = layer if lname == "skeletons" else lname
        got = frame.drop(columns=["rejected"], errors="ignore")
        if lname == "skeletons":
            got = got[frame["rejected"].isna() & frame["method"].notna()]
        want = pyogrio.read_dataframe(out, layer=cli_name)
        assert [c for c in got.columns if c in want.columns] == [c for c in want.columns], (lname, list(got.columns), list(want.columns))
        same_rows(got, out, cli_name)


def test_a_side_input_the_pipeline_names_must_be_given():
    """The Python package opens no file: a registered step's side input the pipeline file names
    must be passed as a frame, and a frame for a step that reads none is refused."""
    path = ROOT / "pipelines" / "streets.yaml"
    quarter = pyogrio.read_dataframe(ROOT / "tests/data/streets.gpkg", layer="quarter", fid_as_index=True)
    with pytest.raises(skeletonise.PipelineError, match=r"steps\.streets\.units.*sides="):
        skeletonise.apply_layers(quarter, path)
    blocks = pyogrio.read_dataframe(ROOT / "tests/data/streets.gpkg", layer="quarter_blocks", fid_as_index=True)
    with pytest.raises(ValueError, match="no registered step `label`"):
        skeletonise.apply_layers(quarter, path, sides={"streets": blocks, "label": blocks})
    layers = skeletonise.apply_layers(quarter, path, sides={"streets": blocks})
    streets = layers["streets"]
    assert streets.left_fid.notna().all() and streets.right_fid.notna().all()


def test_every_registered_step_has_a_pipeline_file_above():
    """Every step the registry has (``partition``, ``label``, ``streets``, …) is in a pipeline file
    of the repository, so that the test above compares its rows through the command line and
    Python: a new step cannot be added without that check."""
    steps = {step for step, *_ in skeletonise._core.step_layers()}
    used = {
        name
        for p in PIPELINES
        for step in yaml.safe_load((ROOT / "pipelines" / p).read_text())["steps"]
        for name in step
    }
    assert steps and steps <= used, steps - used
