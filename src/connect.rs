//! `input.connect`: a line network (rivers flowing in and out) continued
//! through the polygons. Where a line touches or crosses ∂P — or ends within
//! `snap` of it — that boundary point is a *connection point*, and the chosen
//! skeleton gets a leg from its nearest point to it (a straight segment
//! inside P, leaving the boundary within 60° of its inward normal), so that
//! pruning cannot have removed it and the network runs
//! on through the polygon. The lines themselves are not modified; the
//! `connections` layer lists every leg with the line it serves.

use crate::geometry::CoordKey;
use crate::geometry::PreparedPolygon;
use crate::graph::{GraphBuilder, SkeletonGraph};
use crate::layer::{col, fid, text, Attributes, ColumnType, GeometryKind, LayerDef, Shape, When};
use geo::{BoundingRect, Coord, LineString, Rect};

pub use crate::geometry::parts::lines_of;

/// One line of the network.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkLine {
    /// Its FID in the connect source.
    pub fid: Option<u64>,
    /// The line.
    pub line: LineString<f64>,
    bbox: Rect<f64>,
}

/// The lines of `input.connect`, with the snap tolerance.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Network {
    lines: Vec<NetworkLine>,
    /// A line end within this distance of ∂P connects (CRS units).
    pub snap: f64,
}

/// A leg added to a skeleton for a network line.
#[derive(Debug, Clone, PartialEq)]
pub struct ConnectionLeg {
    /// The network line's FID.
    pub line_fid: Option<u64>,
    /// From the skeleton to the connection point on ∂P.
    pub leg: LineString<f64>,
}

impl Network {
    /// The network of `lines` (FID, line) with tolerance `snap`.
    pub fn new(lines: Vec<(Option<u64>, LineString<f64>)>, snap: f64) -> Self {
        let lines = lines
            .into_iter()
            .filter_map(|(fid, line)| {
                let bbox = line.bounding_rect()?;
                Some(NetworkLine { fid, line, bbox })
            })
            .collect();
        Self { lines, snap }
    }

    /// Number of lines.
    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// True when there is no line.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// The connection points of polygon part `p`: (line FID, point on ∂P).
    /// Every point where a line touches or crosses ∂P connects (points of
    /// one line closer than `1e-9 × extent` count once: a line through a
    /// vertex meets two edges there). `snap` only adds near-misses: a line
    /// end outside P within `snap` of ∂P connects at its nearest boundary
    /// point unless a touch or crossing of the same line lies within `snap`
    /// of that point (it already serves the end). An end inside P never
    /// snaps: the line entered P where it crossed ∂P. Whatever `snap`, an
    /// end within the round-off of a reprojection
    /// ([`ROUND_OFF`](crate::geometry::tolerance::ROUND_OFF) × extent)
    /// outside ∂P connects: lines from another CRS connect as in theirs.
    pub fn points(&self, p: &PreparedPolygon) -> Vec<(Option<u64>, Coord<f64>)> {
        let b = p.boundary();
        let (lo, hi) = (b.bbox_min(), b.bbox_max());
        let eps = 1e-9 * p.extent();
        let snap = self
            .snap
            .max(crate::geometry::tolerance::ROUND_OFF * p.extent());
        let mut out: Vec<(Option<u64>, Coord<f64>)> = Vec::new();
        for l in &self.lines {
            let (a, z) = (l.bbox.min(), l.bbox.max());
            if a.x > hi.x + snap || z.x < lo.x - snap || a.y > hi.y + snap || z.y < lo.y - snap {
                continue;
            }
            let mut found: Vec<Coord<f64>> = Vec::new();
            // Points found so far by their cell of side eps: a point within
            // eps of another lies in one of the 3 × 3 cells around it.
            let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
            let cell = |c: Coord<f64>| ((c.x / eps).floor() as i64, (c.y / eps).floor() as i64);
            let mut add = |found: &mut Vec<Coord<f64>>, c: Coord<f64>, tol: f64| {
                let (i, j) = cell(c);
                let near = (i - 1..=i + 1)
                    .flat_map(|x| (j - 1..=j + 1).map(move |y| (x, y)))
                    .filter_map(|k| cells.get(&k))
                    .flatten()
                    .any(|&f| crate::geometry::norm(found[f] - c) <= tol);
                if !near {
                    cells.entry((i, j)).or_default().push(found.len());
                    found.push(c);
                }
            };
            // Touches and crossings: each its own connection.
            for w in l.line.0.windows(2) {
                for i in b.segments_near(w[0], w[1]) {
                    let s = &b.segments()[i];
                    if let Some(c) = intersection(w[0], w[1], s.a, s.b) {
                        add(&mut found, c, eps);
                    }
                }
            }
            // Near-misses: ends outside P within snap of ∂P.
            let crossings = found.len();
            for end in [l.line.0.first(), l.line.0.last()].into_iter().flatten() {
                if b.contains(*end) {
                    continue;
                }
                if let Some((c, _, d)) = b.nearest(*end) {
                    let served = found[..crossings]
                        .iter()
                        .any(|f| crate::geometry::norm(*f - c) <= snap);
                    if d <= snap && !served {
                        add(&mut found, c, eps);
                    }
                }
            }
            out.extend(found.into_iter().map(|c| (l.fid, c)));
        }
        out
    }
}

