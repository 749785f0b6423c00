//! A polygon split exactly by chords: the faces of the planar graph of its
//! rings and of polylines that run through its interior from boundary to
//! boundary (the cuts of `collapse`, the new boundaries of a partition).
//!
//! Exact means: every vertex of the polygon keeps its coordinates bit for
//! bit; a chord's end is inserted into the ring edge it lies on (or is that
//! edge's vertex when it is within `1e-12 × extent` of it); a vertex where
//! two faces meet is one coordinate used by both, so the faces form a valid
//! coverage of the polygon (no gap, no overlap, the same vertices on both
//! sides of every shared edge).
//!
//! The faces are the cycles of half-edges with P on their left: at every
//! vertex the outgoing half-edges are sorted by angle, and a cycle leaves a
//! vertex by the first half-edge clockwise from the one it came in on.
//! Rings that touch at a vertex (OGC-valid) give cycles that pass that
//! vertex twice; they are split there, so every face is an OGC-valid
//! polygon: a shell and the holes inside it.

use super::tolerance::{SAME_POINT, VERTEX_SNAP};
use super::vector::{cross, norm};
use super::PreparedPolygon;
use crate::geometry::CoordKey;
use geo::{Coord, LineString, Polygon};
use rustc_hash::FxHashMap;

/// One face of a split polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The face as a polygon (shell counter-clockwise, holes clockwise).
    pub polygon: Polygon<f64>,
    /// The chords on its boundary (indices into the chords given), sorted,
    /// each once.
    pub chords: Vec<usize>,
}

/// A vertex of the arrangement.
type VertexId = u32;

/// A half-edge: from `from` to `to`; `chord` when it belongs to one,
/// `outside` when it is a ring edge walked against the ring (P on its
/// right).
#[derive(Debug, Clone, Copy)]
struct HalfEdge {
    from: VertexId,
    to: VertexId,
    chord: Option<u32>,
    outside: bool,
}

/// The planar graph of rings and chords.
struct Graph {
    pos: Vec<Coord<f64>>,
    ids: FxHashMap<CoordKey, VertexId>,
    half: Vec<HalfEdge>,
    /// The edges made, each once (a chord laid twice on the same points).
    made: rustc_hash::FxHashSet<(VertexId, VertexId)>,
}

impl Graph {
    fn vertex(&mut self, c: Coord<f64>) -> VertexId {
        let key = CoordKey::from(c);
        if let Some(&v) = self.ids.get(&key) {
            return v;
        }
        let v = self.pos.len() as VertexId;
        self.pos.push(c);
        self.ids.insert(key, v);
        v
    }

    /// Both half-edges of the edge `a`–`b` (nothing for a zero-length one).
    fn edge(&mut self, a: Coord<f64>, b: Coord<f64>, chord: Option<u32>, ring: bool) {
        let (u, v) = (self.vertex(a), self.vertex(b));
        if u == v || !self.made.insert((u.min(v), u.max(v))) {
            return;
        }
        self.half.push(HalfEdge {
            from: u,
            to: v,
            chord,
            outside: false,
        });
        self.half.push(HalfEdge {
            from: v,
            to: u,
            chord,
            outside: ring,
        });
    }
}

/// Where a chord's end meets ∂P: ring edge `(ring, index)` and the point
/// (exactly a vertex of the edge when within the tolerance of it).
fn attach(p: &PreparedPolygon, c: Coord<f64>) -> Option<((u32, u32), Coord<f64>)> {
    let b = p.boundary();
    let (_, i, d) = b.nearest(c)?;
    // Relative to the polygon's size, but never below what its coordinates
    // can resolve (a small polygon far from the origin).
    let resolution = 8.0 * f64::EPSILON * c.x.abs().max(c.y.abs());
    let tol = (SAME_POINT * p.extent()).max(resolution);
    if d > tol {
        return None;
    }
    let s = &b.segments()[i];
    let snap = (VERTEX_SNAP * p.extent()).max(resolution);
    let at = if norm(c - s.a) <= snap {
        s.a
    } else if norm(c - s.b) <= snap {
        s.b
    } else {
        c
    };
    Some(((s.ring, s.index), at))
}

