"""Draws polygons with their label lines and points (layer `labels` of a run), optionally beside
another tool's lines (dashed), one panel per polygon: the README's picture of label lines.

usage: labels_picture.py OUT.png POLYS.gpkg@LAYER LABELS.gpkg [OTHER.gpkg@LAYER] -- FID...
needs: geopandas, pyogrio, matplotlib (PyPI)
"""

import sys

import geopandas as gpd
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

if "--" not in sys.argv or len(sys.argv) < 5:
    sys.exit(__doc__)
k = sys.argv.index("--")
args, fids = sys.argv[1:k], [int(f) for f in sys.argv[k + 1:]]
out, polys, labels = args[0], args[1], args[2]
other = args[3] if len(args) > 3 else None


def layer_of(spec):
    path, _, layer = spec.partition("@")
    return gpd.read_file(path, layer=layer or None, fid_as_index=True)


P = layer_of(polys)
L = gpd.read_file(labels, layer="labels")
O = layer_of(other) if other else None
if O is not None and "src_fid" in O.columns:
    O = O.set_index("src_fid")  # the other tool's lines by their polygon's FID
cols = min(len(fids), 4)
rows = (len(fids) + cols - 1) // cols
fig, axes = plt.subplots(rows, cols, figsize=(4.5 * cols, 4.5 * rows), squeeze=False)
for ax in axes.flat:
    ax.set_axis_off()
for ax, fid in zip(axes.flat, fids):
    P.loc[[fid]].plot(ax=ax, facecolor="#cfe3f3", edgecolor="#4a7aa5", linewidth=0.6)
    mine = L[L.src_fid == fid]
    lines = mine[mine.geom_type == "LineString"]
    points = mine[mine.geom_type == "Point"]
    if len(lines):
        lines.plot(ax=ax, color="#d62728", linewidth=2.0)
    if len(points):
        points.plot(ax=ax, color="#d62728", markersize=30)
    if O is not None and fid in O.index:
        O.loc[[fid]].plot(ax=ax, color="#333333", linewidth=1.0, linestyle="--")
    ax.set_aspect("equal")
    ax.set_title(f"fid {fid}", fontsize=9)
fig.tight_layout()
fig.savefig(out, dpi=100)
