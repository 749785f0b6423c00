//! Exact overlay of a set of polygons A (a unit of a coverage) with one
//! polygon B (a collapsed polygon), for units that overlap it or were
//! digitised against another version of its bank:
//!
//! 1. **Snap** ([`snap_vertices`], [`snap_edges`]): every vertex of A
//!    within `snap` of ∂B moves onto it — onto B's vertex when within
//!    `snap` of one, else onto the nearest point of B's edge, which is put
//!    into that edge — and then every vertex of B within `snap` of an edge
//!    of A (and farther than `snap` from its ends) is put into that edge.
//!    Where A ran along ∂B within `snap`, the two now share their edges
//!    vertex for vertex; a sliver of A narrower than `snap` along ∂B
//!    collapses onto it. The moves and insertions are kept as [`Edits`],
//!    so that the same snapped A can be made again from the original when
//!    the coverage is written ([`Edits::apply`]): a vertex shared by two
//!    units moves the same way in both.
//! 2. **Node** ([`overlay`]): every point where an edge of A and one of B
//!    cross is put into both (computed from the two segments in a fixed
//!    order, so two units that share an edge get the same point), and a
//!    vertex of either within `tol` of the other's edge is put into it.
//! 3. **Classify**: a noded edge of A that is an edge of B the same way
//!    round bounds A ∩ B, the other way round A − B; any other edge of A
//!    bounds A ∩ B when its middle is inside B, else A − B; an edge of B
//!    that is none of A's bounds A ∩ B (and, reversed, A − B) when its
//!    middle is inside A. The two sets of directed edges are walked into
//!    polygons by `polygons_of_edges` (in `arrangement`), an edge met both ways cancelling.
//!
//! No vertex of A or B moves but by the snap; every vertex added is a
//! crossing or a vertex of the other, so A − B, A ∩ B and B share their
//! edges exactly. [`signed_union`] puts such pieces together again: the
//! union of some polygons minus others, noded at each other's vertices.

use super::arrangement::polygons_of_edges;
use super::ring::normalise_polygon;
use super::segment::{closest_on_segment, crossing_point, inner_points_along, properly_cross};
use super::vector::norm;
use super::Boundary;
use crate::geometry::CoordKey;
use geo::{Area, Coord, LineString, MultiPolygon, Polygon};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};
use rustc_hash::{FxHashMap, FxHashSet};

/// A coordinate by its bits.
type Key = CoordKey;

fn key(c: Coord<f64>) -> Key {
    CoordKey::from(c)
}

/// An edge of a polygon set: (polygon, ring — 0 the exterior —, index of
/// its first vertex in the ring).
pub type EdgeAt = (u32, u32, u32);

/// What a snap does to a polygon set: vertices moved (by their original
/// coordinates) and points put into edges (by the edge's place in the
/// original rings).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Edits {
    moves: FxHashMap<Key, Coord<f64>>,
    inserts: FxHashMap<EdgeAt, Vec<Coord<f64>>>,
}

impl Edits {
    /// Whether nothing moves and nothing is put in.
    pub fn is_empty(&self) -> bool {
        self.moves.is_empty() && self.inserts.is_empty()
    }

    /// Adds `other`'s edits; a vertex `self` moves already keeps its move.
    pub fn merge(&mut self, other: &Edits) {
        for (k, c) in &other.moves {
            self.moves.entry(*k).or_insert(*c);
        }
        for (e, pts) in &other.inserts {
            self.inserts.entry(*e).or_default().extend(pts);
        }
    }

    /// Where vertex `c` goes.
    fn moved(&self, c: Coord<f64>) -> Coord<f64> {
        self.moves.get(&key(c)).copied().unwrap_or(c)
    }