/// Why a polygon could not be split.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplitError {
    /// A chord's end does not lie on the boundary.
    #[error("chord {0} does not end on the polygon's boundary")]
    Detached(usize),
}

/// The faces of `p` split by `chords` (see the module documentation).
/// Each chord is a polyline whose first and last points lie on ∂P (within
/// `1e-9 × extent`) and whose other points lie inside P; chords may share
/// points (exactly equal coordinates) but must not cross each other or ∂P.
pub fn split(p: &PreparedPolygon, chords: &[LineString<f64>]) -> Result<Vec<Face>, SplitError> {
    split_with(p, chords, false)
}

/// [`split`] by a network of chords: a chord may also end inside P, on a
/// point (exactly equal coordinates) where another chord passes or ends —
/// the junctions of a partition's boundaries. An end that is on neither
/// ∂P nor another chord is [`SplitError::Detached`].
pub fn split_network(
    p: &PreparedPolygon,
    chords: &[LineString<f64>],
) -> Result<Vec<Face>, SplitError> {
    split_with(p, chords, true)
}

fn split_with(
    p: &PreparedPolygon,
    chords: &[LineString<f64>],
    network: bool,
) -> Result<Vec<Face>, SplitError> {
    let rings: Vec<&LineString<f64>> = p.rings().collect();
    // Every point of every chord, for the ends that meet another chord.
    let mut on_chords: FxHashMap<CoordKey, u32> = FxHashMap::default();
    if network {
        for c in chords {
            for q in &c.0 {
                *on_chords.entry(CoordKey::from(q)).or_default() += 1;
            }
        }
    }
    // The points to insert into each ring edge, and the chords with their
    // ends moved onto ∂P exactly.
    let mut inserts: FxHashMap<(u32, u32), Vec<Coord<f64>>> = FxHashMap::default();
    let mut lines: Vec<Vec<Coord<f64>>> = Vec::with_capacity(chords.len());
    for (k, chord) in chords.iter().enumerate() {
        let mut pts = chord.0.clone();
        if pts.len() < 2 {
            lines.push(Vec::new());
            continue;
        }
        for end in [0, pts.len() - 1] {
            let q = pts[end];
            let shared = on_chords.get(&CoordKey::from(q)).is_some_and(|&n| n > 1);
            match attach(p, q) {
                Some((edge, at)) => {
                    pts[end] = at;
                    inserts.entry(edge).or_default().push(at);
                }
                None if shared => {}
                None => return Err(SplitError::Detached(k)),
            }
        }
        lines.push(pts);
    }
    let mut g = Graph {
        pos: Vec::new(),
        ids: FxHashMap::default(),
        half: Vec::new(),
        made: Default::default(),
    };
    for (r, ring) in rings.iter().enumerate() {
        for (i, w) in ring.0.windows(2).enumerate() {
            let mut pts = vec![w[0]];
            if let Some(extra) = inserts.get(&(r as u32, i as u32)) {
                pts.extend(super::segment::inner_points_along(w[0], w[1], extra));
            }
            pts.push(w[1]);
            pts.dedup();
            for s in pts.windows(2) {
                g.edge(s[0], s[1], None, true);
            }
        }
    }
    for (k, l) in lines.iter().enumerate() {
        for s in l.windows(2) {
            g.edge(s[0], s[1], Some(k as u32), false);
        }
    }
    Ok(faces(&g))
}

/// The union of polygons that form a coverage (no overlap; where two meet,
/// their edges have the same vertices): every edge two of them share is
/// dropped, and the rest is walked into rings, exactly — no vertex moves,
/// none is added. (River reaches cut from one river, a neighbour grown by
/// the pieces of a partition.)
pub fn coverage_union(polygons: &[Polygon<f64>]) -> Vec<Polygon<f64>> {
    let mut edges = Vec::new();
    for p in polygons {
        let p = super::ring::normalise_polygon(p).unwrap_or_else(|_| p.clone());
        for ring in std::iter::once(p.exterior()).chain(p.interiors()) {
            edges.extend(ring.0.windows(2).map(|w| (w[0], w[1])));
        }
    }
    polygons_of_edges(&edges)
}

