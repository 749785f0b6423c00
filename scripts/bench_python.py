"""The measurements of scripts/bench-python.sh, one run each on this machine.

1. The command line (`skeletonise run`, its own elapsed time, which includes
   reading and writing the GeoPackage) against `skeletonise.apply` on the same
   layer and pipeline: the Rust compute time inside the call, and the
   conversion overhead (shapely ⇄ Rust, GeoDataFrame assembly) beside it.
2. `pygeoops.centerline` (default options) on the same GeoSeries against the
   whole `skeletonise.skeletonise` call, with its defaults (five methods,
   pruning, extension, scoring, selection) and with one method (CDT, pruned
   and extended, not scored: one centreline per polygon, as pygeoops makes).
3. The exchange formats (WKB, GeoArrow; in and back) on a generated layer of N polygons.
4. `examples/dask_islands.py` on that layer of N polygons (tiled,
   rotated and scaled copies of the training islands) with 1 and 2 workers
   (threads=1 in each: one core per worker).

The timings of 1 and 2 are the best of REPEAT runs side by side (default 3;
30 in 2 where one call takes less than 0.1 s, after one call of each to warm up;
such layers also get the best of 200 calls in a row of each tool after 50 to warm up, in three
rounds taken in turn),
those of 3 the best of 5 interleaved runs, and those of 4 the best of two runs
each in the order 1, 2, 2, 1 workers, so that a spell of other load on the
machine does not decide a ratio; the load average is printed at the start and
the end.

usage: bench_python.py SKELETONISE_BIN [N_POLYGONS [REPEAT]]
BENCH_PYTHON_SECTIONS="cli pygeoops" runs only those sections (default: all four:
cli pygeoops exchange dask; the last two go together).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyogrio

import skeletonise

ROOT = Path(__file__).resolve().parents[1]
TRAIN = ROOT / "tests/data/gshhg-train.gpkg"
CASES = [
    ("islands_hebrides", "islands.yaml"),
    ("river_st_lawrence", "rivers.yaml"),
    ("river_danube", "rivers.yaml"),
    ("river_lena", "rivers.yaml"),
]


def cli_elapsed(binary: str, layer: str, pipeline: str) -> float:
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "out.gpkg"
        subprocess.run(
            [binary, "run", str(ROOT / "pipelines" / pipeline), "-q", "-o", str(out),
             "--set", f"input.layer={layer}", "--set", "output.candidates=false"],
            check=True, cwd=ROOT, env=dict(os.environ, SKELETONISE_SRC=str(TRAIN)),
        )
        runs = pyogrio.read_dataframe(out, layer="skeletonise_runs")
        return float(runs["elapsed_s"].iloc[0])


def idle_cores(seconds: float = 5.0) -> float:
    """Cores left idle by everything on the machine over `seconds` (/proc/stat)."""
    def sample():
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        return v[3] + v[4], sum(v)  # idle + iowait, all

    (i0, t0), _ = sample(), time.sleep(seconds)
    i1, t1 = sample()
    return (os.cpu_count() or 1) * (i1 - i0) / max(1, t1 - t0)


def back_to_back(call, n: int, warm_up: int = 50) -> float:
    """The best of `n` calls made one after another, after `warm_up` calls
    (the steady state of a loop over many small GeoSeries: Python's adaptive
    interpreter and the caches settle within a few dozen calls)."""
    for _ in range(warm_up):
        call()
    best = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - t0)
    return best


def write_results(results: dict) -> None:
    out = ROOT / "target/bench/python.json"
    out.write_text(json.dumps(results, indent=1))
    print(f"\n(raw figures: {out.relative_to(ROOT)})")


def row(*cells) -> None:
    print("| " + " | ".join(str(c) for c in cells) + " |")


def main() -> None:
    binary = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 100_000
    repeat = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    print(f"load average at the start: {os.getloadavg()[0]:.1f} ({os.cpu_count()} cores, "
          f"{idle_cores():.1f} idle over 5 s); best of {repeat} runs")
    results: dict = {"cli_vs_python": [], "pygeoops": [], "dask": {}}

    only = os.environ.get("BENCH_PYTHON_SECTIONS", "cli pygeoops exchange dask").split()
    print("\n## The command line against skeletonise.apply (same pipeline, same layer)\n")
    row("layer", "features", "CLI elapsed s (incl. GPKG I/O)", "Python compute s", "ratio",
        "conversion s (to Rust + from Rust)", "parse+encode in Rust s", "Python total s")
    row(*["---"] * 8)
    for layer, pipeline in CASES if "cli" in only else []:
        gdf = pyogrio.read_dataframe(TRAIN, layer=layer, fid_as_index=True)
        clis, runs = [], []
        for _ in range(repeat):
            clis.append(cli_elapsed(binary, layer, pipeline))
            runs.append(skeletonise.apply(gdf, ROOT / "pipelines" / pipeline).attrs["skeletonise"]["timings"])
        cli = min(clis)
        t = min(runs, key=lambda r: r["compute_s"])
        conv = t["make_valid_s"] + t["to_rust_s"] + t["from_rust_s"]
        rust_io = t["parse_s"] + t["encode_s"]
        row(layer, len(gdf), f"{cli:.3f}", f"{t['compute_s']:.3f}", f"{t['compute_s'] / cli:.2f}",
            f"{conv:.4f}", f"{rust_io:.4f}", f"{t['total_s']:.3f}")
        results["cli_vs_python"].append({"layer": layer, "cli_s": cli, **t})

    print("\n## pygeoops.centerline (defaults) against skeletonise.skeletonise, same GeoSeries\n")
    print("defaults: five methods, pruned, extended, scored, best chosen; one method: CDT, pruned and")
    print("extended, not scored (one centreline per polygon, as pygeoops makes)\n")
    import pygeoops

    row("layer", "features", "pygeoops s", "skeletonise defaults s", "speed-up", "skeletonise one method s", "speed-up",
        "calls in a row: pygeoops / one method s")
    row(*["---"] * 8)
    for layer, _ in CASES if "pygeoops" in only else []:
        geoms = pyogrio.read_dataframe(TRAIN, layer=layer, fid_as_index=True).geometry
        peer = ours = one = float("inf")
        # A call on one small polygon takes a millisecond: the best of REPEAT
        # would be the best of a few scheduler hiccups, so such layers get 30.
        pygeoops.centerline(geoms)
        t0 = time.perf_counter()
        skeletonise.skeletonise(geoms)
        reps = repeat if time.perf_counter() - t0 > 0.1 else max(repeat, 30)
        for _ in range(reps):
            t0 = time.perf_counter()
            pygeoops.centerline(geoms)
            peer = min(peer, time.perf_counter() - t0)
            t0 = time.perf_counter()
            skeletonise.skeletonise(geoms)
            ours = min(ours, time.perf_counter() - t0)
            t0 = time.perf_counter()
            skeletonise.skeletonise(geoms, methods=["CDT"], score=False, select=False)
            one = min(one, time.perf_counter() - t0)
        entry = {"layer": layer, "pygeoops_s": peer, "skeletonise_s": ours, "one_method_s": one}
        warm = ""
        if reps > repeat:
            # A call of a millisecond after a call of another kind runs on cold
            # caches (on this machine about twice as slow as the next call):
            # also the best of 200 calls in a row of each after 50 to warm up,
            # as a loop over many small GeoSeries makes them, in three rounds
            # with the tools in turn (each tool's best over all), so that a
            # slow spell of the machine meets both tools.
            peer_warm = one_warm = float("inf")
            for _ in range(3):
                peer_warm = min(peer_warm, back_to_back(lambda: pygeoops.centerline(geoms), 200))
                one_warm = min(one_warm, back_to_back(
                    lambda: skeletonise.skeletonise(geoms, methods=["CDT"], score=False, select=False), 200))
            entry |= {"pygeoops_back_to_back_s": peer_warm, "one_method_back_to_back_s": one_warm}
            warm = f"{peer_warm:.4f} / {one_warm:.4f} = {peer_warm / one_warm:.1f}×"
        row(layer, len(geoms), f"{peer:.3f}", f"{ours:.3f}", f"{peer / ours:.1f}×", f"{one:.3f}", f"{peer / one:.1f}×",
            warm)
        results["pygeoops"].append(entry)

    if "exchange" not in only and "dask" not in only:
        write_results(results)
        return
    data = ROOT / "target/bench/islands-generated"
    script = [sys.executable, str(ROOT / "examples/dask_islands.py"), "--input", str(data)]
    sys.path.insert(0, str(ROOT / "examples"))
    import dask_islands

    t0 = time.perf_counter()
    dask_islands.generate(n, data)
    print(f"(generated {data.relative_to(ROOT)} in {time.perf_counter() - t0:.1f} s)\n")
    print("## Exchange formats on the generated layer (raw CDT, one thread; best of 5, interleaved)\n")
    import geopandas as gpd

    big = gpd.read_parquet(data).geometry
    combos = [("wkb", "geoarrow"), ("geoarrow", "geoarrow"), ("wkb", "wkb"), ("geoarrow", "wkb")]
    keys = ("to_rust_s", "parse_s", "encode_s", "from_rust_s")
    best = {c: dict.fromkeys(keys, float("inf")) for c in combos}
    for r in range(5):
        for ex, back in combos if r % 2 == 0 else combos[::-1]:
            t = skeletonise.skeletonise(big, methods=["CDT"], prune=False, extend=False, score=False, select=False,
                                        threads=1, exchange=ex, output=back).attrs["skeletonise"]["timings"]
            for k in keys:
                best[(ex, back)][k] = min(best[(ex, back)][k], t[k])
    row("in", "out", "to Rust s (Python side)", "parse in Rust s", "in: sum s", "encode in Rust s",
        "from Rust s (Python side)", "out: sum s")
    row(*["---"] * 8)
    for (ex, back), t in best.items():
        row(ex, back, f"{t['to_rust_s']:.3f}", f"{t['parse_s']:.3f}", f"{t['to_rust_s'] + t['parse_s']:.3f}",
            f"{t['encode_s']:.3f}", f"{t['from_rust_s']:.3f}", f"{t['encode_s'] + t['from_rust_s']:.3f}")
        results[f"exchange_{ex}_{back}"] = t
    del big
    print(f"\n## Dask: examples/dask_islands.py on {n} generated polygons (16 GeoParquet files), pipelines/islands.yaml,")
    print("every worker reading its files and writing its partitions to GeoParquet\n")
    row("workers", "partitions", "elapsed s (each run)", "best s", "idle cores before each run", "rows", "rejected")
    row(*["---"] * 7)
    runs: dict[int, list] = {1: [], 2: []}
    idle: dict[int, list] = {1: [], 2: []}
    for workers in (1, 2, 2, 1):  # interleaved: a spell of other load hits both
        idle[workers].append(idle_cores())
        p = subprocess.run(script + ["--workers", str(workers), "--output", str(ROOT / "target/bench/skeletons")],
                           check=True, capture_output=True, text=True, cwd=ROOT)
        runs[workers].append(json.loads(p.stdout.strip().splitlines()[-1]))
    for workers, rs in runs.items():
        best = min(rs, key=lambda r: r["elapsed_s"])
        row(workers, best["partitions"], ", ".join(f"{r['elapsed_s']:.1f}" for r in rs), f"{best['elapsed_s']:.1f}",
            ", ".join(f"{c:.1f}" for c in idle[workers]), best["rows"], best["rejected"])
        results["dask"][workers] = {**best, "runs_s": [r["elapsed_s"] for r in rs]}
    one, two = results["dask"][1]["elapsed_s"], results["dask"][2]["elapsed_s"]
    print(f"\n2 workers against 1: {one / two:.2f}× faster")
    print(f"\nload average at the end: {os.getloadavg()[0]:.1f}")
    write_results(results)


if __name__ == "__main__":
    main()