    /// `m` edited: every vertex moved, the points put into their edges in
    /// order along each, repeated points dropped. A ring left with fewer
    /// than three distinct points is dropped (a polygon whose exterior is,
    /// with it).
    pub fn apply(&self, m: &MultiPolygon<f64>) -> MultiPolygon<f64> {
        if self.is_empty() {
            return m.clone();
        }
        let ring = |k: usize, r: usize, l: &LineString<f64>| -> Option<LineString<f64>> {
            let mut out = Vec::with_capacity(l.0.len());
            for (i, w) in l.0.windows(2).enumerate() {
                let (a, b) = (self.moved(w[0]), self.moved(w[1]));
                out.push(a);
                if let Some(extra) = self.inserts.get(&(k as u32, r as u32, i as u32)) {
                    out.extend(inner_points_along(a, b, extra));
                }
            }
            out.push(self.moved(*l.0.last()?));
            out.dedup();
            (out.len() >= 4).then_some(LineString(out))
        };
        MultiPolygon(
            m.0.iter()
                .enumerate()
                .filter_map(|(k, p)| {
                    let exterior = ring(k, 0, p.exterior())?;
                    let holes = p
                        .interiors()
                        .iter()
                        .enumerate()
                        .filter_map(|(r, h)| ring(k, r + 1, h))
                        .collect();
                    Some(Polygon::new(exterior, holes))
                })
                .collect(),
        )
    }
}

/// The rings of a polygon set with their places: (polygon, ring, ring).
fn rings_of(m: &MultiPolygon<f64>) -> impl Iterator<Item = (u32, u32, &LineString<f64>)> {
    m.0.iter().enumerate().flat_map(|(k, p)| {
        std::iter::once(p.exterior())
            .chain(p.interiors())
            .enumerate()
            .map(move |(r, l)| (k as u32, r as u32, l))
    })
}

/// A point put into an edge of B: (ring, index of its first vertex).
pub type BankInsert = ((u32, u32), Coord<f64>);

/// The first step of the snap: every vertex of `a` within `snap` of `b`
/// moves onto it (see the module documentation), into `edits`: onto B's
/// vertex within `snap` of it, else, when farther than `tol` from ∂B
/// (closer, it is on an edge of B already, and [`overlay`] nodes it
/// there), onto the nearest point of B's edge, which goes into `into_b`.
pub fn snap_vertices(
    a: &MultiPolygon<f64>,
    b: &Boundary,
    (snap, tol): (f64, f64),
    edits: &mut Edits,
    into_b: &mut Vec<BankInsert>,
) {
    if snap <= 0.0 {
        return;
    }
    for (_, _, ring) in rings_of(a) {
        for &v in &ring.0 {
            let Some((c, i, d)) = b.nearest_within(v, snap) else {
                continue;
            };
            if d > snap {
                continue;
            }
            let s = &b.segments()[i];
            let (da, db) = (norm(v - s.a), norm(v - s.b));
            let to = if da <= snap && da <= db {
                s.a
            } else if db <= snap {
                s.b
            } else if d <= tol {
                continue;
            } else {
                into_b.push(((s.ring, s.index), c));
                c
            };
            if to != v {
                edits.moves.insert(key(v), to);
            }
        }
    }
}

