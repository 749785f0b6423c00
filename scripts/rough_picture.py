"""Draws polygons with skeletons side by side, each panel optionally zoomed:
the README's pictures of rough boundaries.

usage: rough_picture.py OUT.png POLYS.gpkg[@LAYER][#FID] PANEL...
  PANEL = SKELETONS.gpkg:TITLE[:xmin,ymin,xmax,ymax]
  (the skeletons layer `skeletons`; #FID keeps one polygon and the
  skeletons whose src_fid is that FID)
needs: geopandas, pyogrio, matplotlib (PyPI)
"""

import sys

import geopandas as gpd
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

out, polys, panels = sys.argv[1], sys.argv[2], sys.argv[3:]
path, _, fid = polys.partition("#")
path, _, layer = path.partition("@")
P = gpd.read_file(path, layer=layer or None, fid_as_index=True)
if fid:
    P = P.loc[[int(fid)]]
fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 5.5), squeeze=False)
for ax, panel in zip(axes[0], panels):
    spec = panel.split(":")
    S = gpd.read_file(spec[0], layer="skeletons")
    if fid:
        S = S[S.src_fid == int(fid)]
    P.plot(ax=ax, facecolor="#dde4f0", edgecolor="#445", linewidth=0.5)
    S.plot(ax=ax, color="#c0392b", linewidth=1.2)
    ax.set_title(spec[1], fontsize=10)
    if len(spec) > 2:
        x0, y0, x1, y1 = map(float, spec[2].split(","))
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
fig.tight_layout()
fig.savefig(out, dpi=80)
print(out)
