//! The new boundaries inside a collapsed polygon and its pieces, from the
//! cells of the segment Voronoi diagram of its boundary
//! ([`crate::methods::medial_axis::cells`]): every point of the polygon lies
//! in the cell of the boundary site nearest to it, and a cell belongs to the
//! unit that owns its site. The edges between cells of different owners are
//! the new boundaries — the medial axis between two units' banks, the
//! bisector from the point where two units meet on a convex bank, the normal
//! where they meet on a straight one — and where they meet at a reflex
//! vertex, that vertex's cell is split between them along the bisector of
//! their two edges' normals. The polygon split along the boundaries
//! ([`crate::geometry::arrangement::split_network`]) gives one piece per
//! unit and bank.

use super::owners::{Owned, VertexOwners};
use crate::geometry::arrangement::{split_network, Face};
use crate::geometry::coverage::{edge_key, EdgeKey};
use crate::geometry::vector::{cross, norm};
use crate::geometry::CoordKey;
use crate::geometry::PreparedPolygon;
use crate::methods::medial_axis::cells::{CellEdge, CellSite};
use geo::{Coord, LineString};
use rustc_hash::FxHashMap;

/// An owner: a unit (index into the coverage) or none (unowned bank).
pub type Owner = Option<u32>;

/// A new boundary piece: its line and the owners on its left and right.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// The line.
    pub line: Vec<Coord<f64>>,
    /// The owner on its left, walking it from its first point.
    pub left: Owner,
    /// The owner on its right.
    pub right: Owner,
}

/// A face of the partitioned polygon and its owner.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnedFace {
    /// The face.
    pub face: Face,
    /// Its owner: the owner of its bank.
    pub owner: Owner,
}

fn key(c: Coord<f64>) -> CoordKey {
    CoordKey::from(c)
}

/// The owners at every vertex, and how the cells of the vertices where two
/// units meet are split.
pub struct Vertices {
    owners: FxHashMap<CoordKey, VertexOwners>,
    /// The split of a vertex's cell: the direction from the vertex along
    /// which it is split, and one towards the side of the edge before.
    splits: FxHashMap<CoordKey, (Coord<f64>, Coord<f64>)>,
}

impl Vertices {
    /// The owner of the cell of vertex `v` at point `x` of it: the unit of
    /// its edges when both have one; where two units meet and the cell has
    /// area, the side of its split `x` is on; otherwise (a convex or
    /// straight vertex, whose cell has no area) the one whose edge's inward
    /// normal is nearer in angle to `x − v`, or at a straight angle the
    /// owner of the edge after.
    fn owner_at(&self, v: Coord<f64>, x: Coord<f64>) -> Owner {
        let o = self.owners.get(&key(v))?;
        if o.before == o.after {
            return o.before;
        }
        let (split, before) = match self.splits.get(&key(v)) {
            Some(&s) => s,
            None if cross(o.into, o.out_of) == 0.0 => return o.after,
            None => {
                let na = left_normal(o.into);
                (na + left_normal(o.out_of), na)
            }
        };
        if cross(split, x - v) * cross(split, before) >= 0.0 {
            o.before
        } else {
            o.after
        }
    }
}

fn left_normal(d: Coord<f64>) -> Coord<f64> {
    let l = norm(d);
    Coord {
        x: -d.y / l,
        y: d.x / l,
    }
}

/// Where points were put into the base polygon's edges
/// ([`Owned::splits`]).
type Splits = FxHashMap<EdgeKey, Vec<Coord<f64>>>;

/// The owner of a site at point `x` of its cell.
fn site_owner(
    owned: &Owned,
    splits: &Splits,
    vertices: &Vertices,
    site: CellSite,
    x: Coord<f64>,
) -> Owner {
    match site {
        CellSite::Segment(a, b) => owned.owner_along(splits, a, b, x),
        CellSite::Vertex(v) => vertices.owner_at(v, x),
    }
}

/// The new boundaries of `owned` from the edges of the cells of its base
/// polygon ([`Owned::base`]) — every piece of an edge with different owners
/// on its sides, the splits of the cells of vertices where two units meet,
/// and the normals from the points where two units meet inside an edge —
/// and the owners at the vertices.
pub fn pieces(owned: &Owned, mut edges: Vec<CellEdge>) -> (Vec<Piece>, Vertices) {
    let mut vertices = Vertices {
        owners: owned.at_vertices(),
        splits: FxHashMap::default(),
    };
    let splits = owned.splits();
    let mut out = split_cells(&mut vertices, &mut edges);
    out.extend(split_segment_cells(&vertices, &splits, &mut edges));
    for e in &edges {
        for w in e.line.windows(2) {
            let m = (w[0] + w[1]) * 0.5;
            let left = site_owner(owned, &splits, &vertices, e.sites[0], m);
            let right = site_owner(owned, &splits, &vertices, e.sites[1], m);
            if left == right {
                continue;
            }
            // Consecutive segments with the same owners are one piece.
            match out.last_mut() {
                Some(p) if p.left == left && p.right == right && p.line.last() == Some(&w[0]) => {
                    p.line.push(w[1]);
                }
                _ => out.push(Piece {
                    line: vec![w[0], w[1]],
                    left,
                    right,
                }),
            }
        }
    }
    (out, vertices)
}