/// The second step of the snap: every point of `b_points` within `snap`
/// of an edge of `a` (as `edits` moves its vertices) but farther than
/// `tol` (closer is on it already: [`overlay`] nodes it), and farther than
/// `snap` from both its ends, put into that edge.
pub fn snap_edges(
    a: &MultiPolygon<f64>,
    b_points: &RTree<[f64; 2]>,
    (snap, tol): (f64, f64),
    edits: &mut Edits,
) {
    if snap <= tol {
        return;
    }
    let mut inserts: Vec<(EdgeAt, Coord<f64>)> = Vec::new();
    let bounds = b_points.root().envelope();
    let (lo, hi) = (bounds.lower(), bounds.upper());
    for (k, r, ring) in rings_of(a) {
        for (i, w) in ring.0.windows(2).enumerate() {
            let (p, q) = (edits.moved(w[0]), edits.moved(w[1]));
            if p.x.max(q.x) < lo[0] - snap
                || p.x.min(q.x) > hi[0] + snap
                || p.y.max(q.y) < lo[1] - snap
                || p.y.min(q.y) > hi[1] + snap
            {
                continue;
            }
            let env = AABB::from_corners(
                [p.x.min(q.x) - snap, p.y.min(q.y) - snap],
                [p.x.max(q.x) + snap, p.y.max(q.y) + snap],
            );
            for x in b_points.locate_in_envelope(&env) {
                let x = Coord { x: x[0], y: x[1] };
                let d = norm(closest_on_segment(p, q, x).0 - x);
                if norm(x - p) > snap && norm(x - q) > snap && d <= snap && d > tol {
                    inserts.push(((k, r, i as u32), x));
                }
            }
        }
    }
    for (e, x) in inserts {
        edits.inserts.entry(e).or_default().push(x);
    }
}

/// Whether the interiors of `a` and of a polygon B (its boundary `b`, and
/// a point `probe` inside it) meet, found without an overlay: an edge of
/// `a` properly crosses one of B, a vertex of `a` or the middle of one of
/// its edges lies inside B farther than `tol` from ∂B, or the probe lies
/// inside `a`. (An edge of `a` that runs into B only through B's vertices
/// has them as its own vertices once snapped, so the middle of a piece of
/// it lies inside B.) False for polygons that only meet along their
/// boundaries: the units of a clean coverage and the polygon they
/// surround, reaches cut from one river.
pub fn interiors_meet(
    a: &MultiPolygon<f64>,
    b: &Boundary,
    probe: Option<Coord<f64>>,
    tol: f64,
) -> bool {
    contact(a, b, probe, tol) != Contact::Apart
}

/// How a polygon set A and a polygon B meet (see [`interiors_meet`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// Their interiors do not meet.
    Apart,
    /// B lies inside A, no vertex of A on ∂B (a lake inside a unit).
    Holds,
    /// A's boundary runs through B's interior.
    Crosses,
}

/// How `a` and B (its boundary `b`, a point `probe` inside it) meet: the
/// tests of [`interiors_meet`], telling a B wholly inside `a` apart.
pub fn contact(
    a: &MultiPolygon<f64>,
    b: &Boundary,
    probe: Option<Coord<f64>>,
    tol: f64,
) -> Contact {
    use geo::{BoundingRect, Contains};
    let (lo, hi) = (b.bbox_min(), b.bbox_max());
    let in_box = |c: Coord<f64>| {
        c.x >= lo.x - tol && c.x <= hi.x + tol && c.y >= lo.y - tol && c.y <= hi.y + tol
    };
    // Where a point is: 0 outside B, 1 on ∂B (within `tol`), 2 inside.
    let place = |c: Coord<f64>| -> u8 {
        if !in_box(c) {
            0
        } else if b.is_within(c, tol) {
            1
        } else {
            2 * u8::from(b.contains(c))
        }
    };
    // Whether a's boundary touches ∂B anywhere.
    let mut touches = false;
    for (_, _, r) in rings_of(a) {
        let mut at = r.0.first().map_or(0, |&c| place(c));
        for w in r.0.windows(2) {
            let (p, q) = (w[0], w[1]);
            let (at_p, at_q) = (at, place(q));
            at = at_q;
            touches |= at_p == 1;
            if at_p == 2 {
                return Contact::Crosses;
            }
            if p.x.max(q.x) < lo.x
                || p.x.min(q.x) > hi.x
                || p.y.max(q.y) < lo.y
                || p.y.min(q.y) > hi.y
            {
                continue;
            }
            // An edge between two points of ∂B runs inside or outside.
            if at_p == 1 && at_q == 1 && place((p + q) * 0.5) == 2 {
                return Contact::Crosses;
            }
            let crosses = b.segments_near(p, q).any(|i| {
                let s = &b.segments()[i];
                properly_cross(p, q, s.a, s.b)
            });
            if crosses {
                return Contact::Crosses;
            }
        }
    }
    let (Some(q), Some(r)) = (probe, a.bounding_rect()) else {
        return Contact::Apart;
    };
    let holds = r.min().x <= q.x
        && q.x <= r.max().x
        && r.min().y <= q.y
        && q.y <= r.max().y
        && a.contains(&geo::Point(q));
    match (holds, touches) {
        (true, false) => Contact::Holds,
        // B inside `a` with their boundaries touching: the overlay nodes
        // them.
        (true, true) => Contact::Crosses,
        (false, _) => Contact::Apart,
    }
}

