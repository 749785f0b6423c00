#!/usr/bin/env bash
# Line ends before and after a change, side by side: the features FIDS of LAYER in SOURCE run through
# the default pipeline by BEFORE (another skeletonise binary) and by target/release/skeletonise, drawn
# in pairs of panels zoomed to each polygon (the chosen skeleton in red, its method and Z in the title).
#   BEFORE=/path/to/old/skeletonise scripts/ends_before_after.sh SOURCE LAYER "fid1,fid2,…" OUT.png
# Needs gdal-bin (ogr2ogr) and target/py-venv (geopandas, matplotlib: scripts/python-env.sh).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SRC=$1 LAYER=$2 FIDS=$3 OUT=$4
BEFORE=${BEFORE:?give BEFORE=/path/to/the/other/skeletonise}
AFTER=${AFTER:-$ROOT/target/release/skeletonise}
D=$(mktemp -d)
trap 'rm -rf "$D"' EXIT
ogr2ogr -f GPKG "$D/f.gpkg" "$SRC" "$LAYER" -where "fid in ($FIDS)" -nln f -preserve_fid
"$BEFORE" run -i "$D/f.gpkg" -o "$D/before.gpkg" --overwrite -q
"$AFTER" run -i "$D/f.gpkg" -o "$D/after.gpkg" --overwrite -q
"$ROOT/target/py-venv/bin/python" - "$D" "$OUT" <<'PY'
import sys, geopandas as gpd, matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
d, out = sys.argv[1:]
P = gpd.read_file(f"{d}/f.gpkg", fid_as_index=True)
runs = {c: gpd.read_file(f"{d}/{c}.gpkg", layer="skeletons") for c in ("before", "after")}
per = 3
rows = -(-len(P) // per)
fig, axes = plt.subplots(rows, 2 * per, figsize=(3.2 * 2 * per, 3.4 * rows), squeeze=False)
for ax in axes.flat:
    ax.set_axis_off()
for j in range(len(P)):
    p = P.iloc[[j]]
    b = p.total_bounds
    pad = 0.04 * max(b[2] - b[0], b[3] - b[1])
    for i, (c, S) in enumerate(runs.items()):
        ax = axes[j // per][2 * (j % per) + i]
        p.plot(ax=ax, facecolor="#dde", edgecolor="#445", linewidth=0.6)
        s = S[S.src_fid == P.index[j]]
        s.plot(ax=ax, color="red", linewidth=1.3)
        ax.set_xlim(b[0] - pad, b[2] + pad); ax.set_ylim(b[1] - pad, b[3] + pad); ax.set_aspect("equal")
        label = f"{s.method.iloc[0]} Z {s.distortion.iloc[0]:.6f}" if len(s) else "no skeleton"
        ax.set_title(f"{c}, fid {P.index[j]}\n{label}", fontsize=8)
fig.tight_layout()
fig.savefig(out, dpi=75)
print(out)
PY