/// The splits of the cells of vertices where two units meet, where the
/// diagram gives the vertex a cell with area (a reflex vertex — as the
/// diagram sees it: a vertex within the coordinates' rounding of straight
/// may be either): each along the bisector of the cell's two normal edges,
/// from the vertex to where it leaves the cell — that point put into the
/// cell edge it meets, so that both share it (where the cell is too thin
/// for the ray to meet one exactly, the vertex of its far edges nearest in
/// angle).
fn split_cells(vertices: &mut Vertices, edges: &mut [CellEdge]) -> Vec<Piece> {
    let mut by_vertex: FxHashMap<CoordKey, Vec<usize>> = FxHashMap::default();
    for (k, e) in edges.iter().enumerate() {
        for s in e.sites {
            if let CellSite::Vertex(v) = s {
                by_vertex.entry(key(v)).or_default().push(k);
            }
        }
    }
    let mut by_vertex: Vec<_> = by_vertex.into_iter().collect();
    by_vertex.sort_unstable_by_key(|(k, _)| *k);
    let mut out = Vec::new();
    for (vk, ks) in by_vertex {
        let Some(o) = vertices.owners.get(&vk).copied() else {
            continue;
        };
        let v = vk.coord();
        if o.before == o.after {
            continue;
        }
        let Some((dir, before)) = normals(v, &ks, edges) else {
            continue;
        };
        let Some(x) = cell_exit(v, dir, &ks, edges) else {
            continue;
        };
        vertices.splits.insert(vk, (x - v, before));
        // Walking from v along the split, the edge before is on the left
        // when its side is to the left of the split.
        let (left, right) = if cross(x - v, before) > 0.0 {
            (o.before, o.after)
        } else {
            (o.after, o.before)
        };
        out.push(Piece {
            line: vec![v, x],
            left,
            right,
        });
    }
    out
}

/// The splits of the cells of the base polygon's edges that two units meet
/// inside (a unit's vertex put into the edge): the cell of a segment holds
/// the points whose foot on it is inside it, so the part nearer each unit's
/// piece is on one side of the normal at the meeting point — from the
/// point to where it leaves the cell, that point put into the cell edge it
/// meets. (A diagram of the polygon with the point as a vertex has the same
/// normal as an edge; this one needs no second diagram.)
fn split_segment_cells(vertices: &Vertices, splits: &Splits, edges: &mut [CellEdge]) -> Vec<Piece> {
    if splits.is_empty() {
        return Vec::new();
    }
    let mut by_segment: FxHashMap<EdgeKey, Vec<usize>> = FxHashMap::default();
    for (k, e) in edges.iter().enumerate() {
        for s in e.sites {
            if let CellSite::Segment(a, b) = s {
                let sk = edge_key(a, b);
                if splits.contains_key(&sk) {
                    by_segment.entry(sk).or_default().push(k);
                }
            }
        }
    }
    let mut runs: Vec<(&EdgeKey, &Vec<Coord<f64>>)> = splits.iter().collect();
    runs.sort_unstable_by_key(|(k, _)| **k);
    let mut out = Vec::new();
    for (sk, run) in runs {
        let Some(ks) = by_segment.get(sk) else {
            continue;
        };
        let inward = left_normal(run[run.len() - 1] - run[0]);
        for &t in &run[1..run.len() - 1] {
            let Some(o) = vertices.owners.get(&key(t)) else {
                continue;
            };
            if o.before == o.after {
                continue;
            }
            let Some(x) = cell_exit(t, inward, ks, edges) else {
                continue;
            };
            // Walking the normal inwards, the edge's start is on the left.
            out.push(Piece {
                line: vec![t, x],
                left: o.before,
                right: o.after,
            });
        }
    }
    out
}