/// The polygons bounded by directed edges (the area on each edge's left):
/// an edge met both ways is counted against its reverse and drops out where
/// they cancel; the rest is walked into rings, shells with their holes,
/// exactly — no vertex moves, none is added. The edges must be noded (two
/// edges meet only at shared end points).
pub fn polygons_of_edges(edges: &[(Coord<f64>, Coord<f64>)]) -> Vec<Polygon<f64>> {
    let mut g = Graph {
        pos: Vec::new(),
        ids: FxHashMap::default(),
        half: Vec::new(),
        made: Default::default(),
    };
    // Directed edges with their multiplicity: an edge met in both directions
    // is between two of the polygons.
    let mut count: FxHashMap<(VertexId, VertexId), i64> = FxHashMap::default();
    for &(a, b) in edges {
        let (u, v) = (g.vertex(a), g.vertex(b));
        if u != v {
            *count.entry((u, v)).or_default() += 1;
        }
    }
    let mut kept: Vec<(VertexId, VertexId)> = count
        .iter()
        .filter(|&(&(u, v), &n)| n > count.get(&(v, u)).copied().unwrap_or(0))
        .map(|(&e, _)| e)
        .collect();
    kept.sort_unstable();
    for (u, v) in kept {
        g.half.push(HalfEdge {
            from: u,
            to: v,
            chord: None,
            outside: false,
        });
    }
    faces(&g).into_iter().map(|f| f.polygon).collect()
}

/// The cycles of half-edges with P on their left, as faces.
fn faces(g: &Graph) -> Vec<Face> {
    let n = g.pos.len();
    // Outgoing half-edges of every vertex, counter-clockwise by angle.
    let mut out: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (h, e) in g.half.iter().enumerate() {
        out[e.from as usize].push(h as u32);
    }
    let dir = |h: u32| {
        let e = g.half[h as usize];
        g.pos[e.to as usize] - g.pos[e.from as usize]
    };
    for list in &mut out {
        list.sort_by(|&a, &b| angle_order(dir(a), dir(b)));
    }
    // The next half-edge of a cycle: at the end of `h`, the first outgoing
    // one clockwise from the way back (the twin, when there is one, is
    // skipped: it lies exactly on the way back).
    // None: no half-edge leaves the vertex (edges that do not close into
    // cycles; that open chain gives no face).
    let next = |h: u32| {
        let e = g.half[h as usize];
        let list = &out[e.to as usize];
        if list.is_empty() {
            return None;
        }
        let back = g.pos[e.from as usize] - g.pos[e.to as usize];
        let i = list.partition_point(|&x| angle_order(dir(x), back) == std::cmp::Ordering::Less);
        Some(list[(i + list.len() - 1) % list.len()])
    };
    let mut seen = vec![false; g.half.len()];
    let mut shells: Vec<Shell> = Vec::new();
    let mut holes: Vec<Hole> = Vec::new();
    for start in 0..g.half.len() as u32 {
        if seen[start as usize] {
            continue;
        }
        let mut cycle = Vec::new();
        let mut h = start;
        let mut outside = false;
        let mut open = false;
        while !seen[h as usize] {
            seen[h as usize] = true;
            outside |= g.half[h as usize].outside;
            cycle.push(h);
            match next(h) {
                Some(n) => h = n,
                None => {
                    open = true;
                    break;
                }
            }
        }
        if outside || open || h != start {
            continue;
        }
        for part in simple_cycles(g, &cycle) {
            match ring_of(g, &part) {
                Ring::Shell(shell) => shells.push(shell),
                Ring::Hole(hole) => holes.push(hole),
            }
        }
    }
    assemble(shells, holes)
}

/// A simple cycle of half-edges as the shell of a face or as a hole.
enum Ring {
    Shell(Shell),
    Hole(Hole),
}

