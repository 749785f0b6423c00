"""Skeletonise a polygon layer on a Dask cluster with Dask-GeoPandas.

    python examples/dask_islands.py                          # the training islands, 2 local workers
    python examples/dask_islands.py --generate 100000        # 100 000 tiled, jittered copies of them
    python examples/dask_islands.py --scheduler tcp://host:8786 --input polygons.parquet

Every partition goes through `skeletonise.apply` with the steps of a pipeline
file (`input` and `output` of the file are not used: Dask reads and writes).
Each worker thread runs one partition on one core (`threads=1`), so a cluster
of N single-threaded workers uses N cores; without `--output` the result is
gathered and summarised, with it every worker writes its partitions to a
GeoParquet folder. Prints one JSON line with the timings.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def generate(n: int, path: Path, files: int = 16, seed: int = 1) -> Path:
    """`n` polygons: copies of the training islands on a grid of tiles, each copy
    rotated, scaled and shifted at random (affine, so every copy stays valid),
    written as a GeoParquet folder of `files` files (one Dask partition each)."""
    import geopandas as gpd
    import pandas as pd
    import pyogrio
    import shapely

    src = pyogrio.read_dataframe(ROOT / "tests/data/gshhg-train.gpkg", layer="islands_hebrides")
    base = src.geometry.values
    xmin, ymin, xmax, ymax = shapely.total_bounds(base)
    step = 1.2 * max(xmax - xmin, ymax - ymin)
    rng = np.random.default_rng(seed)
    tiles = -(-n // len(base))
    side = int(np.ceil(np.sqrt(tiles)))
    parts = []
    for t in range(tiles):
        angle, scale = rng.uniform(-np.pi, np.pi), rng.uniform(0.8, 1.25)
        c, s = scale * np.cos(angle), scale * np.sin(angle)
        cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
        dx, dy = (t % side) * step, (t // side) * step
        m = np.array([[c, -s], [s, c]])

        def move(xy, m=m, cx=cx, cy=cy, dx=dx, dy=dy):
            return (xy - (cx, cy)) @ m.T + (cx + dx, cy + dy)

        parts.append(shapely.transform(base, move))
    geoms = np.concatenate(parts)[:n]
    tile = np.repeat(np.arange(tiles), len(base))[:n]
    gdf = gpd.GeoDataFrame({"tile": tile, "island": np.tile(np.arange(len(base)), tiles)[:n]},
                           geometry=geoms, crs=src.crs, index=pd.RangeIndex(1, n + 1, name="fid"))
    import shutil

    shutil.rmtree(path, ignore_errors=True)
    path.mkdir(parents=True)
    bounds = np.linspace(0, n, files + 1).astype(int)
    for i, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
        gdf.iloc[a:b].to_parquet(path / f"part.{i:03d}.parquet", index=True)
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--input", type=Path, help="a GeoParquet file or folder (default: the training islands)")
    ap.add_argument("--generate", type=int, metavar="N",
                    help="write N tiled copies of the islands to the folder --input first (16 files)")
    ap.add_argument("--pipeline", type=Path, default=ROOT / "pipelines/islands.yaml")
    ap.add_argument("--workers", type=int, default=2, help="local worker processes (without --scheduler)")
    ap.add_argument("--scheduler", help="address of a running scheduler instead of a local cluster")
    ap.add_argument("--partitions", type=int, default=0,
                    help="default: one per file of --input, 4 per worker for the training islands")
    ap.add_argument("--output", type=Path, help="a GeoParquet folder the workers write")
    args = ap.parse_args()

    import dask_geopandas
    import distributed
    import pyogrio

    import skeletonise

    if args.generate:
        args.input = args.input or ROOT / "target/bench/islands-generated"
        generate(args.generate, args.input)

    if args.scheduler:
        client = distributed.Client(args.scheduler)
    else:
        cluster = distributed.LocalCluster(n_workers=args.workers, processes=True, threads_per_worker=1,
                                           host="127.0.0.1", dashboard_address=None)
        client = distributed.Client(cluster)
    workers = len(client.scheduler_info()["workers"])
    if args.input:
        # Every worker reads its own files: no partition passes through one process.
        ddf = dask_geopandas.read_parquet(args.input)
        if args.partitions and args.partitions != ddf.npartitions:
            ddf = ddf.repartition(npartitions=args.partitions)
    else:
        gdf = pyogrio.read_dataframe(ROOT / "tests/data/gshhg-train.gpkg", layer="islands_hebrides", fid_as_index=True)
        ddf = dask_geopandas.from_geopandas(gdf, npartitions=args.partitions or 4 * workers)
    nparts = ddf.npartitions

    pipeline = str(args.pipeline.resolve())
    # The result's columns and types, from an empty partition (no work).
    meta = skeletonise.apply(ddf._meta, pipeline)
    skeletons = ddf.map_partitions(skeletonise.apply, pipeline, threads=1, meta=meta)

    start = time.perf_counter()
    if args.output:
        skeletons.to_parquet(args.output, overwrite=True)
        elapsed = time.perf_counter() - start
        out = dask_geopandas.read_parquet(args.output)[["method", "rejected"]].compute()
    else:
        out = skeletons.compute()
        elapsed = time.perf_counter() - start
    summary = {
        "rows": len(out),
        "rejected": int(out["rejected"].notna().sum()),
        "methods": out["method"].value_counts().to_dict(),
    }
    print(json.dumps({"workers": workers, "partitions": nparts, "elapsed_s": round(elapsed, 3), **summary}))
    client.close()


if __name__ == "__main__":
    main()
