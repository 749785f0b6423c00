#!/usr/bin/env python3
"""collapse_picture.py POLYS.gpkg LAYER OUT.gpkg PICTURE.png [--bbox xmin ymin xmax ymax] [--title T]:
the polygon (grey outline), the kept areas (blue), the collapsed lines (red) and the
centreline through the kept areas (thin dark blue) of a `collapse` run."""
import argparse
import geopandas as gpd, matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
ap = argparse.ArgumentParser()
ap.add_argument("polys"); ap.add_argument("layer"); ap.add_argument("out"); ap.add_argument("png")
ap.add_argument("--bbox", type=float, nargs=4); ap.add_argument("--title", default="")
a = ap.parse_args()
P = gpd.read_file(a.polys, layer=a.layer)
A = gpd.read_file(a.out, layer="areas")
S = gpd.read_file(a.out, layer="skeletons")
b = a.bbox or P.total_bounds
fig, ax = plt.subplots(figsize=(9, 9 * (b[3] - b[1]) / (b[2] - b[0])))
P.plot(ax=ax, facecolor="#eeeeee", edgecolor="#888888", linewidth=0.5)
A.plot(ax=ax, facecolor="#9ecae1", edgecolor="#3182bd", linewidth=0.5)
S[S.collapsed == 0].plot(ax=ax, color="#08306b", linewidth=0.4)
S[S.collapsed == 1].plot(ax=ax, color="#d7301f", linewidth=1.2)
ax.set_xlim(b[0], b[2]); ax.set_ylim(b[1], b[3]); ax.set_aspect("equal")
ax.set_xticks([]); ax.set_yticks([]); ax.set_title(a.title, fontsize=10)
fig.tight_layout(); fig.savefig(a.png, dpi=110)
print(a.png)