/// The intersection point of segments `pq` and `ab`, when they meet (not
/// parallel).
fn intersection(p: Coord<f64>, q: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> Option<Coord<f64>> {
    crate::geometry::segment::segment_parameter(p, q, a, b).map(|t| p + (q - p) * t)
}

/// `g` with a leg to every connection point: straight from the nearest
/// point of the skeleton that sees it within 60° of the boundary's inward
/// normal there (the edge split at that point).
/// A point the skeleton already reaches (within `1e-9 × extent`) gets a
/// zero-length leg, so that every connection point is listed. Points are
/// served in order, and a leg made for an earlier point is a line a later
/// one can join. The skeleton's segments are searched through a packed
/// tree and the legs through one rebuilt as they accumulate, so that a
/// polygon with thousands of connection points costs O(k log n). `None`
/// when `expired()` (asked every 256 points) said the time is up.
pub fn add_legs(
    g: &SkeletonGraph,
    p: &PreparedPolygon,
    points: &[(Option<u64>, Coord<f64>)],
    expired: &dyn Fn() -> bool,
) -> Option<(SkeletonGraph, Vec<ConnectionLeg>)> {
    if points.is_empty() || g.is_empty() {
        return Some((g.clone(), Vec::new()));
    }
    let tol = 1e-9 * p.extent();
    let polylines: Vec<Vec<Coord<f64>>> = (0..g.edges().len())
        .map(|e| g.edge_coords(crate::graph::EdgeId::from_index(e)))
        .collect();
    let mut lines = Reachable::new(polylines, p.extent());
    let mut legs = Vec::new();
    for (k, &(fid, c)) in points.iter().enumerate() {
        if k % 256 == 255 && expired() {
            return None;
        }
        let Some((at, s)) = nearest_visible(&lines, p, c) else {
            continue;
        };
        if crate::geometry::norm(s - c) <= tol {
            // Already reached: the connection is listed with a zero-length leg.
            legs.push(ConnectionLeg {
                line_fid: fid,
                leg: LineString(vec![c, c]),
            });
            continue;
        }
        lines.split(at, s);
        lines.add_leg(s, c);
        legs.push(ConnectionLeg {
            line_fid: fid,
            leg: LineString(vec![s, c]),
        });
    }
    let mut b = GraphBuilder::new();
    for l in lines.pieces() {
        b.polyline(&l);
    }
    Some((b.finish(p.boundary()), legs))
}

/// A segment of [`Reachable`]: (line, segment index in it).
type SegmentAt = (usize, usize);

/// The skeleton's polylines and the legs added to them, with the points
/// they are split at, searchable by distance.
struct Reachable {
    /// The skeleton's polylines, then one two-point line per leg.
    lines: Vec<Vec<Coord<f64>>>,
    /// The split points of each line: (segment, parameter, point).
    splits: Vec<Vec<(usize, f64, Coord<f64>)>>,
    /// Every segment of the skeleton's polylines, and a tree of them.
    segments: Vec<SegmentAt>,
    tree: crate::geometry::packed::PackedTree,
    /// The legs in `legs_tree` (the first `indexed` legs) and those after.
    legs_tree: crate::geometry::packed::PackedTree,
    indexed: usize,
    skeleton_lines: usize,
    extent: f64,
}

/// Legs not in the legs' tree that make it be rebuilt.
const LEGS_UNINDEXED: usize = 256;

impl Reachable {
    fn new(lines: Vec<Vec<Coord<f64>>>, extent: f64) -> Self {
        let mut segments = Vec::new();
        let mut ends = Vec::new();
        for (k, l) in lines.iter().enumerate() {
            for (i, w) in l.windows(2).enumerate() {
                segments.push((k, i));
                ends.push([[w[0].x, w[0].y], [w[1].x, w[1].y]]);
            }
        }
        Self {
            splits: vec![Vec::new(); lines.len()],
            skeleton_lines: lines.len(),
            lines,
            tree: crate::geometry::packed::PackedTree::of_segments(&ends),
            segments,
            legs_tree: Default::default(),
            indexed: 0,
            extent,
        }
    }

    fn segment(&self, (k, i): SegmentAt) -> (Coord<f64>, Coord<f64>) {
        (self.lines[k][i], self.lines[k][i + 1])
    }

    /// Every segment with a point within `r` of `c` (by its box), in the
    /// order of the lines (skeleton first, then the legs).
    fn near(&self, c: Coord<f64>, r: f64) -> Vec<SegmentAt> {
        use std::ops::ControlFlow;
        let r2 = r * r;
        let within = |b: &crate::geometry::packed::Bbox| {
            crate::geometry::packed::box_distance_2(b, c.x, c.y) <= r2
        };
        let mut out: Vec<SegmentAt> = Vec::new();
        self.tree.visit(within, |id| {
            out.push(self.segments[id as usize]);
            ControlFlow::<()>::Continue(())
        });
        let first_leg = self.skeleton_lines;
        self.legs_tree.visit(within, |id| {
            out.push((first_leg + id as usize, 0));
            ControlFlow::<()>::Continue(())
        });
        for k in first_leg + self.indexed..self.lines.len() {
            let (a, z) = self.segment((k, 0));
            let b = [a.x.min(z.x), a.y.min(z.y), a.x.max(z.x), a.y.max(z.y)];
            if within(&b) {
                out.push((k, 0));
            }
        }
        out.sort_unstable();
        out
    }

    /// Splits segment `at` at `s`, a point of it.
    fn split(&mut self, (k, i): SegmentAt, s: Coord<f64>) {
        let (a, z) = self.segment((k, i));
        let (_, t) = crate::geometry::segment::closest_on_segment(a, z, s);
        self.splits[k].push((i, t, s));
    }

    /// A leg from `s` to `c`, a line later points can join.
    fn add_leg(&mut self, s: Coord<f64>, c: Coord<f64>) {
        self.lines.push(vec![s, c]);
        self.splits.push(Vec::new());
        let legs = self.lines.len() - self.skeleton_lines;
        if legs - self.indexed > LEGS_UNINDEXED {
            let ends: Vec<[[f64; 2]; 2]> = self.lines[self.skeleton_lines..]
                .iter()
                .map(|l| [[l[0].x, l[0].y], [l[1].x, l[1].y]])
                .collect();
            self.legs_tree = crate::geometry::packed::PackedTree::of_segments(&ends);
            self.indexed = legs;
        }
    }

    /// Every line cut at its split points.
    fn pieces(mut self) -> Vec<Vec<Coord<f64>>> {
        let mut out = Vec::new();
        for (line, mut splits) in self.lines.drain(..).zip(self.splits.drain(..)) {
            splits.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
            let mut piece = vec![line[0]];
            let mut next = splits.iter().peekable();
            for i in 0..line.len() - 1 {
                while let Some(&(_, _, s)) = next.next_if(|x| x.0 == i) {
                    piece.push(s);
                    out.push(std::mem::replace(&mut piece, vec![s]));
                }
                piece.push(line[i + 1]);
            }
            out.push(piece);
        }
        out
    }
}

/// `prune: {mode: network}`: the through-lines of `raw` (a method's raw
/// skeleton of `p`) between the connection `points` — a leg to each (see
/// [`add_legs`]; on a raw skeleton it is short, since the skeleton reaches
/// near every boundary vertex), then the union of the shortest paths
/// between them along the skeleton (`graph::prune::network`). The
/// result's leaves are the connection points (with one point: it and the
/// farthest tip); a point no straight leg inside P reaches keeps the leaf
/// nearest to it instead. Nothing is extended. `None` when `expired()`
/// said the feature's time is up before the paths were found.
pub fn through_lines(
    raw: &SkeletonGraph,
    p: &PreparedPolygon,
    points: &[Coord<f64>],
    expired: &dyn Fn() -> bool,
) -> Option<SkeletonGraph> {
    let listed: Vec<(Option<u64>, Coord<f64>)> = points.iter().map(|&c| (None, c)).collect();
    let (with_legs, _) = add_legs(raw, p, &listed, expired)?;
    if expired() {
        return None;
    }
    let m = with_legs.merged();
    let tol = 1e-9 * p.extent();
    let deg = m.degrees();
    // The node at each point (nodes sorted by x, looked up within tol);
    // where no straight leg inside P reached it (a conformed method's end
    // cut short), the leaf nearest to it.
    let mut by_x: Vec<(f64, usize)> = m
        .nodes()
        .iter()
        .enumerate()
        .map(|(i, n)| (n.pos.x, i))
        .collect();
    by_x.sort_by(|a, b| a.0.total_cmp(&b.0));
    let at = |c: Coord<f64>| {
        let from = by_x.partition_point(|&(x, _)| x < c.x - tol);
        by_x[from..]
            .iter()
            .take_while(|&&(x, _)| x <= c.x + tol)
            .map(|&(_, i)| (crate::geometry::norm(m.nodes()[i].pos - c), i))
            .filter(|&(d, _)| d <= tol)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, i)| i)
    };
    let nearest_leaf = |c: Coord<f64>| {
        m.nodes()
            .iter()
            .enumerate()
            .filter(|&(i, _)| deg[i] == 1)
            .map(|(i, n)| (crate::geometry::norm(n.pos - c), i))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, i)| i)
    };
    let mut terminals: Vec<crate::graph::NodeId> = points
        .iter()
        .filter_map(|&c| at(c).or_else(|| nearest_leaf(c)))
        .map(crate::graph::NodeId::from_index)
        .collect();
    terminals.sort();
    terminals.dedup();
    let keep = crate::graph::prune::network::mask(&m, &terminals, expired)?;
    Some(m.filter_edges(|e, _| keep[e.index()]).merged())
}

