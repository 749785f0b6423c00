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
use crate::geometry::vector::{cross, norm};
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

fn key(c: Coord<f64>) -> (u64, u64) {
    (c.x.to_bits(), c.y.to_bits())
}

/// The owners at every vertex, and which side of a mixed reflex vertex's
/// cell a point is on.
struct Vertices(FxHashMap<(u64, u64), VertexOwners>);

impl Vertices {
    /// The owner of the cell of vertex `v` at point `x` of it: the unit of
    /// its edges when both have one; at a vertex where two units meet, the
    /// one whose edge's inward normal is nearer in angle to `x − v` (the
    /// cell is split along the bisector of the normals), or at a straight
    /// angle (a cell with no area: the normal) the owner of the edge after.
    fn owner_at(&self, v: Coord<f64>, x: Coord<f64>) -> Owner {
        let o = self.0.get(&key(v))?;
        if o.before == o.after {
            return o.before;
        }
        let (na, nb) = (left_normal(o.into), left_normal(o.out_of));
        if cross(o.into, o.out_of) == 0.0 {
            return o.after;
        }
        let bisector = na + nb;
        let d = x - v;
        if cross(bisector, d) * cross(bisector, na) >= 0.0 {
            o.before
        } else {
            o.after
        }
    }

    /// The bisector direction of a vertex where two units meet at a reflex
    /// angle (its cell lies in P and is split), if `v` is one.
    fn split_direction(&self, v: Coord<f64>) -> Option<Coord<f64>> {
        let o = self.0.get(&key(v))?;
        let reflex = cross(o.into, o.out_of) < 0.0;
        (o.before != o.after && reflex).then(|| left_normal(o.into) + left_normal(o.out_of))
    }
}

fn left_normal(d: Coord<f64>) -> Coord<f64> {
    let l = norm(d);
    Coord {
        x: -d.y / l,
        y: d.x / l,
    }
}

/// The owner of a site at point `x` of its cell.
fn site_owner(owned: &Owned, vertices: &Vertices, site: CellSite, x: Coord<f64>) -> Owner {
    match site {
        CellSite::Segment(a, b) => owned.owner(a, b),
        CellSite::Vertex(v) => vertices.owner_at(v, x),
    }
}

/// The new boundaries of `owned` from the edges of its cells: every piece
/// of an edge with different owners on its sides, and the bisectors that
/// split the cells of reflex vertices where two units meet.
pub fn pieces(owned: &Owned, mut edges: Vec<CellEdge>) -> Vec<Piece> {
    let vertices = Vertices(owned.at_vertices());
    let bisectors = split_cells(&vertices, &mut edges);
    let mut out = bisectors;
    for e in &edges {
        for w in e.line.windows(2) {
            let m = (w[0] + w[1]) * 0.5;
            let left = site_owner(owned, &vertices, e.sites[0], m);
            let right = site_owner(owned, &vertices, e.sites[1], m);
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
    out
}

/// The bisectors of the cells of reflex vertices where two units meet:
/// each from its vertex to where it leaves the cell, that point inserted
/// into the cell edge it crosses (so both share it exactly).
fn split_cells(vertices: &Vertices, edges: &mut [CellEdge]) -> Vec<Piece> {
    let mut by_vertex: FxHashMap<(u64, u64), Vec<usize>> = FxHashMap::default();
    for (k, e) in edges.iter().enumerate() {
        for s in e.sites {
            if let CellSite::Vertex(v) = s {
                by_vertex.entry(key(v)).or_default().push(k);
            }
        }
    }
    let mut out = Vec::new();
    for (vk, ks) in by_vertex {
        let v = Coord {
            x: f64::from_bits(vk.0),
            y: f64::from_bits(vk.1),
        };
        let Some(dir) = vertices.split_direction(v) else {
            continue;
        };
        // The nearest crossing of the ray from v with the cell's other edges.
        let mut best: Option<(f64, usize, usize, Coord<f64>)> = None;
        for &k in &ks {
            for (j, w) in edges[k].line.windows(2).enumerate() {
                if w[0] == v || w[1] == v {
                    continue;
                }
                if let Some((t, x)) = ray_hit(v, dir, w[0], w[1]) {
                    if best.is_none_or(|b| t < b.0) {
                        best = Some((t, k, j, x));
                    }
                }
            }
        }
        let Some((_, k, j, x)) = best else { continue };
        let line = &mut edges[k].line;
        let x = if norm(x - line[j]) == 0.0 {
            line[j]
        } else if norm(x - line[j + 1]) == 0.0 {
            line[j + 1]
        } else {
            line.insert(j + 1, x);
            x
        };
        let o = vertices.0[&vk];
        // Walking from v along the bisector, the edge before (whose normal
        // turns left of the bisector) is on the left.
        out.push(Piece {
            line: vec![v, x],
            left: o.before,
            right: o.after,
        });
    }
    out
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

/// The polygon split along `pieces`, each face with its owner (the owner of
/// the most of its bank by length; every bank edge of a face has the same
/// owner unless the boundaries are broken).
pub fn faces(owned: &Owned, pieces: &[Piece]) -> Result<Vec<OwnedFace>, String> {
    let p = PreparedPolygon::new(&owned.polygon).map_err(|e| e.to_string())?;
    let chords: Vec<LineString<f64>> = pieces.iter().map(|q| LineString(q.line.clone())).collect();
    let faces = split_network(&p, &chords).map_err(|e| {
        format!("the new boundaries do not split the polygon ({e}); please report this feature")
    })?;
    Ok(faces
        .into_iter()
        .map(|face| {
            let mut length: FxHashMap<Owner, f64> = FxHashMap::default();
            for r in std::iter::once(face.polygon.exterior()).chain(face.polygon.interiors()) {
                for w in r.0.windows(2) {
                    if owned.is_edge(w[0], w[1]) {
                        *length.entry(owned.owner(w[0], w[1])).or_default() += norm(w[1] - w[0]);
                    }
                }
            }
            let owner = length
                .into_iter()
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
                .and_then(|(o, _)| o);
            OwnedFace { face, owner }
        })
        .collect())
}
