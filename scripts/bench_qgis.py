"""Times the QGIS provider against the Python package on the same layer (scripts/bench-qgis.sh).

    python bench_qgis.py qgis   SRC LAYER RUNS   (QGIS's Python: processing.run, a memory layer in and out)
    python bench_qgis.py python SRC LAYER RUNS   (the package's venv: skeletonise.skeletonise on the GeoSeries)
    python bench_qgis.py summary < LINES         (the medians and their ratio)

Prints one JSON line: the layer, the features, and the wall time of every run (seconds). Both
sides start from the layer in memory (QGIS: a memory layer copied from the file; Python: a
GeoDataFrame read with pyogrio) and end with the skeletons in memory (a QGIS memory layer with
the source's fields; a GeoDataFrame): the conversion both ways is included, file I/O is not.
"""

import json
import os
import sys
import time


def qgis_runs(src, layer, runs):
    from qgis.core import QgsFeatureRequest, QgsVectorLayer

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "qgis"))
    from skeletonise_qgis.standalone import start

    app, provider = start()  # both kept: the registry does not own a Python provider
    import processing

    disk = QgsVectorLayer(f"{src}|layername={layer}", layer, "ogr")
    mem = disk.materialize(QgsFeatureRequest())
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        out = processing.run("skeletonise:skeletonise", {"INPUT": mem, "OUTPUT": "memory:"})["OUTPUT"]
        times.append(time.perf_counter() - t0)
    del provider, app
    return mem.featureCount(), out.featureCount(), times


def python_runs(src, layer, runs):
    import geopandas as gpd
    import skeletonise

    gdf = gpd.read_file(src, layer=layer, fid_as_index=True, engine="pyogrio")
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        out = skeletonise.skeletonise(gdf.geometry)
        times.append(time.perf_counter() - t0)
    return len(gdf), len(out), times


def summary(lines):
    """The medians of both sides and their ratio, from the JSON lines of the runs."""
    import statistics

    rows = [json.loads(line) for line in lines if line.strip()]
    med = {s: statistics.median(t for r in rows if r["side"] == s for t in r["times"]) for s in ("qgis", "python")}
    r = rows[0]
    return (
        f"{r['layer']}: {r['features']} features, QGIS {med['qgis']:.3f} s, Python {med['python']:.3f} s, "
        f"ratio {med['qgis'] / med['python']:.2f} (median of {len(rows) // 2} runs each)"
    )


if __name__ == "__main__":
    if sys.argv[1] == "summary":
        print(summary(sys.stdin))
        sys.exit(0)
    side, src, layer, runs = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    n, rows, times = (qgis_runs if side == "qgis" else python_runs)(src, layer, runs)
    print(json.dumps({"side": side, "layer": layer, "features": n, "rows": rows, "times": times}))