/// The bisector of the two normal edges of vertex `v`'s cell (the edges
/// between it and the cells of its two polygon edges, which start at `v`),
/// and the direction of the one on the side of the edge before; `None`
/// where the cell has no far edge (no area).
fn normals(v: Coord<f64>, ks: &[usize], edges: &[CellEdge]) -> Option<(Coord<f64>, Coord<f64>)> {
    let mut into = None;
    let mut out_of = None;
    let mut far = false;
    for &k in ks {
        let e = &edges[k];
        let (first, last) = (e.line[0], e.line[e.line.len() - 1]);
        let end = if first == v {
            last
        } else if last == v {
            first
        } else {
            far = true;
            continue;
        };
        for s in e.sites {
            match s {
                CellSite::Segment(_, b) if b == v => into = Some(end - v),
                CellSite::Segment(a, _) if a == v => out_of = Some(end - v),
                _ => {}
            }
        }
    }
    let (a, b) = (into?, out_of?);
    let unit = |d: Coord<f64>| d / norm(d);
    (far && norm(a) > 0.0 && norm(b) > 0.0).then(|| (unit(a) + unit(b), a))
}

/// Where the ray from `v` along `dir` leaves the cell (its first crossing
/// with a far edge, put into that edge), or the far edges' vertex nearest
/// to it in angle.
fn cell_exit(
    v: Coord<f64>,
    dir: Coord<f64>,
    ks: &[usize],
    edges: &mut [CellEdge],
) -> Option<Coord<f64>> {
    let mut best: Option<(f64, usize, usize, Coord<f64>)> = None;
    let mut nearest: Option<(f64, Coord<f64>)> = None;
    let unit = dir / norm(dir);
    for &k in ks {
        for (j, w) in edges[k].line.windows(2).enumerate() {
            if w[0] == v || w[1] == v {
                continue;
            }
            if let Some((t, x)) = ray_hit(v, dir, w[0], w[1]) {
                if best.is_none_or(|b| t < b.0) {
                    best = Some((t, k, j, x));
                }
            }
            for q in [w[0], w[1]] {
                let d = q - v;
                let off = cross(unit, d).abs() / norm(d);
                if crate::geometry::vector::dot(unit, d) > 0.0 && nearest.is_none_or(|n| off < n.0)
                {
                    nearest = Some((off, q));
                }
            }
        }
    }
    let Some((_, k, j, x)) = best else {
        return nearest.map(|n| n.1);
    };
    let line = &mut edges[k].line;
    Some(if x == line[j] {
        line[j]
    } else if x == line[j + 1] {
        line[j + 1]
    } else {
        line.insert(j + 1, x);
        x
    })
}

/// Where the ray `o + t·d` (t > 0) crosses segment `a`–`b`: `(t, point)`.
fn ray_hit(
    o: Coord<f64>,
    d: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
) -> Option<(f64, Coord<f64>)> {
    let s = b - a;
    let den = cross(d, s);
    if den == 0.0 {
        return None;
    }
    let w = a - o;
    let t = cross(w, s) / den;
    let u = cross(w, d) / den;
    (t > 0.0 && (0.0..=1.0).contains(&u)).then(|| (t, a + s * u))
}

/// The polygon `p` (`owned`'s, prepared) split along `chords` (the new
/// boundaries, and the cuts of a partial partition), each face with its owner: the owner of the most
/// of its bank by length (every bank edge of a face has the same owner
/// unless the boundaries are broken); a face with no bank edge (a cut
/// through the cell of a reflex vertex leaves two) takes the owner of the
/// vertex's cell where the face lies.
pub fn faces(
    p: &PreparedPolygon,
    owned: &Owned,
    vertices: &Vertices,
    chords: &[LineString<f64>],
) -> Result<Vec<OwnedFace>, crate::geometry::arrangement::SplitError> {
    let faces = split_network(p, chords)?;
    Ok(faces
        .into_iter()
        .map(|face| {
            let owner = bank_owner(owned, &face).unwrap_or_else(|| vertex_owner(vertices, &face));
            OwnedFace { face, owner }
        })
        .collect())
}

/// The owner of the most of `face`'s bank by length (`None`: it has none).
fn bank_owner(owned: &Owned, face: &Face) -> Option<Owner> {
    let mut length: FxHashMap<Owner, f64> = FxHashMap::default();
    for r in std::iter::once(face.polygon.exterior()).chain(face.polygon.interiors()) {
        for w in r.0.windows(2) {
            if owned.is_edge(w[0], w[1]) {
                *length.entry(owned.owner(w[0], w[1])).or_default() += norm(w[1] - w[0]);
            }
        }
    }
    length
        .into_iter()
        .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
        .map(|(o, _)| o)
}

/// The owner of a face without bank edges: that of the cell of a polygon
/// vertex on it, at the face's inner point.
fn vertex_owner(vertices: &Vertices, face: &Face) -> Owner {
    use geo::InteriorPoint;
    let inner = face.polygon.interior_point().map(|p| p.0);
    face.polygon
        .exterior()
        .0
        .iter()
        .find(|v| vertices.owners.contains_key(&key(**v)))
        .and_then(|&v| vertices.owner_at(v, inner?))
}