/// A simple cycle of half-edges with P on its left: a shell when it turns
/// counter-clockwise, else a hole of the face around it.
fn ring_of(g: &Graph, part: &[u32]) -> Ring {
    let coords: Vec<Coord<f64>> = part
        .iter()
        .map(|&h| g.pos[g.half[h as usize].from as usize])
        .collect();
    let chords = part
        .iter()
        .filter_map(|&h| g.half[h as usize].chord)
        .collect();
    if signed_area(&coords) > 0.0 {
        let edges = part
            .iter()
            .map(|&h| (g.half[h as usize].from, g.half[h as usize].to))
            .collect();
        return Ring::Shell(Shell {
            coords,
            chords,
            edges,
        });
    }
    // A hole of the face: a ring, or rings joined by chords. It is placed by
    // the middle of a ring edge, which no other face has on its boundary; a
    // hole of chords alone (a loop of boundaries around an island) by the
    // middle of a chord, which the face inside the loop has on its boundary
    // too.
    let ring_edge = part
        .iter()
        .copied()
        .find(|&h| g.half[h as usize].chord.is_none());
    let e = g.half[ring_edge.unwrap_or(part[0]) as usize];
    let probe = (g.pos[e.from as usize] + g.pos[e.to as usize]) * 0.5;
    Ring::Hole(Hole {
        coords,
        chords,
        probe,
        on_chord: ring_edge.is_none().then_some((e.from, e.to)),
    })
}

/// A cycle with P on its left that turns clockwise: a hole of the face
/// around it.
struct Hole {
    coords: Vec<Coord<f64>>,
    chords: Vec<u32>,
    /// A point on it that lies on no other face's boundary, or (a hole of
    /// chords alone) on that of the face inside it only.
    probe: Coord<f64>,
    /// The half-edge the probe is on, when it is a chord's.
    on_chord: Option<(VertexId, VertexId)>,
}

/// A cycle with P on its left that turns counter-clockwise: the shell of a
/// face, its chords and its half-edges.
struct Shell {
    coords: Vec<Coord<f64>>,
    chords: Vec<u32>,
    edges: rustc_hash::FxHashSet<(VertexId, VertexId)>,
}

/// A cycle of half-edges split at the vertices it passes more than once
/// (rings touching at a point), into cycles that pass each vertex once.
fn simple_cycles(g: &Graph, cycle: &[u32]) -> Vec<Vec<u32>> {
    let mut at: FxHashMap<VertexId, usize> = FxHashMap::default();
    let mut stack: Vec<u32> = Vec::with_capacity(cycle.len());
    let mut out = Vec::new();
    for &h in cycle {
        let from = g.half[h as usize].from;
        if let Some(&i) = at.get(&from) {
            // The loop since the last visit of `from` closes here.
            let part: Vec<u32> = stack.drain(i..).collect();
            for &x in &part {
                at.remove(&g.half[x as usize].from);
            }
            out.push(part);
        }
        at.insert(from, stack.len());
        stack.push(h);
    }
    if !stack.is_empty() {
        out.push(stack);
    }
    out
}

/// Shells with the holes that lie in them (each hole in the smallest shell
/// that contains it).
fn assemble(shells: Vec<Shell>, holes: Vec<Hole>) -> Vec<Face> {
    let areas: Vec<f64> = shells.iter().map(|s| signed_area(&s.coords)).collect();
    let mut inner: Vec<Vec<LineString<f64>>> = vec![Vec::new(); shells.len()];
    let mut chords: Vec<Vec<u32>> = shells.iter().map(|s| s.chords.clone()).collect();
    for hole in holes {
        // Not the face inside a loop of chords: it has the probe's chord,
        // the other way round.
        let inside = |k: usize| {
            hole.on_chord
                .is_some_and(|(a, b)| shells[k].edges.contains(&(b, a)))
        };
        let owner = (0..shells.len())
            .filter(|&k| !inside(k) && contains(&shells[k].coords, hole.probe))
            .min_by(|&a, &b| areas[a].total_cmp(&areas[b]));
        if let Some(k) = owner {
            inner[k].push(closed(hole.coords));
            chords[k].extend(hole.chords);
        }
    }
    shells
        .into_iter()
        .zip(inner)
        .zip(chords)
        .map(|((shell, interiors), mut chords)| {
            chords.sort_unstable();
            chords.dedup();
            Face {
                polygon: Polygon::new(closed(shell.coords), interiors),
                chords: chords.into_iter().map(|c| c as usize).collect(),
            }
        })
        .collect()
}

fn closed(mut c: Vec<Coord<f64>>) -> LineString<f64> {
    if let Some(&f) = c.first() {
        c.push(f);
    }
    LineString(c)
}