/// The point of the skeleton's lines nearest to `c` from which the
/// straight segment to `c` stays inside P and meets ∂P within 60° of its
/// inward normal at `c` (so that a leg never runs along the shore), among
/// the 64 nearest in that cone: (segment, point). The lines are searched
/// within a radius doubled until it holds the answer, 64 candidates, or
/// the whole polygon; candidates at one distance are taken in the lines'
/// order.
fn nearest_visible(
    lines: &Reachable,
    p: &PreparedPolygon,
    c: Coord<f64>,
) -> Option<(SegmentAt, Coord<f64>)> {
    const CANDIDATES: usize = 64;
    let b = p.boundary();
    let (_, seg, _) = b.nearest(c)?;
    let s = &b.segments()[seg];
    let d = s.b - s.a;
    let len = crate::geometry::norm(d);
    if len == 0.0 {
        return None;
    }
    let n = Coord {
        x: -d.y / len,
        y: d.x / len,
    };
    // The cone's edges: n turned by ∓60°.
    let (cos, sin) = (0.5, 3f64.sqrt() / 2.0);
    let right = Coord {
        x: n.x * cos + n.y * sin,
        y: -n.x * sin + n.y * cos,
    };
    let left = Coord {
        x: n.x * cos - n.y * sin,
        y: n.x * sin + n.y * cos,
    };
    let cross = |u: Coord<f64>, v: Coord<f64>| u.x * v.y - u.y * v.x;
    // The point of a segment inside the cone nearest to c.
    let in_cone = |a: Coord<f64>, z: Coord<f64>| {
        // The part of the segment inside the cone: both half-planes.
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for (edge, sign) in [(right, 1.0), (left, -1.0)] {
            let (fa, fz) = (sign * cross(edge, a - c), sign * cross(edge, z - c));
            if fa < 0.0 && fz < 0.0 {
                t1 = -1.0;
            } else if fa < 0.0 {
                t0 = t0.max(fa / (fa - fz));
            } else if fz < 0.0 {
                t1 = t1.min(fa / (fa - fz));
            }
        }
        if t0 > t1 {
            return None;
        }
        let (pa, pz) = (a + (z - a) * t0, a + (z - a) * t1);
        let (q, _) = crate::geometry::segment::closest_on_segment(pa, pz, c);
        Some((crate::geometry::norm(q - c), q))
    };
    let mut r = lines.extent / 1024.0;
    loop {
        let whole = r > 2.0 * lines.extent;
        let mut candidates: Vec<(f64, SegmentAt, Coord<f64>)> = lines
            .near(c, if whole { f64::INFINITY } else { r })
            .into_iter()
            .filter_map(|at| {
                let (a, z) = lines.segment(at);
                in_cone(a, z).map(|(d, q)| (d, at, q))
            })
            .filter(|&(d, _, _)| whole || d <= r)
            .collect();
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
        let found = candidates
            .iter()
            .take(CANDIDATES)
            .find(|&&(_, _, q)| b.reaches(q, c));
        if let Some(&(_, at, q)) = found {
            return Some((at, q));
        }
        if whole || candidates.len() >= CANDIDATES {
            return None;
        }
        r *= 2.0;
    }
}