/// `a` less a polygon `b` that lies inside it, its boundary apart from
/// `a`'s ([`Contact::Holds`]): `b`'s exterior a new hole of the part of
/// `a` that holds it, `b`'s holes (islands) new parts.
pub fn with_hole(a: &MultiPolygon<f64>, b: &Polygon<f64>, probe: Coord<f64>) -> Vec<Polygon<f64>> {
    use geo::Contains;
    let mut out = a.0.clone();
    if let Some(k) = out.iter().position(|q| q.contains(&geo::Point(probe))) {
        let mut holes = out[k].interiors().to_vec();
        holes.push(b.exterior().clone());
        out[k] = Polygon::new(out[k].exterior().clone(), holes);
    }
    out.extend(
        b.interiors()
            .iter()
            .map(|r| Polygon::new(r.clone(), Vec::new())),
    );
    out
}

/// The vertices of a polygon's rings as points of an R-tree.
pub fn vertex_index(p: &Polygon<f64>) -> RTree<[f64; 2]> {
    let mut pts: Vec<[f64; 2]> = std::iter::once(p.exterior())
        .chain(p.interiors())
        .flat_map(|r| r.0.iter().map(|c| [c.x, c.y]))
        .collect();
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    RTree::bulk_load(pts)
}

/// A polygon set cut by another: what lies outside it and what inside.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overlay {
    /// A − B.
    pub outside: Vec<Polygon<f64>>,
    /// A ∩ B.
    pub inside: Vec<Polygon<f64>>,
}

