"""Draws the features listed by `examples/ends.rs --wkt FILE.csv`: one panel per feature with its
polygon (grey), raw medial axis (thin), chosen skeleton (red) and best-scoring candidate (blue, dashed).

usage: ends_picture.py FILE.csv OUT.png [FID ...]      (default: every feature in the file, 24 at most)
needs: shapely, matplotlib (PyPI)
"""

import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import shapely  # noqa: E402

csv.field_size_limit(1 << 30)
path, out, *want = sys.argv[1:]
rows = {}
for r in csv.DictReader(open(path)):
    rows.setdefault(r["fid"], []).append(r)
fids = want or list(rows)[:24]
cols = min(4, len(fids))
lines = math.ceil(len(fids) / cols)
fig, axes = plt.subplots(lines, cols, figsize=(5 * cols, 5 * lines), squeeze=False)
for ax in axes.flat:
    ax.set_axis_off()


def draw(ax, g, **kw):
    for part in getattr(g, "geoms", [g]):
        if part.geom_type == "Polygon":
            for ring in [part.exterior, *part.interiors]:
                x, y = ring.xy
                ax.fill(x, y, facecolor="#dde", edgecolor="#445", linewidth=0.6)
        else:
            x, y = part.xy
            ax.plot(x, y, **kw)


for ax, fid in zip(axes.flat, fids):
    title = [f"fid {fid}"]
    for r in rows[fid]:
        g = shapely.from_wkt(r["wkt"])
        kind = r["kind"]
        if kind == "polygon":
            draw(ax, g)
        elif kind == "axis":
            draw(ax, g, color="#99a", linewidth=0.4)
        elif kind == "chosen":
            draw(ax, g, color="red", linewidth=1.4)
            title.append(f"chosen {r['label']}")
        elif kind == "best":
            draw(ax, g, color="blue", linewidth=1.0, linestyle="--")
            title.append(f"best {r['label']}")
    ax.set_title("\n".join(title), fontsize=8)
    ax.set_aspect("equal")
fig.tight_layout()
fig.savefig(out, dpi=90)
print(out)