/// One row of the `connections` layer: a leg added to a skeleton for a
/// line of `input.connect`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConnectionRow {
    /// Source FID of the polygon.
    pub src_fid: Option<u64>,
    /// FID of the network line the leg serves.
    pub line_fid: Option<u64>,
    /// The leg, from the skeleton to the connection point on the boundary.
    pub geometry: geo::LineString<f64>,
}

/// The `connections` layer (with `input.connect`).
pub const CONNECTIONS: LayerDef<ConnectionRow> = LayerDef {
    name: "connections",
    when: When::Connect,
    geometry: GeometryKind::LineString,
    shape: |r| Some(Shape::Line(r.geometry.clone())),
    attributes: Attributes::None,
    columns: &[
        col("src_fid", ColumnType::Int64, |r| fid(r.src_fid)),
        col("line_fid", ColumnType::Int64, |r| fid(r.line_fid)),
    ],
};

/// What a row of the `network` layer is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NetworkKind {
    /// A piece of a line of `input.connect`, between its connection points.
    Line,
    /// A piece of a polygon's skeleton (its through-lines in `network` mode).
    Skeleton,
    /// A leg from the skeleton to a connection point, or from a line's end
    /// to the point on ∂P it was snapped to.
    Connection,
}

impl NetworkKind {
    /// The `kind` column's value.
    pub fn name(self) -> &'static str {
        match self {
            NetworkKind::Line => "line",
            NetworkKind::Skeleton => "skeleton",
            NetworkKind::Connection => "connection",
        }
    }
}

