//! `input.merge_adjacent`: polygons that share boundary — river reaches,
//! tiles, map sheets — become one feature before skeletonising, so that their
//! skeleton is one line with no gap or kink at the former seams.
//!
//! Two polygons are adjacent when they share a boundary edge: both end
//! vertices agree within [`SNAP`] CRS units (reaches and tiles cut from one
//! source share their seam's vertices). Each connected group (optionally only
//! among features with the same value of one field) is dissolved into one
//! (multi)polygon; the merged feature takes the attributes of its member
//! with the smallest FID and lists every member's FID.

use crate::feature::Feature;
use crate::graph::UnionFind;
use geo::{Coord, Geometry, LineString, MultiPolygon, Polygon};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::float::simplify::SimplifyShape;
use std::collections::HashMap;

/// An edge of a group: the group key and its two snapped end vertices.
type EdgeKey = (String, (i64, i64), (i64, i64));

/// Vertices of a shared edge agree within this many CRS units.
pub const SNAP: f64 = 1e-6;

/// The features with every group of adjacent polygons dissolved into one,
/// in the order of each group's first member; `by`: merge only features
/// whose attribute at this index has the same value.
pub fn merge_adjacent(features: Vec<Feature>, by: Option<usize>) -> Vec<Feature> {
    merge_with(features, by, dissolve)
}

/// [`merge_adjacent`] with each group's union made exactly
/// (`geometry::arrangement::coverage_union`: the shared edges
/// dropped, every other vertex kept bit for bit), for polygons that share
/// their edges vertex for vertex (reaches cut from one river) — what a
/// partition needs, whose pieces must keep the source's vertices.
///
/// Polygons that overlap (two reaches drawn over each other by a
/// millimetre) join a group too; such a group cannot be put together
/// exactly and is dissolved as [`merge_adjacent`] dissolves (a warning
/// names its members): the units are snapped onto the bank they then have.
pub fn merge_adjacent_exactly(features: Vec<Feature>, by: Option<usize>) -> Vec<Feature> {
    let overlapping = overlapping_pairs(&features);
    let mut uf = UnionFind::new(features.len());
    for &(i, j) in &overlapping {
        uf.union(i, j);
    }
    let overlapped: std::collections::HashSet<u64> = overlapping
        .iter()
        .flat_map(|&(i, j)| [features[i].fid, features[j].fid])
        .flatten()
        .collect();
    merge_groups(features, by, uf, |group| {
        if group
            .iter()
            .any(|f| f.fid.is_some_and(|x| overlapped.contains(&x)))
        {
            let fids: Vec<String> = group
                .iter()
                .map(|f| crate::feature::fid_text(f.fid))
                .collect();
            tracing::warn!(
                "features {} overlap each other: dissolved into one polygon (not exactly, as `merge_adjacent` does) before the steps",
                fids.join(", ")
            );
            dissolve(group)
        } else {
            dissolve_exactly(group)
        }
    })
}

/// The pairs of polygon features whose interiors overlap (by their
/// indices, the smaller first): `geometry::overlay::interiors_meet` either
/// way round (within `1e-9 ×` the pair's extent).
fn overlapping_pairs(features: &[Feature]) -> Vec<(usize, usize)> {
    use crate::geometry::overlay::interiors_meet;
    use crate::geometry::Boundary;
    use geo::{BoundingRect, InteriorPoint};
    use rstar::RTreeObject;
    let polys: Vec<Option<MultiPolygon<f64>>> = features
        .iter()
        .map(|f| polygons(f).map(MultiPolygon))
        .collect();
    let tree = crate::geometry::box_index(
        polys
            .iter()
            .map(|p| p.as_ref().and_then(|p| p.bounding_rect())),
    );
    let boxes: Vec<&crate::geometry::IndexedBox> = tree.iter().collect();
    let mut out = Vec::new();
    for b in &boxes {
        let i = b.data;
        let (lo, hi) = (b.geom().envelope().lower(), b.geom().envelope().upper());
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        for hit in tree.locate_in_envelope_intersecting(&b.geom().envelope()) {
            let j = hit.data;
            if j <= i {
                continue;
            }
            let (Some(a), Some(c)) = (&polys[i], &polys[j]) else {
                continue;
            };
            let meet = |a: &MultiPolygon<f64>, c: &MultiPolygon<f64>| {
                c.0.iter().any(|q| {
                    let probe = q.interior_point().map(|p| p.0);
                    interiors_meet(a, &Boundary::new(q), probe, 1e-9 * extent)
                })
            };
            if meet(a, c) || meet(c, a) {
                out.push((i, j));
            }
        }
    }
    out
}

