//! Roundabouts made one node (`prune: { roundabouts: D }`): the medial
//! axis of street space rings every island, a roundabout's as well as a
//! city block's. A street network at a smaller scale shows a roundabout as
//! one junction; a block stays a ring of streets. The rule tells them apart
//! by the size the user gives: an island (a hole of the polygon) no wider
//! than `D` (CRS units; its diameter, the largest distance between two of
//! its vertices) is a roundabout's.
//!
//! The ring around such an island is the boundary of the face of the
//! skeleton (a plane graph) that holds the island: walked from the first
//! line a ray from the island's centre meets, turning at each node into
//! the next branch clockwise from the one it came by (so the face stays on
//! the left), without the branches walked both ways (legs hanging into the
//! face). The face must hold this island and no other. Then the ring goes,
//! a new node takes the island's centre (its centroid, or a point inside
//! it when the centroid falls outside a crescent), and every other branch
//! that met the ring runs straight into that node from where it leaves the
//! ring's neighbourhood (after its last point within [`STRAIGHT_FROM`]
//! times the ring's distance from the centre). The node's degree is the
//! number of roads that meet the roundabout; a turning circle at a dead end
//! (one road) ends that road at the circle's centre. The straight lines
//! cross the island, which is not street space: that is what one node
//! means. Two islands whose rings share a branch (a double roundabout)
//! are two nodes joined by a straight link, each road meeting the nearer.
//! An island that no face of the lines holds alone is left as it is, and so
//! is every island wider than `D`.

use super::{Branch, GraphBuilder, NodeId, SkeletonGraph};
use crate::geometry::PreparedPolygon;
use geo::{Centroid, Contains, Coord, InteriorPoint, LineString, Polygon};

/// A branch that met the ring runs straight to the centre from after its
/// last point within this many times the ring's distance from the centre.
pub const STRAIGHT_FROM: f64 = 1.25;

/// Most vertices measured pair by pair for an island's diameter (an island
/// of more: its convex hull's vertices; a hull of more: the diagonal of its
/// bounding box).
const MAX_PAIRS: usize = 2048;

/// `g` with the ring around every island of `polygon` no wider than `max`
/// replaced by one node at the island's centre (see the module
/// documentation); `g` itself when there is none.
pub fn roundabouts(g: &SkeletonGraph, polygon: &PreparedPolygon, max: f64) -> SkeletonGraph {
    if max.is_nan() || max <= 0.0 || g.is_empty() {
        return g.clone();
    }
    let holes = polygon.polygon().interiors();
    let centres: Vec<Option<Coord<f64>>> = holes
        .iter()
        .map(|h| (diameter(h) <= max).then(|| centre(h)).flatten())
        .collect();
    if centres.iter().all(Option::is_none) {
        return g.clone();
    }
    let branches = g.branches();
    let ring_of = rings(&branches, holes, &centres);
    if ring_of.iter().all(Vec::is_empty) {
        return g.clone();
    }
    // The centre a node of a ring is replaced by: the nearest of the
    // rings' it is on.
    let mut hub: Vec<Option<Coord<f64>>> = vec![None; g.nodes().len()];
    for (br, cs) in branches.iter().zip(&ring_of) {
        for &c in cs {
            for n in [br.start, br.end] {
                let at = g.node(n).pos;
                let d = |q: Coord<f64>| (q.x - at.x).hypot(q.y - at.y);
                if hub[n.index()].is_none_or(|h| d(c) < d(h)) {
                    hub[n.index()] = Some(c);
                }
            }
        }
    }
    let mut b = GraphBuilder::new();
    for (br, cs) in branches.iter().zip(&ring_of) {
        match cs.as_slice() {
            // Between two islands (a double roundabout): a link between
            // their nodes.
            [c1, c2] => {
                b.segment(*c1, *c2);
            }
            [_, ..] => {}
            [] => {
                let mut coords = br.coords.clone();
                if let Some(c) = hub[br.start.index()] {
                    coords = into_centre(&coords, c);
                }
                if let Some(c) = hub[br.end.index()] {
                    coords.reverse();
                    coords = into_centre(&coords, c);
                    coords.reverse();
                }
                b.path(&coords);
            }
        }
    }
    b.finish(polygon.boundary())
}

/// For each branch, the centres of the islands (`holes` with a `centres`
/// entry) whose ring it is on: the boundary of the face holding the island
/// and no other.
fn rings(
    branches: &[Branch],
    holes: &[LineString<f64>],
    centres: &[Option<Coord<f64>>],
) -> Vec<Vec<Coord<f64>>> {
    let out = leaving(branches);
    let mut ring_of: Vec<Vec<Coord<f64>>> = vec![Vec::new(); branches.len()];
    for (k, c) in centres.iter().enumerate() {
        let Some(c) = *c else { continue };
        let Some(ring) = face_around(branches, &out, c) else {
            continue;
        };
        let others = holes
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != k)
            .any(|(_, h)| ring.outline.contains(&h.0[0]));
        if ring.outline.contains(&c) && !others {
            for &b in &ring.branches {
                ring_of[b].push(c);
            }
        }
    }
    ring_of
}

