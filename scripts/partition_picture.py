#!/usr/bin/env python3
"""partition_picture.py SRC.gpkg RIVERS UNITS OUT.gpkg PICTURE.png [--bbox xmin ymin xmax ymax] [--title T]:
before and after a `partition` run, side by side: the units (each its own colour) and the
water (blue) before, with the units' boundaries inside the water dashed where the units cover it
(real administrative data: the legal line); the grown units, the new boundaries (red), the kept areas (yellow) and
the river's old banks (dotted) after."""
import argparse

import geopandas as gpd
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("src"); ap.add_argument("rivers"); ap.add_argument("units"); ap.add_argument("out"); ap.add_argument("png")
ap.add_argument("--bbox", type=float, nargs=4); ap.add_argument("--title", default="")
a = ap.parse_args()
R = gpd.read_file(a.src, layer=a.rivers)
U = gpd.read_file(a.src, layer=a.units, fid_as_index=True)
C = gpd.read_file(a.out, layer="coverage")
B = gpd.read_file(a.out, layer="boundaries")
layers = gpd.list_layers(a.out)["name"].tolist()
A = gpd.read_file(a.out, layer="areas") if "areas" in layers else None
b = a.bbox or R.total_bounds
rng = np.random.default_rng(3)
palette = plt.get_cmap("Pastel1").colors + plt.get_cmap("Pastel2").colors
colour = {fid: palette[rng.integers(len(palette))] for fid in U.index}
h = 6 * (b[3] - b[1]) / (b[2] - b[0])
fig, axs = plt.subplots(1, 2, figsize=(12, max(3.0, h)))
U.plot(ax=axs[0], color=[colour[f] for f in U.index], edgecolor="#555555", linewidth=0.4)
R.plot(ax=axs[0], facecolor="#6baed6", edgecolor="#08519c", linewidth=0.5)
# Units that cover the water (real administrative data): their boundaries inside it, dashed.
inside = U.boundary.intersection(R.union_all())
inside = inside[~inside.is_empty]
if len(inside):
    inside.plot(ax=axs[0], color="#333333", linewidth=0.9, linestyle="--")
C.plot(ax=axs[1], color=[colour[f] for f in C.src_fid], edgecolor="#555555", linewidth=0.4)
if A is not None and len(A):
    A.plot(ax=axs[1], facecolor="#ffeda0", edgecolor="#b8860b", linewidth=0.6)
R.boundary.plot(ax=axs[1], color="#08519c", linewidth=0.5, linestyle=":")
B.plot(ax=axs[1], color="#d7301f", linewidth=1.3)
axs[0].set_title("before: the units and the water (unit boundaries inside it dashed)", fontsize=10)
axs[1].set_title("after: the units grown, the new boundaries (red)", fontsize=10)
for ax in axs:
    ax.set_xlim(b[0], b[2]); ax.set_ylim(b[1], b[3]); ax.set_aspect("equal")
    ax.set_xticks([]); ax.set_yticks([]); ax.set_xlabel(""); ax.set_ylabel("")
if a.title:
    fig.suptitle(a.title, fontsize=10)
fig.tight_layout(); fig.savefig(a.png, dpi=100)
print(a.png)
