#!/usr/bin/env python3
"""Measures a partition (the `partition` step's output) against its input, and
the same measures for the peer, GEOS CoverageCleaner (shapely.coverage_clean:
every gap merged into the neighbour it shares the longest border with), on the
same data:

- coverage: the output units and areas form a valid coverage (shapely
  coverage_is_valid), every geometry is valid;
- area: |Σ out − Σ in| / Σ in (units and collapsed polygons in, units and
  areas out);
- unchanged: units that received nothing are bit for bit the input's;
- shrunk: units that lost area (more than 1e-9 of theirs);
- nearest: the share of random points of the collapsed polygons that lie in
  the unit whose bank is nearest (ties within the arc tolerance, 0.2 % of the
  distance, count as right; points nearest to unowned bank are left out);
- z: the paper's distortion of the new boundaries against the two units'
  banks, z = |d_l − d_r| / (d_l + d_r) at 49 points evenly spread along
  each line, mean over the points.

    scripts/partition_quality.py IN.gpkg RIVERS UNITS OUT.gpkg [--peer] [--covering]

With --covering the units cover the collapsed polygons (real administrative
units, `partition: {overlap: cut}`): each unit's *land* (the unit minus the
collapsed polygons) stands for the unit — its bank, the area in — and
"unchanged" means: outside the collapsed polygons every unit is its land
(what differs by more than the snap, 1e-7 × the waters' extent, at most
1e-9 of its area), and units that touch no collapsed polygon are bit for
bit the input's.

prints one line of measures (JSON); with --peer a second for CoverageCleaner.
"""

from __future__ import annotations

import argparse
import json
import warnings

import numpy as np
import pyogrio
import shapely

warnings.filterwarnings("ignore", category=RuntimeWarning)


def read(path, layer, **kw):
    return pyogrio.read_dataframe(path, layer=layer, fid_as_index=True, **kw)


def as_multi(geoms):
    """Polygons as one-part multipolygons (the `coverage` layer's type), the
    coordinates untouched."""
    return np.array([shapely.MultiPolygon([g]) if g.geom_type == "Polygon" else g for g in geoms])


def banks(rivers, units, near=0.0):
    """Each unit's bank: the part of the collapsed polygons' boundary that lies
    on its boundary (shared edges have identical vertices, so it is exact).
    With `near` > 0, the part within that distance of it (a unit's land,
    computed by GEOS, whose noding of the shore can differ from ours by
    round-off)."""
    edge = shapely.union_all(rivers.geometry.boundary.values)
    shapely.prepare(edge)
    out = {}
    for fid, g in zip(units.index, units.geometry):
        if near > 0 and shapely.distance(edge, g) <= near:
            b = shapely.line_merge(shapely.intersection(edge, shapely.buffer(g.boundary, near)))
            if not b.is_empty and b.length > 0:
                out[fid] = b
        elif shapely.intersects(edge, g):
            b = shapely.line_merge(shapely.intersection(edge, g.boundary))
            if not b.is_empty and b.length > 0:
                out[fid] = b
    return out


def sample_points(rivers, n, seed=1):
    """n random points inside the collapsed polygons, spread by area."""
    rng = np.random.default_rng(seed)
    geoms = rivers.geometry.values
    areas = shapely.area(geoms)
    counts = rng.multinomial(n, areas / areas.sum())
    pts = []
    for g, k in zip(geoms, counts):
        if k == 0:
            continue
        shapely.prepare(g)
        minx, miny, maxx, maxy = g.bounds
        got = []
        while sum(len(x) for x in got) < k:
            xy = rng.uniform((minx, miny), (maxx, maxy), size=(max(64, 4 * k), 2))
            cand = shapely.points(xy)
            got.append(cand[shapely.contains(g, cand)])
        pts.append(np.concatenate(got)[:k])
    return np.concatenate(pts)


def nearest_share(points, polys, fids, bank):
    """The share of `points` in the polygon (of `polys`, unit `fids`) whose
    bank is nearest, ties within 0.2 % of the distance counting as right."""
    bank_fids = list(bank)
    bank_geoms = np.array([bank[f] for f in bank_fids])
    tree = shapely.STRtree(bank_geoms)
    (pi, bi), d_near = tree.query_nearest(points, return_distance=True, all_matches=False)
    near = np.full(len(points), -1, dtype=np.int64)
    dist = np.full(len(points), np.inf)
    near[pi] = np.array(bank_fids)[bi]
    dist[pi] = d_near
    ptree = shapely.STRtree(polys)
    qi, ui = ptree.query(points, predicate="within")
    holder = np.full(len(points), -1, dtype=np.int64)
    holder[qi] = np.asarray(fids)[ui]
    ok = holder == near
    for i in np.nonzero(~ok)[0]:
        own = bank.get(holder[i])
        if own is not None and shapely.distance(points[i], own) - dist[i] <= 0.002 * dist[i] + 1e-9:
            ok[i] = True
    return float(ok.mean())