/// The centre of an island: its centroid, or a point inside it when the
/// centroid is not.
fn centre(island: &LineString<f64>) -> Option<Coord<f64>> {
    let hole = Polygon::new(island.clone(), vec![]);
    hole.centroid()
        .filter(|c| hole.contains(c))
        .or_else(|| hole.interior_point())
        .map(|p| p.0)
}

/// The largest distance between two vertices of `ring` (above
/// [`MAX_PAIRS`] vertices, between two of its convex hull's; a hull of
/// more: the diagonal of its bounding box).
fn diameter(ring: &LineString<f64>) -> f64 {
    use geo::{BoundingRect, ConvexHull};
    let pairs = |pts: &[Coord<f64>]| {
        let mut d2: f64 = 0.0;
        for (i, a) in pts.iter().enumerate() {
            for q in &pts[i + 1..] {
                d2 = d2.max((a.x - q.x).powi(2) + (a.y - q.y).powi(2));
            }
        }
        d2.sqrt()
    };
    if ring.0.len() <= MAX_PAIRS {
        return pairs(&ring.0);
    }
    let hull = ring.convex_hull();
    if hull.exterior().0.len() <= MAX_PAIRS {
        return pairs(&hull.exterior().0);
    }
    ring.bounding_rect()
        .map_or(0.0, |r| r.width().hypot(r.height()))
}

/// A face's boundary: the branches walked one way only, and its outline.
struct Face {
    branches: Vec<usize>,
    outline: Polygon<f64>,
}

/// One way along a branch: its index and whether from its start.
type Half = (usize, bool);

/// The half-edges leaving each node of the plane graph `branches`, with
/// their directions.
type Leaving = std::collections::HashMap<NodeId, Vec<(Half, f64)>>;

fn leaving(branches: &[Branch]) -> Leaving {
    let mut out = Leaving::default();
    let angle = |p: Coord<f64>, q: Coord<f64>| (q.y - p.y).atan2(q.x - p.x);
    for (k, b) in branches.iter().enumerate() {
        let n = b.coords.len();
        if n < 2 {
            continue;
        }
        out.entry(b.start)
            .or_default()
            .push(((k, true), angle(b.coords[0], b.coords[1])));
        out.entry(b.end)
            .or_default()
            .push(((k, false), angle(b.coords[n - 1], b.coords[n - 2])));
    }
    out
}

/// The boundary of the face of the plane graph `branches` (leaving its
/// nodes as `out` says) that holds `c` (see the module documentation);
/// `None` when no branch lies east of `c` or the walk does not close.
fn face_around(branches: &[Branch], out: &Leaving, c: Coord<f64>) -> Option<Face> {
    let first = first_east(branches, c)?;
    let end_of = |(k, fwd): Half| {
        if fwd {
            branches[k].end
        } else {
            branches[k].start
        }
    };
    let mut walked: Vec<Half> = vec![first];
    let mut at = first;
    for _ in 0..=2 * branches.len() {
        let back: Half = (at.0, !at.1);
        let node = end_of(at);
        let leaving = out.get(&node)?;
        let back_angle = leaving.iter().find(|(h, _)| *h == back)?.1;
        let tau = std::f64::consts::TAU;
        // The next half-edge clockwise from the way back (the way back
        // itself only at a dead end).
        let next = leaving
            .iter()
            .filter(|(h, _)| *h != back || leaving.len() == 1)
            .min_by(|a, b| {
                let cw = |x: f64| (back_angle - x).rem_euclid(tau);
                cw(a.1).total_cmp(&cw(b.1))
            })?
            .0;
        if next == first {
            return Some(face(branches, &walked));
        }
        walked.push(next);
        at = next;
    }
    None
}

/// The half-edge of the branch nearest to `c` due east of it, oriented so
/// that `c` lies on its left.
fn first_east(branches: &[Branch], c: Coord<f64>) -> Option<Half> {
    let mut best: Option<(f64, Half)> = None;
    for (k, b) in branches.iter().enumerate() {
        for w in b.coords.windows(2) {
            let (p, q) = (w[0], w[1]);
            if (p.y > c.y) == (q.y > c.y) {
                continue;
            }
            let x = p.x + (c.y - p.y) / (q.y - p.y) * (q.x - p.x);
            if x > c.x && best.is_none_or(|(bx, _)| x < bx) {
                best = Some((x, (k, q.y > p.y)));
            }
        }
    }
    best.map(|(_, h)| h)
}

