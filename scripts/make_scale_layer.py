"""Writes a large polygon layer for scale runs: the training islands tiled
over a grid and jittered (every vertex moved by up to 1 m by a smooth
displacement field with its own phase in each copy — the same point moves
the same way, so rings stay closed), so that no two polygons are the same.

usage: make_scale_layer.py SRC.gpkg LAYER OUT.gpkg N
needs: shapely, geopandas, pyogrio, numpy (PyPI)
"""

import sys

import geopandas as gpd
import numpy as np
import shapely

src, layer, out, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
base = gpd.read_file(src, layer=layer)
copies = -(-n // len(base))
minx, miny, maxx, maxy = base.total_bounds
step = max(maxx - minx, maxy - miny) * 1.05
side = int(np.ceil(np.sqrt(copies)))
rng = np.random.default_rng(12345)
parts = []
for k in range(copies):
    dx, dy = (k % side) * step, (k // side) * step
    phase = rng.uniform(0, 2 * np.pi, 2)

    def jitter(c, phase=phase, dx=dx, dy=dy):
        wobble = np.stack(
            [np.sin(c[:, 1] / 37.0 + phase[0]), np.cos(c[:, 0] / 41.0 + phase[1])], axis=1
        )
        return c + wobble + [dx, dy]

    g = shapely.transform(base.geometry.values, jitter)
    parts.append(gpd.GeoDataFrame({"copy": k, "kind": base["kind"]}, geometry=g, crs=base.crs))
result = gpd.GeoDataFrame(
    gpd.pd.concat(parts, ignore_index=True).iloc[:n], crs=base.crs
)
result.to_file(out, layer="scale", driver="GPKG")
print(f"{out}: {len(result)} polygons, {int(shapely.get_num_coordinates(result.geometry.values).sum())} vertices")