def boundary_z(lines, left, right, bank):
    """Mean z of `lines` (between units `left` and `right`) against the two
    units' banks, and the number of points it is taken at."""
    zs = []
    for line, lf, rf in zip(lines, left, right):
        if lf not in bank or rf not in bank or line is None or line.is_empty:
            continue
        for part in shapely.get_parts(line):
            pts = shapely.line_interpolate_point(part, np.linspace(0, 1, 51)[1:-1], normalized=True)
            dl = shapely.distance(pts, bank[lf])
            dr = shapely.distance(pts, bank[rf])
            s = dl + dr
            keep = s > 0
            zs.append(np.abs(dl - dr)[keep] / s[keep])
    z = np.concatenate(zs) if zs else np.array([])
    return (float(z.mean()) if len(z) else float("nan")), int(len(z))


def land_of(units, rivers):
    """The units less the collapsed polygons (their land), and the units
    farther than the default snap (1e-7 × the waters' extent) from all of
    them (written bit for bit)."""
    water = shapely.union_all(rivers.geometry.values)
    land = units.copy()
    land["geometry"] = shapely.difference(units.geometry.values, water)
    x0, y0, x1, y1 = shapely.total_bounds(rivers.geometry.values)
    far = shapely.distance(units.geometry.values, water) > 1e-7 * max(x1 - x0, y1 - y0)
    untouched = set(units.index[far])
    return land, untouched, water


def legal_offset(units, water, bnd):
    """How far the legal lines inside the water (the boundaries two covering
    units share there) lie from the new boundaries: at 2 000 points along
    them, the distance to the nearest new boundary between two units, as a
    share of the local width (twice the distance to the shore): median, and
    the largest distance (CRS units)."""
    g = units.geometry.values
    shared = [shapely.intersection(shapely.boundary(g[i]), shapely.boundary(g[j]))
              for i in range(len(g)) for j in range(i + 1, len(g))]
    legal = shapely.intersection(shapely.union_all(shared), water) if shared else None
    inner = bnd[bnd.left_fid.notna() & bnd.right_fid.notna()] if bnd is not None else None
    if legal is None or legal.is_empty or legal.length == 0 or inner is None or not len(inner):
        return None, None
    pts = shapely.line_interpolate_point(legal, np.linspace(0, legal.length, 2002)[1:-1])
    d = shapely.distance(pts, shapely.union_all(inner.geometry.values))
    w = 2 * shapely.distance(pts, water.boundary)
    return float(np.median(d[w > 0] / w[w > 0])), float(d.max())