fn merge_with(
    features: Vec<Feature>,
    by: Option<usize>,
    dissolve: fn(Vec<Feature>) -> Feature,
) -> Vec<Feature> {
    let uf = UnionFind::new(features.len());
    merge_groups(features, by, uf, dissolve)
}

/// [`merge_with`] starting from the groups `uf` already joined.
fn merge_groups(
    features: Vec<Feature>,
    by: Option<usize>,
    mut uf: UnionFind,
    dissolve: impl Fn(Vec<Feature>) -> Feature,
) -> Vec<Feature> {
    let n = features.len();
    // Each edge (quantised, unordered) → the first feature seen with it, per group key.
    let mut edges: HashMap<EdgeKey, usize> = HashMap::new();
    for (i, f) in features.iter().enumerate() {
        let Some(parts) = polygons(f) else { continue };
        // As in SQL, NULL equals nothing: a feature whose `merge_by` value
        // is NULL merges with no other.
        let key = match by {
            None => String::new(),
            Some(k) => match f.attributes.get(k).and_then(|v| v.as_text()) {
                Some(v) => v,
                None => continue,
            },
        };
        for p in &parts {
            for ring in std::iter::once(p.exterior()).chain(p.interiors()) {
                for w in ring.0.windows(2) {
                    let (a, b) = (snap(w[0]), snap(w[1]));
                    if a == b {
                        continue;
                    }
                    let e = (key.clone(), a.min(b), a.max(b));
                    match edges.get(&e) {
                        Some(&j) if j != i => uf.union(i, j),
                        Some(_) => {}
                        None => {
                            edges.insert(e, i);
                        }
                    }
                }
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        groups[uf.find(i)].push(i);
    }
    let mut slots: Vec<Option<Feature>> = features.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(n);
    for (root, members) in groups.iter().enumerate() {
        match members.len() {
            0 => {}
            1 => out.push(slots[root].take().expect("each feature once")),
            _ => {
                let group: Vec<Feature> = members
                    .iter()
                    .map(|&i| slots[i].take().expect("each feature once"))
                    .collect();
                out.push(dissolve(group));
            }
        }
    }
    out
}

/// The polygons of a readable polygon feature.
fn polygons(f: &Feature) -> Option<Vec<Polygon<f64>>> {
    if f.geometry_error.is_some() {
        return None;
    }
    match f.geometry.as_ref()? {
        Geometry::Polygon(p) => Some(vec![p.clone()]),
        Geometry::MultiPolygon(m) => Some(m.0.clone()),
        _ => None,
    }
}

fn snap(c: Coord<f64>) -> (i64, i64) {
    ((c.x / SNAP).round() as i64, (c.y / SNAP).round() as i64)
}

/// One feature from a group of adjacent ones (the first, by FID, gives the
/// attributes), its geometry their union, `members` their FIDs.
pub fn dissolve(mut group: Vec<Feature>) -> Feature {
    group.sort_by_key(|f| f.fid);
    let ring = |l: &LineString<f64>| -> Vec<[f64; 2]> {
        let n = l.0.len().saturating_sub(1);
        l.0[..n].iter().map(|c| [c.x, c.y]).collect()
    };
    let shapes: Vec<Vec<Vec<[f64; 2]>>> = group
        .iter()
        .flat_map(|f| polygons(f).unwrap_or_default())
        .map(|p| {
            // Exterior counter-clockwise, holes clockwise, for the non-zero rule.
            let p = crate::geometry::ring::normalise_polygon(&p).unwrap_or(p);
            std::iter::once(ring(p.exterior()))
                .chain(p.interiors().iter().map(ring))
                .collect()
        })
        .collect();
    let closed = |c: &Vec<[f64; 2]>| {
        let mut v: Vec<Coord<f64>> = c.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
        if let Some(&f) = v.first() {
            v.push(f);
        }
        LineString(v)
    };
    let merged: Vec<Polygon<f64>> = shapes
        .simplify_shape(FillRule::NonZero)
        .iter()
        .filter(|s| !s.is_empty())
        .map(|s| Polygon::new(closed(&s[0]), s[1..].iter().map(closed).collect()))
        .collect();
    merged_feature(group, merged)
}

/// The group's first feature (by FID) standing for all of it: `merged` its
/// geometry, the members' FIDs listed, repaired if any member was.
fn merged_feature(mut group: Vec<Feature>, merged: Vec<Polygon<f64>>) -> Feature {
    let members: Vec<u64> = group.iter().filter_map(|f| f.fid).collect();
    let member_wkb: Vec<Option<Vec<u8>>> = group
        .iter()
        .filter(|f| f.fid.is_some())
        .map(|f| f.source_wkb.clone())
        .collect();
    let repaired = group.iter().any(|f| f.repaired);
    let mut first = group.swap_remove(0);
    first.geometry = Some(match merged.len() {
        1 => Geometry::Polygon(merged.into_iter().next().expect("one")),
        _ => Geometry::MultiPolygon(MultiPolygon(merged)),
    });
    first.source_wkb = None;
    first.repaired = repaired;
    first.checked = false;
    first.members = members;
    first.member_wkb = member_wkb;
    first
}

/// [`dissolve`] with the union made exactly.
fn dissolve_exactly(mut group: Vec<Feature>) -> Feature {
    group.sort_by_key(|f| f.fid);
    let parts: Vec<Polygon<f64>> = group
        .iter()
        .flat_map(|f| polygons(f).unwrap_or_default())
        .collect();
    let merged = crate::geometry::coverage::coverage_union(&parts);
    merged_feature(group, merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::{polygon, Area};

    fn square(fid: u64, x: f64) -> Feature {
        Feature::from_geometry(
            Some(fid),
            Geometry::Polygon(
                polygon![(x: x, y: 0.), (x: x + 1., y: 0.), (x: x + 1., y: 1.), (x: x, y: 1.)],
            ),
        )
    }

    #[test]
    fn squares_sharing_an_edge_become_one_and_a_distant_one_stays() {
        let out = merge_adjacent(vec![square(3, 1.0), square(1, 0.0), square(7, 5.0)], None);
        assert_eq!(out.len(), 2);
        let m = out.iter().find(|f| f.fid == Some(1)).expect("merged");
        assert_eq!(m.members, vec![1, 3]);
        let Some(Geometry::Polygon(p)) = &m.geometry else {
            panic!("{:?}", m.geometry)
        };
        assert!((p.unsigned_area() - 2.0).abs() < 1e-9);
        assert!(out.iter().any(|f| f.fid == Some(7) && f.members.is_empty()));
    }

    #[test]
    fn null_merge_by_values_merge_with_nothing_as_in_sql() {
        use crate::feature::Value;
        let with = |f: Feature, v: Value| Feature {
            attributes: vec![v],
            ..f
        };
        let out = merge_adjacent(
            vec![
                with(square(1, 0.0), Value::Null),
                with(square(2, 1.0), Value::Null),
                with(square(3, 2.0), Value::Text("a".into())),
                with(square(4, 3.0), Value::Text("a".into())),
            ],
            Some(0),
        );
        let members: Vec<Vec<u64>> = out.iter().map(|f| f.members.clone()).collect();
        assert_eq!(members, [vec![], vec![], vec![3, 4]]);
    }
}
