"""Shared fixtures: the repository's training data and the command line's output on it."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely

import skeletonise

ROOT = Path(__file__).resolve().parents[2]
TRAIN = ROOT / "tests" / "data" / "gshhg-train.gpkg"


def cli_binary() -> Path:
    """The command line built by `cargo build` (SKELETONISE_BIN, else release, else debug)."""
    if os.environ.get("SKELETONISE_BIN"):
        return Path(os.environ["SKELETONISE_BIN"])
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "skeletonise"
        if p.exists():
            return p
    pytest.skip("the skeletonise binary is not built (cargo build)")


def read_layer(layer: str):
    """A training layer with the source FIDs as index (as the command line numbers src_fid)."""
    return pyogrio.read_dataframe(TRAIN, layer=layer, fid_as_index=True)


def run_cli(pipeline: str, out: Path, *sets: str) -> Path:
    """Runs `skeletonise run` on a pipeline of the repository, writing `out`."""
    args = [str(cli_binary()), "run", str(ROOT / "pipelines" / pipeline), "-o", str(out), "-q"]
    for s in sets:
        args += ["--set", s]
    env = dict(os.environ, SKELETONISE_SRC=str(TRAIN))
    subprocess.run(args, check=True, cwd=ROOT, env=env)
    return out


def assert_same_as_cli(frame, gpkg: Path, tol: float = 1e-9) -> None:
    """Row for row: every skeleton row of the command line's output has the same
    method, counts and geometry and scores within `tol`; every rejected feature
    has the same reason; no row is lost."""
    cli = pyogrio.read_dataframe(gpkg, layer="skeletons")
    written = frame[frame["rejected"].isna() & frame["method"].notna()]
    key = ["src_fid", "polygon_part"] if "polygon_part" in cli.columns else ["src_fid"]
    cli = cli.sort_values(key).reset_index(drop=True)
    written = written.sort_values(key).reset_index(drop=True)
    assert len(written) == len(cli), (len(written), len(cli))
    for name, kind in skeletonise.columns("skeletons", explode="polygon_part" in cli.columns):
        a, b = written[name], cli[name]
        if kind == "real":
            a, b = a.to_numpy(float), b.to_numpy(float)
            both_nan = np.isnan(a) & np.isnan(b)
            worst = np.max(np.where(both_nan, 0.0, np.abs(a - b)), initial=0.0)
            assert not np.isnan(worst) and worst <= tol * max(1.0, np.nanmax(np.abs(b), initial=0.0)), (name, worst)
        elif kind == "text":
            missing = lambda v: None if pd.isna(v) else v  # pandas NA and GDAL's None alike
            assert [missing(v) for v in a] == [missing(v) for v in b], name
        else:
            assert list(a.astype("Int64").fillna(-1)) == list(pd.Series(b).astype("Int64").fillna(-1)), name
    same = shapely.equals_exact(written.geometry.values, cli.geometry.values, tolerance=0)
    assert same.all(), f"{(~same).sum()} geometries differ"
    layers = {name for name, _ in pyogrio.list_layers(gpkg)}
    rejected = frame[frame["rejected"].notna()]
    if "rejected" in layers:
        cli_rej = pyogrio.read_dataframe(gpkg, layer="rejected").sort_values("src_fid")
        assert list(rejected.sort_values("src_fid")["rejected"]) == list(cli_rej["reason"])
    else:
        assert rejected.empty


@pytest.fixture(scope="session")
def islands():
    return read_layer("islands_hebrides")


@pytest.fixture(scope="session")
def cli_islands(tmp_path_factory) -> Path:
    return run_cli("islands.yaml", tmp_path_factory.mktemp("cli") / "islands.gpkg")
