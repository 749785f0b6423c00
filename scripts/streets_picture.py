"""Draws street space with its reference centrelines (dashed blue), the skeleton lines (red) and
their junction nodes (black), whole and zoomed on junctions, for two runs side by side: the
README's picture of `prune: {junctions: merge}`.

usage: streets_picture.py OUT.png STREETS.gpkg LAYER KEEP.gpkg MERGE.gpkg [ZOOM_HALF_WIDTH JUNCTION...]
  JUNCTION = index into LAYER_junctions (one row of zoomed panels each)
needs: geopandas, shapely, matplotlib (PyPI)
"""

import sys
from collections import Counter

import geopandas as gpd
import matplotlib
import shapely

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

if len(sys.argv) < 6:
    sys.exit(__doc__)
out, data, layer, keep, merge = sys.argv[1:6]
half = float(sys.argv[6]) if len(sys.argv) > 6 else None
picked = [int(i) for i in sys.argv[7:]]

space = gpd.read_file(data, layer=layer)
ref = gpd.read_file(data, layer=layer + "_lines")
junctions = gpd.read_file(data, layer=layer + "_junctions")


def nodes(frame):
    """Junctions (degree ≥ 3) of a skeleton layer's lines."""
    lines = [g for geom in frame.geometry.values for g in getattr(geom, "geoms", [geom])]
    degree = Counter()
    for part in lines:
        cs = list(part.coords)
        degree[cs[0]] += 1
        degree[cs[-1]] += 1
    return [p for p, d in degree.items() if d >= 3]


runs = [(gpd.read_file(keep, layer="skeletons"), "junctions: keep (default)"),
        (gpd.read_file(merge, layer="skeletons"), "junctions: merge")]
windows = [None] + [
    (p.x - half, p.y - half, p.x + half, p.y + half) for p in junctions.geometry.values[picked]
]
fig, axes = plt.subplots(len(windows), 2, figsize=(11, 5.2 * len(windows)), squeeze=False)
for row, window in enumerate(windows):
    for col, (sk, title) in enumerate(runs):
        ax = axes[row][col]
        space.plot(ax=ax, facecolor="#dde", edgecolor="#445", linewidth=0.6)
        ref.plot(ax=ax, color="#2255cc", linewidth=0.9, linestyle="--")
        sk.plot(ax=ax, color="#d11", linewidth=1.3)
        xs = nodes(sk)
        ax.scatter([p[0] for p in xs], [p[1] for p in xs], color="black", s=14 if window is None else 30, zorder=5)
        jx = junctions.geometry.values
        ax.scatter(shapely.get_x(jx), shapely.get_y(jx), facecolor="none", edgecolor="#2255cc",
                   s=40 if window is None else 120, zorder=4)
        if window is not None:
            ax.set_xlim(window[0], window[2])
            ax.set_ylim(window[1], window[3])
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"{title}: {len(xs)} junction nodes" if window is None else title, fontsize=10)
fig.tight_layout()
fig.savefig(out, dpi=90)
print(out)