/// Where two segments cross, computed the same whichever way round either
/// is given and whichever is given first (two units sharing an edge get
/// one point where it crosses B).
fn canonical_crossing(p: Coord<f64>, q: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> Coord<f64> {
    let lt = |u: Coord<f64>, v: Coord<f64>| (u.x, u.y) < (v.x, v.y);
    let (p, q) = if lt(q, p) { (q, p) } else { (p, q) };
    let (a, b) = if lt(b, a) { (b, a) } else { (a, b) };
    if lt(a, p) || (a == p && lt(b, q)) {
        crossing_point(a, b, p, q)
    } else {
        crossing_point(p, q, a, b)
    }
}

/// Normalised rings (exterior counter-clockwise, holes clockwise) of the
/// polygons of `m` that have area.
fn normalised_rings(m: &[Polygon<f64>]) -> Vec<Vec<Coord<f64>>> {
    m.iter()
        .filter_map(|p| normalise_polygon(p).ok())
        .flat_map(|p| {
            std::iter::once(p.exterior().0.clone())
                .chain(p.interiors().iter().map(|r| r.0.clone()))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Points to put into segments, by segment number.
type SegmentInserts = FxHashMap<usize, Vec<Coord<f64>>>;

/// A segment's box in an R-tree, with the segment's number.
type Boxed = GeomWithData<Rectangle<[f64; 2]>, usize>;

fn boxed(segs: &[(Coord<f64>, Coord<f64>)]) -> RTree<Boxed> {
    RTree::bulk_load(
        segs.iter()
            .enumerate()
            .map(|(i, &(a, b))| {
                GeomWithData::new(Rectangle::from_corners([a.x, a.y], [b.x, b.y]), i)
            })
            .collect(),
    )
}

/// The segments of closed rings, each with its ring and place.
fn segments(rings: &[Vec<Coord<f64>>]) -> Vec<(Coord<f64>, Coord<f64>)> {
    rings
        .iter()
        .flat_map(|r| r.windows(2).map(|w| (w[0], w[1])))
        .collect()
}

/// The rings with the points of `inserts` (by segment number, as
/// [`segments`] numbers them) put in, repeated points dropped.
fn noded(
    rings: &[Vec<Coord<f64>>],
    inserts: &FxHashMap<usize, Vec<Coord<f64>>>,
) -> Vec<Vec<Coord<f64>>> {
    let mut n = 0;
    rings
        .iter()
        .map(|r| {
            let mut out = Vec::with_capacity(r.len());
            for w in r.windows(2) {
                out.push(w[0]);
                if let Some(extra) = inserts.get(&n) {
                    out.extend(inner_points_along(w[0], w[1], extra));
                }
                n += 1;
            }
            out.push(r[r.len() - 1]);
            out.dedup();
            out
        })
        .collect()
}

/// Puts into the segments of `a` and `b` every point where one of each
/// crosses the other, and every end of one within `tol` of the other
/// (farther than `tol` from its ends).
fn node_pair(
    a: &[(Coord<f64>, Coord<f64>)],
    b: &[(Coord<f64>, Coord<f64>)],
    tol: f64,
) -> (SegmentInserts, SegmentInserts) {
    let tree = boxed(b);
    let mut into_a = SegmentInserts::default();
    let mut into_b = SegmentInserts::default();
    let near = |e: Coord<f64>, s: (Coord<f64>, Coord<f64>)| {
        e != s.0
            && e != s.1
            && norm(e - s.0) > tol
            && norm(e - s.1) > tol
            && norm(closest_on_segment(s.0, s.1, e).0 - e) <= tol
    };
    for (i, &(p, q)) in a.iter().enumerate() {
        let env = AABB::from_corners(
            [p.x.min(q.x) - tol, p.y.min(q.y) - tol],
            [p.x.max(q.x) + tol, p.y.max(q.y) + tol],
        );
        for hit in tree.locate_in_envelope_intersecting(&env) {
            let j = hit.data;
            let (c, d) = b[j];
            for e in [p, q] {
                if near(e, (c, d)) {
                    into_b.entry(j).or_default().push(e);
                }
            }
            for e in [c, d] {
                if near(e, (p, q)) {
                    into_a.entry(i).or_default().push(e);
                }
            }
            if properly_cross(p, q, c, d) {
                let x = canonical_crossing(p, q, c, d);
                if [p, q, c, d].iter().all(|&e| norm(x - e) > tol) {
                    into_a.entry(i).or_default().push(x);
                    into_b.entry(j).or_default().push(x);
                }
            }
        }
    }
    (into_a, into_b)
}

/// `a` cut by `b` (see the module documentation); `a`'s vertices within
/// `tol` of `b`'s edges (and the other way round) count as on them. Both
/// are taken as they are: snap first for a wider tolerance.
pub fn overlay(a: &[Polygon<f64>], b: &Polygon<f64>, tol: f64) -> Overlay {
    let ar = normalised_rings(a);
    let br = normalised_rings(std::slice::from_ref(b));
    if ar.is_empty() {
        return Overlay::default();
    }
    let (into_a, into_b) = node_pair(&segments(&ar), &segments(&br), tol);
    let (ar, br) = (noded(&ar, &into_a), noded(&br, &into_b));
    let (ae, be) = (segments(&ar), segments(&br));
    let a_bound = Boundary::from_rings(
        ar.iter()
            .map(|r| LineString(r.clone()))
            .collect::<Vec<_>>()
            .iter(),
    );
    let b_bound = Boundary::from_rings(
        br.iter()
            .map(|r| LineString(r.clone()))
            .collect::<Vec<_>>()
            .iter(),
    );
    let set = |e: &[(Coord<f64>, Coord<f64>)]| -> FxHashSet<(Key, Key)> {
        e.iter().map(|&(p, q)| (key(p), key(q))).collect()
    };
    let (a_set, b_set) = (set(&ae), set(&be));
    let mid = |p: Coord<f64>, q: Coord<f64>| (p + q) * 0.5;
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for &(p, q) in &ae {
        if p == q {
            continue;
        }
        if b_set.contains(&(key(p), key(q))) {
            inside.push((p, q));
        } else if b_set.contains(&(key(q), key(p))) || !b_bound.contains(mid(p, q)) {
            outside.push((p, q));
        } else {
            inside.push((p, q));
        }
    }
    for &(p, q) in &be {
        if p == q || a_set.contains(&(key(p), key(q))) || a_set.contains(&(key(q), key(p))) {
            continue;
        }
        if a_bound.contains(mid(p, q)) {
            inside.push((p, q));
            outside.push((q, p));
        }
    }
    Overlay {
        outside: polygons_of_edges(&outside),
        inside: polygons_of_edges(&inside),
    }
}

/// The union of `plus` minus `minus`, exactly: every polygon's edges noded
/// at the vertices of all the others within `tol`, the edges of `plus` and
/// the reversed edges of `minus` counted, an edge met both ways
/// cancelling, the rest walked into polygons. For pieces that share their
/// edges (a unit, what it held of a collapsed polygon, what it was given):
/// no vertex moves.
pub fn signed_union(plus: &[Polygon<f64>], minus: &[Polygon<f64>], tol: f64) -> Vec<Polygon<f64>> {
    let pr = normalised_rings(plus);
    let mr = normalised_rings(minus);
    let mut pts: Vec<[f64; 2]> = pr
        .iter()
        .chain(&mr)
        .flat_map(|r| r.iter().map(|c| [c.x, c.y]))
        .collect();
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    let index = RTree::bulk_load(pts);
    let node = |rings: &[Vec<Coord<f64>>]| -> Vec<Vec<Coord<f64>>> {
        let segs = segments(rings);
        let mut inserts: FxHashMap<usize, Vec<Coord<f64>>> = FxHashMap::default();
        for (i, &(p, q)) in segs.iter().enumerate() {
            let env = AABB::from_corners(
                [p.x.min(q.x) - tol, p.y.min(q.y) - tol],
                [p.x.max(q.x) + tol, p.y.max(q.y) + tol],
            );
            for x in index.locate_in_envelope(&env) {
                let x = Coord { x: x[0], y: x[1] };
                // Not a point near an end (it would go in on the wrong side
                // of it): such a point is a vertex of its own.
                if norm(x - p) > tol
                    && norm(x - q) > tol
                    && norm(closest_on_segment(p, q, x).0 - x) <= tol
                {
                    inserts.entry(i).or_default().push(x);
                }
            }
        }
        noded(rings, &inserts)
    };
    let mut edges = segments(&node(&pr));
    edges.extend(segments(&node(&mr)).into_iter().map(|(p, q)| (q, p)));
    polygons_of_edges(&edges)
}

/// The area of polygons.
pub fn area(ps: &[Polygon<f64>]) -> f64 {
    // + 0: an empty sum is −0.
    ps.iter().map(|p| p.unsigned_area()).sum::<f64>() + 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    fn square(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon<f64> {
        polygon![(x: x0, y: y0), (x: x1, y: y0), (x: x1, y: y1), (x: x0, y: y1)]
    }

    #[test]
    fn a_unit_over_half_a_lake_is_cut_along_the_shore() {
        let unit = square(0., 0., 10., 10.);
        let lake = square(5., 2., 15., 8.);
        let o = overlay(&[unit], &lake, 1e-9);
        assert!((area(&o.outside) - 70.0).abs() < 1e-9, "{o:?}");
        assert!((area(&o.inside) - 30.0).abs() < 1e-9, "{o:?}");
        // Put together again: the unit.
        let back = signed_union(&o.outside, &[], 1e-9);
        let whole = signed_union(&[back, o.inside].concat(), &[], 1e-9);
        assert_eq!(whole.len(), 1);
        assert!((whole[0].unsigned_area() - 100.0).abs() < 1e-9);
        // The unit's four corners and the two crossings, kept.
        assert_eq!(whole[0].exterior().0.len(), 7, "{whole:?}");
    }

    #[test]
    fn collinear_sides_overlap_too() {
        // The unit covers the lake with sides along its sides.
        let unit = square(0., 0., 10., 10.);
        let lake = square(0., 0., 10., 3.);
        let o = overlay(&[unit], &lake, 1e-9);
        assert!((area(&o.inside) - 30.0).abs() < 1e-9, "{o:?}");
        assert!((area(&o.outside) - 70.0).abs() < 1e-9, "{o:?}");
    }

    #[test]
    fn a_unit_that_only_touches_holds_nothing() {
        let unit = square(0., 0., 10., 10.);
        let lake = square(10., 2., 15., 8.);
        let o = overlay(std::slice::from_ref(&unit), &lake, 1e-9);
        assert!(o.inside.is_empty(), "{o:?}");
        assert!((area(&o.outside) - 100.0).abs() < 1e-9);
    }

    #[test]
    fn a_lake_inside_a_unit_becomes_its_hole() {
        let unit = square(0., 0., 10., 10.);
        let lake = square(2., 2., 4., 4.);
        let o = overlay(&[unit], &lake, 1e-9);
        assert_eq!(o.outside.len(), 1);
        assert_eq!(o.outside[0].interiors().len(), 1);
        assert!((area(&o.inside) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn a_snap_closes_a_gap_and_moves_a_sliver_onto_the_bank() {
        // The unit's side at x = 10.0000001, the lake's at x = 10, with a
        // vertex of the lake at y = 5 that the unit lacks.
        let unit = square(10.0000001, 0., 20., 10.);
        let lake = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 5.), (x: 10., y: 10.), (x: 0., y: 10.)];
        let um = MultiPolygon(vec![unit]);
        let b = Boundary::new(&lake);
        let mut edits = Edits::default();
        let mut into_b = Vec::new();
        snap_vertices(&um, &b, (1e-6, 1e-12), &mut edits, &mut into_b);
        assert!(into_b.is_empty());
        snap_edges(&um, &vertex_index(&lake), (1e-6, 1e-12), &mut edits);
        let snapped = edits.apply(&um);
        // The unit's corners move onto the lake's; the lake's vertex at
        // y = 5 now lies on the unit's side exactly, and the overlay nodes it.
        let ring = &snapped.0[0].exterior().0;
        assert!(ring.contains(&Coord { x: 10., y: 10. }), "{ring:?}");
        assert!(ring.contains(&Coord { x: 10., y: 0. }), "{ring:?}");
        let o = overlay(&snapped.0, &lake, 1e-9);
        assert!(o.inside.is_empty(), "{o:?}");
    }

    #[test]
    fn two_units_sharing_an_edge_get_one_crossing_point() {
        let p = Coord { x: 0.1, y: 0.3 };
        let q = Coord { x: 7.3, y: 9.1 };
        let a = Coord { x: 0.0, y: 5.7 };
        let b = Coord { x: 8.9, y: 1.3 };
        let x = canonical_crossing(p, q, a, b);
        assert_eq!(x, canonical_crossing(q, p, a, b));
        assert_eq!(x, canonical_crossing(a, b, q, p));
        assert_eq!(x, canonical_crossing(b, a, p, q));
    }
}
