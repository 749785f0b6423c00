"""Skeletons of one polygon layer with pygeoops.centerline (default options),
written to a GeoPackage layer with the source FID in `src_fid`.

usage: score_peers_pygeoops.py SRC.gpkg LAYER OUT.gpkg
"""

import sys
import time

import geopandas as gpd
import pygeoops

src, layer, out = sys.argv[1:4]
polys = gpd.read_file(src, layer=layer, fid_as_index=True)
t0 = time.perf_counter()
lines = pygeoops.centerline(polys.geometry.values)
elapsed = time.perf_counter() - t0
gdf = gpd.GeoDataFrame(
    {"src_fid": polys.index.astype("int64")}, geometry=list(lines), crs=polys.crs
)
gdf = gdf[~gdf.geometry.is_empty & gdf.geometry.notna()]
gdf.to_file(out, layer=layer, driver="GPKG")
print(f"{layer}\tpygeoops.centerline\t{len(polys)} polygons\t{len(gdf)} skeletons\t{elapsed:.1f}s")
