"""The peer side of scripts/bench-dvd.sh: pygeoops.centerline on one layer.

    python bench_dvd_peer.py SOURCE LAYER spacing   # prints the shared spacing d
    python bench_dvd_peer.py SOURCE LAYER run D     # runs pygeoops with densify_distance=D

The shared spacing d is the layer's mean boundary edge length / 4 (total
perimeter over 4 x total vertices), i.e. the density of the paper's factor 4
spread evenly. Both sides then densify with the same d: our DVD with
`densify: {spacing: d}` and pygeoops with `densify_distance=d`; both cut every
edge into ceil(len / d) equal pieces (GEOS segmentize), so both Voronoi
diagrams get the same points, and the script prints the counts to show it.

pygeoops runs with min_branch_length=0 and simplifytolerance=0 so that it does
what DVD does (densify, Voronoi, keep the edges inside the polygon) plus its
line merge, without its pruning and simplification steps.
"""

import sys
import time

import pyogrio
import pygeoops
import shapely


def polygon_parts(source, layer):
    df = pyogrio.read_dataframe(source, layer=layer)
    return [g for g in shapely.get_parts(df.geometry.values) if not g.is_empty]


def distinct_vertices(g):
    # Every ring repeats its first point at the end.
    return shapely.get_num_coordinates(g) - len(shapely.get_rings(g))


def main():
    source, layer, what = sys.argv[1:4]
    parts = polygon_parts(source, layer)
    if what == "spacing":
        perimeter = sum(g.length for g in parts)
        vertices = sum(distinct_vertices(g) for g in parts)
        print(f"{perimeter / (4 * vertices):.6f}")
        return
    d = float(sys.argv[4])
    start = time.perf_counter()
    failed = 0
    lines = 0
    for g in parts:
        try:
            c = pygeoops.centerline(
                g, densify_distance=d, min_branch_length=0, simplifytolerance=0
            )
            lines += 0 if c is None else shapely.get_num_geometries(c)
        except Exception:  # report, as our side does, instead of stopping
            failed += 1
    secs = time.perf_counter() - start
    points = sum(distinct_vertices(shapely.segmentize(g, d)) for g in parts)
    print(
        f"{layer}\tpygeoops spacing:{d}\tparts={len(parts)}\tfailed={failed}"
        f"\tpoints={points}\tlines={lines}\tseconds={secs:.4f}"
    )


if __name__ == "__main__":
    main()
