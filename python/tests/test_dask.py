"""`skeletonise.apply` on a Dask cluster of two worker processes (loopback) gives the
command line's output on the training islands, row for row."""

from __future__ import annotations

import pytest

import skeletonise
from conftest import ROOT, assert_same_as_cli

dask_geopandas = pytest.importorskip("dask_geopandas")
distributed = pytest.importorskip("distributed")


def test_two_worker_processes_give_the_command_line_output(islands, cli_islands):
    pipeline = str(ROOT / "pipelines" / "islands.yaml")
    with distributed.LocalCluster(
        n_workers=2,
        processes=True,
        threads_per_worker=1,
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        ddf = dask_geopandas.from_geopandas(islands, npartitions=6)
        meta = skeletonise.apply(islands.iloc[:0], pipeline)
        with distributed.get_task_stream(client) as tasks:
            out = ddf.map_partitions(skeletonise.apply, pipeline, threads=1, meta=meta).compute()
        # Both workers did some of the work.
        assert len({t["worker"] for t in tasks.data}) == 2
    assert len(out) == len(islands)
    out = out.loc[islands.index]
    assert_same_as_cli(out, cli_islands)
