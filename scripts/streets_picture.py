#!/usr/bin/env python3
"""A picture of street space collapsed to a network: for each run given, the street space (blue), the
reference centrelines (dashed) and their junctions (green circles), the output lines (red), their
junction nodes (black) and line ends (magenta squares), side by side.

usage: streets_picture.py DATA LAYER OUT.png RUN.gpkg [RUN.gpkg...] [--window X0,Y0,X1,Y1]
  DATA holds LAYER (the street space), LAYER_lines and LAYER_junctions (scripts/make_streets.py);
  each RUN is a run's output (its `skeletons` layer).
needs: geopandas, matplotlib (PyPI)
"""

from __future__ import annotations

import sys
from collections import Counter

import geopandas as gpd
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from shapely.geometry import Point  # noqa: E402


def nodes(lines) -> tuple[list[Point], list[Point]]:
    """The junction nodes (degree ≥ 3) and line ends (degree 1) of the lines' pieces."""
    degree = Counter()
    for g in lines:
        for piece in getattr(g, "geoms", [g]):
            degree[piece.coords[0]] += 1
            degree[piece.coords[-1]] += 1
    return ([Point(p) for p, n in degree.items() if n >= 3], [Point(p) for p, n in degree.items() if n == 1])


def main(args: list[str]) -> None:
    window = None
    if "--window" in args:
        i = args.index("--window")
        window = [float(v) for v in args[i + 1].split(",")]
        args = args[:i] + args[i + 2:]
    if len(args) < 4:
        sys.exit(__doc__)
    data, layer, out, runs = args[0], args[1], args[2], args[3:]
    space = gpd.read_file(data, layer=layer)
    lines = gpd.read_file(data, layer=layer + "_lines")
    junctions = gpd.read_file(data, layer=layer + "_junctions")
    fig, axes = plt.subplots(1, len(runs), figsize=(7 * len(runs), 6.5), squeeze=False)
    for ax, run in zip(axes[0], runs):
        space.plot(ax=ax, color="#cde", edgecolor="#68a", lw=0.4)
        lines.plot(ax=ax, color="#777", lw=0.7, linestyle="--")
        junctions.plot(ax=ax, color="g", markersize=70, alpha=0.4)
        skeleton = gpd.read_file(run, layer="skeletons")
        skeleton.plot(ax=ax, color="r", lw=1.1)
        inner, ends = nodes(skeleton.geometry)
        if inner:
            gpd.GeoSeries(inner).plot(ax=ax, color="k", markersize=14)
        if ends:
            gpd.GeoSeries(ends).plot(ax=ax, color="m", markersize=14, marker="s")
        if window:
            ax.set_xlim(window[0], window[2])
            ax.set_ylim(window[1], window[3])
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_title(run.rsplit("/", 1)[-1], fontsize=10)
    fig.savefig(out, dpi=72, bbox_inches="tight")


if __name__ == "__main__":
    main(sys.argv[1:])