def measure_ours(src, rivers_layer, units_layer, out, samples=20000, covering=False):
    units = read(src, units_layer)
    rivers = read(src, rivers_layer)
    if covering:
        original, (units, untouched, water) = units, land_of(units, rivers)
    cov = pyogrio.read_dataframe(out, layer="coverage")
    layers = {n for n, _ in pyogrio.list_layers(out)}
    areas = pyogrio.read_dataframe(out, layer="areas") if "areas" in layers else None
    given = pyogrio.read_dataframe(out, layer="given", read_geometry=False) if "given" in layers else None
    bnd = pyogrio.read_dataframe(out, layer="boundaries") if "boundaries" in layers else None
    out_geoms = cov.geometry.values
    everything = np.concatenate([out_geoms, areas.geometry.values]) if areas is not None else out_geoms
    a_in = shapely.area(units.geometry.values).sum() + shapely.area(rivers.geometry.values).sum()
    a_out = shapely.area(everything).sum()
    received = set(given.unit_fid) if given is not None else set()
    orig = as_multi(units.geometry.loc[cov.src_fid].values)
    same = shapely.equals_exact(orig, out_geoms, tolerance=0)
    unchanged_ok = bool(all(s for s, f in zip(same, cov.src_fid) if f not in received))
    if covering:
        first = as_multi(original.geometry.loc[cov.src_fid].values)
        same = shapely.equals_exact(first, out_geoms, tolerance=0)
        outside = shapely.difference(out_geoms, water)
        # What the snap moved (vertices and edges within `snap`, 1e-7 ×
        # the water's extent by default, of its bank, each by less than
        # `snap`) is not a change.
        x0, y0, x1, y1 = shapely.total_bounds(rivers.geometry.values)
        band = shapely.buffer(shapely.boundary(orig), 1e-7 * max(x1 - x0, y1 - y0))
        changed = shapely.symmetric_difference(outside, orig)
        moved = shapely.area(shapely.difference(changed, band))
        unchanged_ok = bool(
            all(s for s, f in zip(same, cov.src_fid) if f in untouched)
            and (moved <= 1e-9 * np.maximum(shapely.area(orig), 1.0)).all()
        )
    lost = shapely.area(shapely.difference(orig, out_geoms))
    if covering:
        m_held = float(given.held.sum()) if given is not None and "held" in given else 0.0
    shrunk = int((lost > 1e-9 * np.maximum(shapely.area(orig), 1.0)).sum())
    if covering:
        x0, y0, x1, y1 = shapely.total_bounds(rivers.geometry.values)
        bank = banks(rivers, units, near=1e-8 * max(x1 - x0, y1 - y0))
    else:
        bank = banks(rivers, units)
    m = {
        "units": len(cov),
        "grown": int((~same).sum()),
        "coverage_valid": bool(shapely.coverage_is_valid(everything)),
        "all_valid": bool(shapely.is_valid(everything).all()),
        "area_rel": float(abs(a_out - a_in) / a_in),
        "unchanged_bit_for_bit": unchanged_ok,
        "shrunk": shrunk,
        "same_order": list(cov.src_fid) == sorted(cov.src_fid),
    }
    if covering:
        m["held"] = m_held
        m["legal_offset_median"], m["legal_offset_max"] = legal_offset(original, water, bnd)
    if given is not None and not covering:
        gained = shapely.area(out_geoms) - shapely.area(orig)
        by = given.groupby("unit_fid")["area"].sum()
        want = np.array([by.get(f, 0.0) for f in cov.src_fid])
        m["given_rel"] = float(np.abs(gained - want).max() / a_in)
    if samples:
        pts = sample_points(rivers, samples)
        # Points nearest to bank no unit owns are not judged.
        edge = shapely.union_all(rivers.geometry.values).boundary
        owned = shapely.union_all(list(bank.values()))
        free = shapely.difference(edge, owned)
        judged = pts
        if not free.is_empty and free.length > 0:
            d_free = shapely.distance(pts, free)
            d_owned = shapely.distance(pts, owned)
            judged = pts[d_owned < d_free]
        polys = np.concatenate([out_geoms, areas.geometry.values]) if areas is not None else out_geoms
        fids = list(cov.src_fid) + ([-2] * len(areas) if areas is not None else [])
        m["nearest"] = nearest_share(judged, polys, fids, bank)
        m["nearest_points"] = int(len(judged))
    if bnd is not None and len(bnd):
        m["z_mean"], m["z_points"] = boundary_z(
            bnd.geometry.values, bnd.left_fid.fillna(-1).astype(int), bnd.right_fid.fillna(-1).astype(int), bank
        )
    return m


def measure_peer(src, rivers_layer, units_layer):
    """CoverageCleaner on the units alone (each collapsed polygon a gap, merged
    into the neighbour with the longest shared border), measured as ours."""
    units = read(src, units_layer)
    rivers = read(src, rivers_layer)
    width = max(max(g.bounds[2] - g.bounds[0], g.bounds[3] - g.bounds[1]) for g in rivers.geometry)
    cleaned = shapely.coverage_clean(units.geometry.values, gap_width=width)
    bank = banks(rivers, units)
    everything = cleaned
    a_in = shapely.area(units.geometry.values).sum() + shapely.area(rivers.geometry.values).sum()
    river = shapely.union_all(rivers.geometry.values)
    shapely.prepare(river)
    # New boundaries: what two cleaned units share now and did not before,
    # in or on the collapsed polygons (along a bank, where one unit took the
    # whole polygon).
    tree = shapely.STRtree(cleaned)
    a, b = tree.query(cleaned, predicate="touches")
    lines, left, right = [], [], []
    fids = list(units.index)
    before = units.geometry.values
    for i, j in zip(a, b):
        if i >= j:
            continue
        shared = shapely.intersection(cleaned[i].boundary, cleaned[j].boundary)
        new = shapely.difference(shared, shapely.intersection(before[i].boundary, before[j].boundary))
        new = shapely.intersection(new, river)
        if new.is_empty or new.length == 0:
            continue
        lines.append(new)
        left.append(fids[i])
        right.append(fids[j])
    pts = sample_points(rivers, 20000)
    m = {
        "coverage_valid": bool(shapely.coverage_is_valid(everything)),
        "area_rel": float(abs(shapely.area(everything).sum() - a_in) / a_in),
        "nearest": nearest_share(pts, cleaned, fids, bank),
    }
    m["z_mean"], m["z_points"] = boundary_z(lines, left, right, bank)
    return m


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("src")
    p.add_argument("rivers")
    p.add_argument("units")
    p.add_argument("out")
    p.add_argument("--peer", action="store_true")
    p.add_argument("--samples", type=int, default=20000, help="random points (0: no nearest-bank measure)")
    p.add_argument("--covering", action="store_true", help="the units cover the collapsed polygons")
    o = p.parse_args()
    print(json.dumps({"tool": "skeletonise", **measure_ours(o.src, o.rivers, o.units, o.out, o.samples, o.covering)}))
    if o.peer:
        print(json.dumps({"tool": "CoverageCleaner", **measure_peer(o.src, o.rivers, o.units)}))


if __name__ == "__main__":
    main()