/// One row of the `network` layer: the lines and the skeletons as one
/// network, noded (every junction one shared coordinate).
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkRow {
    /// What the row is.
    pub kind: NetworkKind,
    /// Source FID of the polygon (skeletons and their legs).
    pub src_fid: Option<u64>,
    /// FID of the network line (lines, and the legs that serve one).
    pub line_fid: Option<u64>,
    /// The piece.
    pub geometry: LineString<f64>,
}

/// The `network` layer (with `input.connect`).
pub const NETWORK: LayerDef<NetworkRow> = LayerDef {
    name: "network",
    when: When::Connect,
    geometry: GeometryKind::LineString,
    shape: |r| Some(Shape::Line(r.geometry.clone())),
    attributes: Attributes::None,
    columns: &[
        col("kind", ColumnType::Text, |r| text(r.kind.name())),
        col("src_fid", ColumnType::Int64, |r| fid(r.src_fid)),
        col("line_fid", ColumnType::Int64, |r| fid(r.line_fid)),
    ],
};

/// The `network` rows of one polygon's skeleton (`g`, with the legs
/// [`add_legs`] added): one per edge, a leg (`legs`) as `connection`.
pub fn skeleton_rows(
    g: &SkeletonGraph,
    legs: &[ConnectionLeg],
    src_fid: Option<u64>,
) -> Vec<NetworkRow> {
    // Each leg by its two ends (the first leg listed for a pair).
    let key = |a: Coord<f64>, b: Coord<f64>| {
        let (a, b) = (CoordKey::from(a), CoordKey::from(b));
        (a.min(b), a.max(b))
    };
    let mut by_ends: std::collections::HashMap<_, &ConnectionLeg> = Default::default();
    for l in legs {
        let (a, b) = (l.leg.0[0], l.leg.0[l.leg.0.len() - 1]);
        if a != b {
            by_ends.entry(key(a, b)).or_insert(l);
        }
    }
    (0..g.edges().len())
        .map(|e| {
            let coords = g.edge_coords(crate::graph::EdgeId::from_index(e));
            let leg = match coords[..] {
                [a, b] => by_ends.get(&key(a, b)).copied(),
                _ => None,
            };
            NetworkRow {
                kind: leg.map_or(NetworkKind::Skeleton, |_| NetworkKind::Connection),
                src_fid,
                line_fid: leg.and_then(|l| l.line_fid),
                geometry: LineString(coords),
            }
        })
        .collect()
}