/// Twice the signed area of an open ring (positive counter-clockwise),
/// summed relative to its first vertex (raw products of coordinates far
/// from the origin would cancel away a small ring's area).
fn signed_area(c: &[Coord<f64>]) -> f64 {
    let n = c.len();
    let o = c[0];
    (1..n.saturating_sub(1))
        .map(|i| cross(c[i] - o, c[i + 1] - o))
        .sum()
}

/// Whether `p` lies inside the open ring `c` (even-odd).
fn contains(c: &[Coord<f64>], p: Coord<f64>) -> bool {
    let n = c.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (c[i], c[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Counter-clockwise order of directions by angle from the positive x axis
/// (exact: half-plane, then the sign of the cross product).
fn angle_order(a: Coord<f64>, b: Coord<f64>) -> std::cmp::Ordering {
    let half = |d: Coord<f64>| u8::from(d.y < 0.0 || (d.y == 0.0 && d.x < 0.0));
    half(a)
        .cmp(&half(b))
        .then_with(|| 0.0f64.total_cmp(&cross(a, b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::{polygon, Area};

    fn area(faces: &[Face]) -> f64 {
        faces.iter().map(|f| f.polygon.unsigned_area()).sum()
    }

    #[test]
    fn a_rectangle_cut_twice_gives_three_faces_that_keep_its_vertices() {
        let r = polygon![(x: 0., y: 0.), (x: 30., y: 0.), (x: 30., y: 10.), (x: 0., y: 10.)];
        let p = PreparedPolygon::new(&r).unwrap();
        let cuts = [
            LineString::from(vec![(10., 0.), (10., 5.), (10., 10.)]),
            LineString::from(vec![(20., 10.), (20., 0.)]),
        ];
        let f = split(&p, &cuts).unwrap();
        assert_eq!(f.len(), 3);
        assert!((area(&f) - 300.0).abs() < 1e-9);
        let mut chords: Vec<Vec<usize>> = f.iter().map(|f| f.chords.clone()).collect();
        chords.sort();
        assert_eq!(chords, [vec![0], vec![0, 1], vec![1]]);
        for corner in [(0., 0.), (30., 0.), (30., 10.), (0., 10.)] {
            let c = Coord::from(corner);
            assert!(f.iter().any(|f| f.polygon.exterior().0.contains(&c)));
        }
    }

    #[test]
    fn holes_touching_the_shell_and_each_other_give_valid_faces() {
        use geo::Validation;
        // Two triangular holes touching each other at (50, 50), one of them
        // touching the shell at (0, 50).
        let p = Polygon::new(
            LineString::from(vec![
                (0., 0.),
                (100., 0.),
                (100., 100.),
                (0., 100.),
                (0., 50.),
                (0., 0.),
            ]),
            vec![
                LineString::from(vec![(0., 50.), (50., 50.), (25., 60.), (0., 50.)]),
                LineString::from(vec![(50., 50.), (75., 40.), (75., 60.), (50., 50.)]),
            ],
        );
        let pp = PreparedPolygon::new(&p).unwrap();
        let whole = split(&pp, &[]).unwrap();
        assert!((area(&whole) - p.unsigned_area()).abs() < 1e-9);
        for f in &whole {
            assert!(f.polygon.is_valid(), "{:?}", f.polygon);
        }
        let cut = split(&pp, &[LineString::from(vec![(90., 0.), (90., 100.)])]).unwrap();
        assert_eq!(cut.len(), 2);
        assert!((area(&cut) - p.unsigned_area()).abs() < 1e-9);
        for f in &cut {
            assert!(f.polygon.is_valid(), "{:?}", f.polygon);
        }
    }

    #[test]
    fn a_small_polygon_far_from_the_origin_keeps_its_holes_as_holes() {
        // 6 cm across at 10 000 km: products of raw coordinates lose the
        // holes' orientation.
        let (x, y) = (1e7, 1e7);
        let p = Polygon::new(
            LineString::from(vec![
                (x, y),
                (x + 0.06, y),
                (x + 0.06, y + 0.06),
                (x, y + 0.06),
                (x, y),
            ]),
            vec![LineString::from(vec![
                (x + 0.01, y + 0.01),
                (x + 0.02, y + 0.01),
                (x + 0.02, y + 0.02),
                (x + 0.01, y + 0.01),
            ])],
        );
        let pp = PreparedPolygon::new(&p).unwrap();
        let f = split(
            &pp,
            &[LineString::from(vec![(x + 0.03, y), (x + 0.03, y + 0.06)])],
        )
        .unwrap();
        assert_eq!(f.len(), 2);
        assert!(
            (area(&f) - p.unsigned_area()).abs() < 1e-12,
            "{} vs {}",
            area(&f),
            p.unsigned_area()
        );
    }

    #[test]
    fn a_network_of_chords_with_a_junction_splits_into_three_faces() {
        let r = polygon![(x: 0., y: 0.), (x: 20., y: 0.), (x: 20., y: 10.), (x: 0., y: 10.)];
        let p = PreparedPolygon::new(&r).unwrap();
        let j = (8., 5.);
        let chords = [
            LineString::from(vec![(0., 5.), j]),
            LineString::from(vec![j, (20., 5.)]),
            LineString::from(vec![j, (8., 10.)]),
        ];
        let f = split_network(&p, &chords).unwrap();
        assert_eq!(f.len(), 3);
        assert!((area(&f) - 200.0).abs() < 1e-9);
        // Not a network: an end inside P that no other chord meets.
        let e = split_network(&p, &[LineString::from(vec![(0., 5.), (8., 5.)])]).unwrap_err();
        assert_eq!(e, SplitError::Detached(0));
    }

    #[test]
    fn a_loop_of_chords_around_a_hole_is_the_hole_of_the_face_outside_it() {
        // A 10 × 10 square with a 2 × 2 hole, and a closed chord around the
        // hole touching nothing: the face inside the loop has the hole, the
        // one outside has the loop as its hole (not the face inside it).
        let r = Polygon::new(
            LineString::from(vec![(0., 0.), (10., 0.), (10., 10.), (0., 10.), (0., 0.)]),
            vec![LineString::from(vec![
                (4., 4.),
                (4., 6.),
                (6., 6.),
                (6., 4.),
                (4., 4.),
            ])],
        );
        let p = PreparedPolygon::new(&r).unwrap();
        let lp = LineString::from(vec![(2., 2.), (8., 2.), (8., 8.), (2., 8.), (2., 2.)]);
        let mut f = split_network(&p, &[lp]).unwrap();
        f.sort_by(|a, b| {
            a.polygon
                .unsigned_area()
                .total_cmp(&b.polygon.unsigned_area())
        });
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].polygon.interiors().len(), 1);
        assert!(
            (f[0].polygon.unsigned_area() - 32.0).abs() < 1e-12,
            "{:?}",
            f[0]
        );
        assert_eq!(f[1].polygon.interiors().len(), 1);
        assert!(
            (f[1].polygon.unsigned_area() - 64.0).abs() < 1e-12,
            "{:?}",
            f[1]
        );
    }

    #[test]
    fn the_union_of_a_coverage_drops_shared_edges_and_keeps_every_vertex() {
        use geo::Validation;
        let sq = |x: f64, y: f64| polygon![(x: x, y: y), (x: x + 1., y: y), (x: x + 1., y: y + 1.), (x: x, y: y + 1.)];
        let u = coverage_union(&[sq(0., 0.), sq(1., 0.)]);
        assert_eq!(u.len(), 1);
        assert_eq!(u[0].exterior().0.len(), 7, "{:?}", u[0]);
        assert!((u[0].unsigned_area() - 2.0).abs() < 1e-12);
        // Eight squares around a ninth: a shell and a hole.
        let ring: Vec<Polygon<f64>> = (0..3)
            .flat_map(|i| (0..3).map(move |j| (f64::from(i), f64::from(j))))
            .filter(|&(i, j)| (i, j) != (1., 1.))
            .map(|(i, j)| sq(i, j))
            .collect();
        let u = coverage_union(&ring);
        assert_eq!(u.len(), 1);
        assert_eq!(u[0].interiors().len(), 1);
        assert!(u[0].is_valid() && (u[0].unsigned_area() - 8.0).abs() < 1e-12);
    }

    #[test]
    fn a_chord_end_off_the_boundary_is_an_error() {
        let r = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)];
        let p = PreparedPolygon::new(&r).unwrap();
        let e = split(&p, &[LineString::from(vec![(5., 0.), (5., 5.)])]).unwrap_err();
        assert_eq!(e, SplitError::Detached(0));
    }
}
