"""Draws polygons with the lines of a network meeting them and the skeletons made in
`network` mode (and optionally another run's, dashed): the README's pictures of river
networks through lakes.

usage: network_picture.py OUT.png POLYS.gpkg@LAYER LINES.gpkg@LAYER SKELETONS.gpkg[,OTHER.gpkg] PANEL...
  PANEL = FID[:xmin,ymin,xmax,ymax][=TITLE]  (one polygon per panel, optionally zoomed)
needs: geopandas, pyogrio, matplotlib (PyPI)
"""

import sys

import geopandas as gpd
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

if len(sys.argv) < 6:
    sys.exit(__doc__)
out, polys, lines, skels, panels = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:]


def layer_of(spec):
    path, _, layer = spec.partition("@")
    return gpd.read_file(path, layer=layer or None, fid_as_index=True)


P, L = layer_of(polys), layer_of(lines)
runs = [gpd.read_file(s, layer="skeletons") for s in skels.split(",")]
fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 5.5), squeeze=False)
for ax, panel in zip(axes[0], panels):
    panel, _, title = panel.partition("=")
    fid, _, box = panel.partition(":")
    poly = P.loc[[int(fid)]]
    poly.plot(ax=ax, facecolor="#cfe3f3", edgecolor="#4a7aa5", linewidth=0.6)
    L.plot(ax=ax, color="#1f4e9a", linewidth=1.4)
    for k, S in enumerate(runs):
        S[S.src_fid == int(fid)].plot(
            ax=ax, color="#d62728" if k == 0 else "#555555", linewidth=1.6 if k == 0 else 0.9,
            linestyle="-" if k == 0 else "--")
    if box:
        x0, y0, x1, y1 = map(float, box.split(","))
    else:
        x0, y0, x1, y1 = poly.total_bounds
        pad = 0.05 * max(x1 - x0, y1 - y0)
        x0, y0, x1, y1 = x0 - pad, y0 - pad, x1 + pad, y1 + pad
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title or str(poly.iloc[0].get("name", f"fid {fid}")), fontsize=10)
fig.tight_layout()
fig.savefig(out, dpi=110)