impl Network {
    /// The `network` rows of the lines: each line split at its connection
    /// points `met` (line FID, point on ∂P, as the `connections` legs end),
    /// the point inserted into the line where it lies on it, so that the
    /// pieces and the skeletons share it. A point off the line (a line end
    /// snapped to ∂P) gets a `connection` row from the nearest line end to
    /// it instead.
    pub fn rows(&self, met: &[(Option<u64>, Coord<f64>)]) -> Vec<NetworkRow> {
        let mut at: std::collections::HashMap<Option<u64>, Vec<Coord<f64>>> = Default::default();
        for &(f, c) in met {
            at.entry(f).or_default().push(c);
        }
        let mut rows = Vec::new();
        for l in &self.lines {
            let row = |kind, geometry| NetworkRow {
                kind,
                src_fid: None,
                line_fid: l.fid,
                geometry,
            };
            let (cuts, snapped) = l.cuts(at.get(&l.fid).map_or(&[][..], Vec::as_slice));
            rows.extend(snapped.into_iter().map(|s| row(NetworkKind::Connection, s)));
            rows.extend(
                l.pieces(&cuts)
                    .into_iter()
                    .map(|p| row(NetworkKind::Line, p)),
            );
        }
        rows
    }
}

/// Where a point cuts a line: the segment, the parameter along it, the point.
type Cut = (usize, f64, Coord<f64>);

impl NetworkLine {
    /// A point counts as on the line within this distance.
    fn tolerance(&self) -> f64 {
        let (a, z) = (self.bbox.min(), self.bbox.max());
        1e-6 * (z.x - a.x).max(z.y - a.y).max(1.0)
    }

    /// Where `points` cut the line, as (segment, parameter along it, point),
    /// in order along it; and for each point off the line, the segment from
    /// the nearer line end to it.
    fn cuts(&self, points: &[Coord<f64>]) -> (Vec<Cut>, Vec<LineString<f64>>) {
        let line = &self.line.0;
        let (mut cuts, mut snapped) = (Vec::new(), Vec::new());
        let tol = self.tolerance();
        // The line's segments in a tree when many points are looked up.
        let tree = (points.len() > 8 && line.len() > 64).then(|| {
            let ends: Vec<[[f64; 2]; 2]> = line
                .windows(2)
                .map(|w| [[w[0].x, w[0].y], [w[1].x, w[1].y]])
                .collect();
            crate::geometry::packed::PackedTree::of_segments(&ends)
        });
        let at = |i: usize, c: Coord<f64>| {
            let (q, t) = crate::geometry::segment::closest_on_segment(line[i], line[i + 1], c);
            (crate::geometry::norm(q - c), i, t)
        };
        // The segment nearest to c within tol (ties: the first).
        let first =
            |a: (f64, usize, f64), b: (f64, usize, f64)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
        for &c in points {
            let nearest = match &tree {
                Some(tree) => {
                    let mut best: Option<(f64, usize, f64)> = None;
                    tree.visit(
                        |b| crate::geometry::packed::box_distance_2(b, c.x, c.y) <= tol * tol,
                        |i| {
                            let x = at(i as usize, c);
                            if best.is_none_or(|b| first(x, b).is_lt()) {
                                best = Some(x);
                            }
                            std::ops::ControlFlow::<()>::Continue(())
                        },
                    );
                    best
                }
                None => (0..line.len() - 1)
                    .map(|i| at(i, c))
                    .min_by(|&a, &b| first(a, b)),
            };
            match nearest {
                Some((d, i, t)) if d <= tol => cuts.push((i, t, c)),
                _ => {
                    let (first, last) = (line[0], line[line.len() - 1]);
                    let far = crate::geometry::norm(first - c) > crate::geometry::norm(last - c);
                    snapped.push(LineString(vec![if far { last } else { first }, c]));
                }
            }
        }
        cuts.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        (cuts, snapped)
    }