/// The face from its walk: the branches walked one way only, and the
/// outline of the whole walk.
fn face(branches: &[Branch], walked: &[Half]) -> Face {
    let mut outline: Vec<Coord<f64>> = Vec::new();
    for &(k, fwd) in walked {
        let c = &branches[k].coords;
        if fwd {
            outline.extend_from_slice(c);
        } else {
            outline.extend(c.iter().rev());
        }
    }
    let once = walked
        .iter()
        .filter(|&&(k, fwd)| !walked.contains(&(k, !fwd)))
        .map(|&(k, _)| k)
        .collect();
    Face {
        branches: once,
        outline: Polygon::new(LineString(outline), vec![]),
    }
}

/// `coords` (starting on a ring) starting at `centre` instead, straight to
/// the point after its last one within [`STRAIGHT_FROM`] times the ring's
/// distance from the centre (its last point when none is beyond).
fn into_centre(coords: &[Coord<f64>], centre: Coord<f64>) -> Vec<Coord<f64>> {
    let d = |p: Coord<f64>| (p.x - centre.x).hypot(p.y - centre.y);
    let reach = STRAIGHT_FROM * d(coords[0]);
    let from = coords
        .iter()
        .rposition(|&p| d(p) <= reach)
        .map_or(1, |i| i + 1)
        .min(coords.len() - 1);
    let mut out = Vec::with_capacity(coords.len() - from + 1);
    out.push(centre);
    out.extend_from_slice(&coords[from..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// Street space with a roundabout: a ring road 20 wide around a round
    /// island of radius `island` (centre at the origin), and `arms` roads
    /// 16 wide leaving it east, north, west and south (the first `arms` of
    /// them) to 150 from the centre, with round ends (to 158). Its medial axis pruned and extended, as the pipeline's
    /// defaults make it.
    fn roundabout(island: f64, arms: usize) -> (PreparedPolygon, SkeletonGraph) {
        use geo::{BooleanOps, Buffer};
        let r = island + 10.0;
        let ring = geo::Point::new(0.0, 0.0).buffer(r + 10.0);
        let mut space = ring.difference(&geo::Point::new(0.0, 0.0).buffer(island));
        let ends = [c(150., 0.), c(0., 150.), c(-150., 0.), c(0., -150.)];
        for e in ends.iter().take(arms) {
            let road = geo::LineString::from(vec![c(0., 0.), *e]).buffer(8.0);
            space = space.union(&road.difference(&geo::Point::new(0.0, 0.0).buffer(r)));
        }
        axis(&space)
    }

    /// The medial axis of `space`, pruned and extended as the pipeline's
    /// defaults make it.
    fn axis(space: &geo::MultiPolygon<f64>) -> (PreparedPolygon, SkeletonGraph) {
        assert_eq!(space.0.len(), 1);
        let p = PreparedPolygon::new(&space.0[0]).unwrap();
        let raw = crate::methods::build(
            crate::methods::MethodId::MA,
            &crate::methods::SkeletonParams::default(),
        )
        .skeletonise(&p, &crate::methods::MethodContext::default())
        .unwrap();
        let g = crate::graph::extend::prune_and_extend(
            &raw,
            &p,
            Some(&crate::graph::prune::PruneParams::default()),
            Some(&crate::graph::extend::ExtendParams::default()),
        );
        (p, g)
    }

    #[test]
    fn a_double_roundabout_is_two_nodes_joined_by_a_straight_link() {
        // Two islands of radius 8 at (±15, 0), each ringed by a road 12
        // wide, the rings run together between them; a road 12 wide leaves
        // each west or east and north.
        use geo::{BooleanOps, Buffer};
        let o = |x: f64| geo::Point::new(x, 0.0);
        let mut space = o(-15.).buffer(20.0).union(&o(15.).buffer(20.0));
        for (a, b) in [
            (c(-15., 0.), c(-150., 0.)),
            (c(15., 0.), c(150., 0.)),
            (c(-15., 0.), c(-15., 150.)),
            (c(15., 0.), c(15., 150.)),
        ] {
            space = space.union(&geo::LineString::from(vec![a, b]).buffer(6.0));
        }
        space = space.difference(&o(-15.).buffer(8.0).union(&o(15.).buffer(8.0)));
        let (p, g) = axis(&space);
        let two = roundabouts(&g, &p, 20.0);
        two.check_invariants().unwrap();
        let n = nodes(&two);
        let hubs: Vec<_> = n.iter().filter(|(_, d)| *d >= 3).collect();
        assert_eq!(hubs.len(), 2, "{n:?}");
        for (q, d) in hubs {
            assert_eq!(*d, 3, "{n:?}");
            assert!((q.x.abs() - 15.0).abs() < 0.5 && q.y.abs() < 0.5, "{n:?}");
        }
        assert_eq!(n.iter().filter(|(_, d)| *d == 1).count(), 4, "{n:?}");
        // The link and the four roads, straight from the centres to their
        // rounded ends (at x = ±156 west and east, y = 156 north).
        let want = 30.0 + 2.0 * 141.0 + 2.0 * 156.0;
        assert!(
            (two.total_length() - want).abs() < 1e-3,
            "{}",
            two.total_length()
        );
    }

    /// The nodes of `g` with their degrees, leaves and junctions only.
    fn nodes(g: &SkeletonGraph) -> Vec<(Coord<f64>, usize)> {
        let deg = g.degrees();
        g.nodes()
            .iter()
            .zip(deg)
            .filter(|(_, d)| *d != 2)
            .map(|(n, d)| (n.pos, d))
            .collect()
    }

    #[test]
    fn a_small_island_ringed_by_the_lines_becomes_one_node_with_straight_roads() {
        let (p, g) = roundabout(12.0, 4);
        // The medial axis rings the island: four three-way junctions.
        assert_eq!(
            nodes(&g).iter().filter(|(_, d)| *d == 3).count(),
            4,
            "{:?}",
            nodes(&g)
        );
        let one = roundabouts(&g, &p, 30.0);
        one.check_invariants().unwrap();
        // One four-way node at the island's centre, four ends, nothing else;
        // each road straight from the centre to its rounded end.
        let n = nodes(&one);
        let hubs: Vec<_> = n.iter().filter(|(_, d)| *d >= 3).collect();
        assert_eq!(hubs.len(), 1, "{n:?}");
        assert_eq!(hubs[0].1, 4);
        assert!(hubs[0].0.x.hypot(hubs[0].0.y) < 0.5, "{n:?}");
        assert_eq!(n.iter().filter(|(_, d)| *d == 1).count(), 4, "{n:?}");
        assert!(
            (one.total_length() - 4.0 * 158.0).abs() < 1e-3,
            "{}",
            one.total_length()
        );
        // An island wider than the size given stays ringed (a block), and
        // 0 leaves every ring.
        assert_eq!(roundabouts(&g, &p, 20.0), g);
        assert_eq!(roundabouts(&g, &p, 0.0), g);
    }

    #[test]
    fn a_turning_circle_ends_its_road_at_the_centre() {
        let (p, g) = roundabout(6.0, 1);
        let one = roundabouts(&g, &p, 15.0);
        one.check_invariants().unwrap();
        let n = nodes(&one);
        assert_eq!(n.len(), 2, "{n:?}");
        assert!(
            n.iter().any(|(q, d)| *d == 1 && q.x.hypot(q.y) < 0.5),
            "{n:?}"
        );
        assert!(
            (one.total_length() - 158.0).abs() < 1e-3,
            "{}",
            one.total_length()
        );
    }

    #[test]
    fn a_negative_or_unbounded_size_is_refused_naming_the_key() {
        use crate::graph::prune::PruneParams;
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let p = PruneParams {
                roundabouts: bad,
                ..PruneParams::default()
            };
            assert_eq!(p.validate().unwrap_err().0, "roundabouts");
        }
        let ok = PruneParams {
            roundabouts: 30.0,
            ..PruneParams::default()
        };
        assert!(ok.validate().is_ok());
    }

    #[test]
    fn the_diameter_is_the_largest_distance_between_two_vertices() {
        let sq = LineString::from(vec![(0., 0.), (3., 0.), (3., 4.), (0., 4.), (0., 0.)]);
        assert_eq!(diameter(&sq), 5.0);
        // A densely digitised island: its hull's vertices, pair by pair
        // (a circle's bounding box would say √2 times more); a hull of too
        // many vertices, its bounding box.
        let circle = |n: usize| {
            LineString::from(
                (0..=n)
                    .map(|i| {
                        let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
                        (10.0 * a.cos(), 10.0 * a.sin())
                    })
                    .collect::<Vec<_>>(),
            )
        };
        let mut teeth = circle(1000).0;
        teeth.extend(circle(4000).0.iter().map(|p| Coord {
            x: p.x * 0.5,
            y: p.y * 0.5,
        }));
        teeth.push(teeth[0]);
        assert!((diameter(&LineString(teeth)) - 20.0).abs() < 1e-6);
        assert!((diameter(&circle(5000)) - 20.0 * 2f64.sqrt()).abs() < 1e-6);
    }
}