    /// The line's pieces between `cuts` (see [`NetworkLine::cuts`]); a cut at
    /// a vertex takes the vertex's place (the skeleton's end is the point on
    /// ∂P, bit for bit).
    fn pieces(&self, cuts: &[Cut]) -> Vec<LineString<f64>> {
        let line = &self.line.0;
        let tol = 1e-3 * self.tolerance();
        let near = |a: Coord<f64>, b: Coord<f64>| crate::geometry::norm(a - b) <= tol;
        let mut out = Vec::new();
        let mut piece: Vec<Coord<f64>> = vec![line[0]];
        let mut k = 0;
        for i in 0..line.len() - 1 {
            while k < cuts.len() && cuts[k].0 == i {
                let c = cuts[k].2;
                match piece.last_mut() {
                    Some(last) if near(*last, c) => *last = c,
                    _ => piece.push(c),
                }
                if piece.len() > 1 {
                    out.push(LineString(std::mem::take(&mut piece)));
                }
                piece = vec![c];
                k += 1;
            }
            if piece.last().is_none_or(|&last| !near(last, line[i + 1])) {
                piece.push(line[i + 1]);
            }
        }
        if piece.len() > 1 {
            out.push(LineString(piece));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    #[test]
    fn network_rows_split_lines_at_their_points_and_bridge_snapped_ends() {
        let p = PreparedPolygon::new(
            &polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 10.), (x: 0., y: 10.)],
        )
        .unwrap();
        let net = Network::new(
            vec![
                // Crosses the polygon: in at x = 0, out at x = 100.
                (
                    Some(1),
                    LineString::from(vec![(-10., 5.), (50., 5.), (120., 5.)]),
                ),
                // Ends 0.5 outside the north side.
                (Some(2), LineString::from(vec![(50., 30.), (50., 10.5)])),
            ],
            1.0,
        );
        let pts = net.points(&p);
        let rows = net.rows(&pts);
        let lines: Vec<&NetworkRow> = rows
            .iter()
            .filter(|r| r.kind == NetworkKind::Line)
            .collect();
        let pieces: Vec<Vec<(f64, f64)>> = lines
            .iter()
            .filter(|r| r.line_fid == Some(1))
            .map(|r| r.geometry.0.iter().map(|c| (c.x, c.y)).collect())
            .collect();
        assert_eq!(
            pieces,
            vec![
                vec![(-10., 5.), (0., 5.)],
                vec![(0., 5.), (50., 5.), (100., 5.)],
                vec![(100., 5.), (120., 5.)]
            ],
            "split at both crossings, the points shared"
        );
        // The snapped end: the line unchanged, a connection from its end to
        // the point on the boundary.
        assert_eq!(lines.iter().filter(|r| r.line_fid == Some(2)).count(), 1);
        let bridge: Vec<&NetworkRow> = rows
            .iter()
            .filter(|r| r.kind == NetworkKind::Connection)
            .collect();
        assert_eq!(bridge.len(), 1);
        assert_eq!(
            bridge[0].geometry,
            LineString::from(vec![(50., 10.5), (50., 10.)])
        );
        assert_eq!(bridge[0].line_fid, Some(2));
    }

    #[test]
    fn a_line_crossing_and_one_ending_near_the_boundary_connect_once_each() {
        let p = PreparedPolygon::new(
            &polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 10.), (x: 0., y: 10.)],
        )
        .unwrap();
        let net = Network::new(
            vec![
                (Some(1), LineString::from(vec![(-10., 5.), (20., 5.)])),
                (Some(2), LineString::from(vec![(50., 30.), (50., 10.5)])),
                (Some(3), LineString::from(vec![(50., 30.), (70., 30.)])),
            ],
            1.0,
        );
        let pts = net.points(&p);
        assert_eq!(
            pts,
            vec![
                (Some(1), Coord { x: 0., y: 5. }),
                (Some(2), Coord { x: 50., y: 10. })
            ]
        );
        let mut b = GraphBuilder::new();
        b.segment(Coord { x: 5., y: 5. }, Coord { x: 95., y: 5. });
        let (g, legs) = add_legs(&b.finish(p.boundary()), &p, &pts, &|| false).unwrap();
        assert_eq!(legs.len(), 2);
        assert_eq!(legs[1].leg, LineString::from(vec![(50., 5.), (50., 10.)]));
        assert_eq!(
            g.leg_count(),
            3,
            "the line's two legs and the new one at x = 50"
        );
    }
}
