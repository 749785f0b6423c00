//! Who owns each edge of a collapsed polygon: the coverage's units indexed
//! by their boundary segments, a unit vertex that lies on one of the
//! polygon's edges (a T-junction) inserted there, every edge of the polygon
//! given to the unit whose boundary it lies on (or to none: unowned bank).

use crate::geometry::coverage::{edge_key, EdgeKey};
use crate::geometry::segment::{closest_on_segment, inner_points_along};
use crate::geometry::vector::norm;
use crate::geometry::CoordKey;
use crate::geometry::{Boundary, PreparedPolygon};
use crate::neighbours::Indexed;
use geo::{Coord, LineString, Polygon};
use rustc_hash::FxHashMap;

pub use crate::neighbours::{Coverage, Unit};

/// A collapsed polygon with its owners: the polygon with every T-junction
/// inserted, and the unit (an index into the coverage) that owns each of
/// its edges, by the edge's two ends.
#[derive(Debug, Clone)]
pub struct Owned {
    /// The polygon, its rings normalised, the units' vertices on its edges
    /// inserted.
    pub polygon: Polygon<f64>,
    /// The polygon before any point was put into its edges (its vertices
    /// moved onto the units' where they meet): the segment Voronoi diagram
    /// is of this one, and [`Self::splits`] says where its edges were
    /// split.
    pub base: Polygon<f64>,
    owner: FxHashMap<EdgeKey, Option<u32>>,
}

fn key(c: Coord<f64>) -> CoordKey {
    CoordKey::from(c)
}

impl Owned {
    /// The owner of the polygon's edge from `a` to `b` (`None`: unowned or
    /// no such edge).
    pub fn owner(&self, a: Coord<f64>, b: Coord<f64>) -> Option<u32> {
        self.owner.get(&edge_key(a, b)).copied().flatten()
    }

    /// Whether `a`–`b` is an edge of the polygon.
    pub fn is_edge(&self, a: Coord<f64>, b: Coord<f64>) -> bool {
        self.owner.contains_key(&edge_key(a, b))
    }

    /// The polygon with `points` (each within `tol` of its boundary) put
    /// into the edges they lie on — or, within `tol` of a vertex, that
    /// vertex — the new edges owned as the edge they split; and each point
    /// as it now is in the polygon (`None`: not on its boundary).
    pub fn with_points(&self, points: &[Coord<f64>], tol: f64) -> (Owned, Vec<Option<Coord<f64>>>) {
        let b = Boundary::new(&self.polygon);
        let mut inserts = Inserts::default();
        let mut at = Vec::with_capacity(points.len());
        for &v in points {
            let on = b.nearest_within(v, tol).and_then(|(_, i, d)| {
                let s = &b.segments()[i];
                if norm(v - s.a) <= tol {
                    Some(s.a)
                } else if norm(v - s.b) <= tol {
                    Some(s.b)
                } else if d <= tol {
                    inserts.entry((s.ring, s.index)).or_default().push(v);
                    Some(v)
                } else {
                    None
                }
            });
            at.push(on);
        }
        let polygon = with_inserted(&self.polygon, &inserts, |c| c);
        let old_rings = std::iter::once(self.polygon.exterior()).chain(self.polygon.interiors());
        let new_rings = std::iter::once(polygon.exterior()).chain(polygon.interiors());
        let mut owner = FxHashMap::default();
        for (old, new) in old_rings.zip(new_rings) {
            // Each new edge lies in the old edge from the last old vertex
            // passed: the points were put between the old vertices.
            let mut k = 0;
            for w in new.0.windows(2) {
                let o = self.owner(old.0[k], old.0[k + 1]);
                owner.insert(edge_key(w[0], w[1]), o);
                if w[1] == old.0[k + 1] {
                    k += 1;
                }
            }
        }
        let base = self.base.clone();
        (
            Owned {
                polygon,
                base,
                owner,
            },
            at,
        )
    }

    /// Every edge of [`Self::base`] that points were put into, by its key:
    /// its vertices in the polygon from its start to its end (the points
    /// put in, in order between them).
    pub fn splits(&self) -> FxHashMap<EdgeKey, Vec<Coord<f64>>> {
        let mut out = FxHashMap::default();
        let base = std::iter::once(self.base.exterior()).chain(self.base.interiors());
        let new = std::iter::once(self.polygon.exterior()).chain(self.polygon.interiors());
        for (old, new) in base.zip(new) {
            // The base's vertices are the polygon's, in order, with the
            // points put in between them.
            let mut k = 0;
            let mut run = vec![old.0[0]];
            for &c in &new.0[1..] {
                run.push(c);
                if old.0.get(k + 1) == Some(&c) {
                    if run.len() > 2 {
                        out.insert(edge_key(old.0[k], c), std::mem::take(&mut run));
                    }
                    run.clear();
                    run.push(c);
                    k += 1;
                }
            }
        }
        out
    }

    /// The owner of base edge `a`–`b` (see [`Self::base`]) at the foot of
    /// point `x` on it, with `splits` from [`Self::splits`]: where points
    /// were put into the edge, the owner of the piece the foot lies on.
    pub fn owner_along(
        &self,
        splits: &FxHashMap<EdgeKey, Vec<Coord<f64>>>,
        a: Coord<f64>,
        b: Coord<f64>,
        x: Coord<f64>,
    ) -> Option<u32> {
        let Some(run) = splits.get(&edge_key(a, b)) else {
            return self.owner(a, b);
        };
        let d = b - a;
        let along = |c: Coord<f64>| crate::geometry::vector::dot(c - a, d);
        let s = along(x);
        let i = run[1..run.len() - 1]
            .iter()
            .take_while(|&&c| along(c) <= s)
            .count();
        self.owner(run[i], run[i + 1])
    }

    /// The owners of the edges into and out of every vertex.
    pub fn at_vertices(&self) -> FxHashMap<CoordKey, VertexOwners> {
        let mut out = FxHashMap::default();
        for r in std::iter::once(self.polygon.exterior()).chain(self.polygon.interiors()) {
            let n = r.0.len() - 1;
            for i in 0..n {
                let (u, v, w) = (r.0[(i + n - 1) % n], r.0[i], r.0[i + 1]);
                out.insert(
                    key(v),
                    VertexOwners {
                        before: self.owner(u, v),
                        after: self.owner(v, w),
                        into: v - u,
                        out_of: w - v,
                    },
                );
            }
        }
        out
    }
}

/// The owners of the two edges at a vertex, and their directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexOwners {
    /// The edge that ends at the vertex.
    pub before: Option<u32>,
    /// The edge that starts there.
    pub after: Option<u32>,
    /// The direction of the edge before.
    pub into: Coord<f64>,
    /// The direction of the edge after.
    pub out_of: Coord<f64>,
}

/// `p` with its owners in `cov`, whose units meet it only along its
/// boundary (cut by it: [`super::cut`]); its [base](Owned::base) is `of`
/// (whose vertices are `p`'s, `p` having more inside its edges: where the
/// units were snapped onto it) with the same vertices moved.
pub fn owned(p: &PreparedPolygon, of: &Polygon<f64>, cov: &Coverage, tol: f64) -> Owned {
    let (polygon, base) = with_t_junctions(p, of, cov, tol);
    let mut owner = FxHashMap::default();
    for r in std::iter::once(polygon.exterior()).chain(polygon.interiors()) {
        for w in r.0.windows(2) {
            owner.insert(edge_key(w[0], w[1]), owner_of(cov, w[0], w[1], tol));
        }
    }
    Owned {
        polygon,
        base,
        owner,
    }
}

/// The unit whose boundary holds the edge `a`–`b` (both ends within `tol`
/// of one of its segments).
fn owner_of(cov: &Coverage, a: Coord<f64>, b: Coord<f64>, tol: f64) -> Option<u32> {
    let on = |s: &Indexed, c: Coord<f64>| {
        let (f, t) = (s.geom().from, s.geom().to);
        let (q, _) = closest_on_segment(Coord { x: f[0], y: f[1] }, Coord { x: t[0], y: t[1] }, c);
        norm(q - c) <= tol
    };
    cov.near(a, b, tol)
        .filter(|s| on(s, a) && on(s, b))
        .map(|s| s.data)
        .min()
}

/// `p`'s rings with every unit vertex that lies on one of its edges (within
/// `tol`, not at its ends) inserted there, and every vertex of `p` within
/// `tol` of a unit vertex moved onto it, with the unit's coordinates: where
/// they meet, the polygon and the units then share their vertices exactly
/// (the units keep theirs bit for bit); and `of` with only the moves.
fn with_t_junctions(
    p: &PreparedPolygon,
    of: &Polygon<f64>,
    cov: &Coverage,
    tol: f64,
) -> (Polygon<f64>, Polygon<f64>) {
    let b = p.boundary();
    let (lo, hi) = (b.bbox_min(), b.bbox_max());
    let mut inserts = Inserts::default();
    let mut moves: FxHashMap<CoordKey, Coord<f64>> = FxHashMap::default();
    // A unit vertex that is one of the polygon's is where it should be.
    let own: rustc_hash::FxHashSet<CoordKey> = p
        .rings()
        .flat_map(|r| r.0.iter().map(|&c| key(c)))
        .collect();
    for s in cov.near(lo, hi, tol) {
        let v = Coord {
            x: s.geom().from[0],
            y: s.geom().from[1],
        };
        if own.contains(&key(v)) {
            continue;
        }
        let Some((_, i, d)) = b.nearest_within(v, tol) else {
            continue;
        };
        let seg = &b.segments()[i];
        if d > tol {
            continue;
        }
        match [seg.a, seg.b].into_iter().find(|&e| norm(v - e) <= tol) {
            Some(e) if e != v => {
                moves.insert(key(e), v);
            }
            Some(_) => {}
            None => inserts.entry((seg.ring, seg.index)).or_default().push(v),
        }
    }
    let moved = |c: Coord<f64>| moves.get(&key(c)).copied().unwrap_or(c);
    let base = match moves.is_empty() {
        true => of.clone(),
        false => with_inserted(of, &Inserts::default(), moved),
    };
    (with_inserted(p.polygon(), &inserts, moved), base)
}

/// Where points go into a polygon's edges: by (ring, edge index), ring 0
/// the exterior.
pub(super) type Inserts = FxHashMap<(u32, u32), Vec<Coord<f64>>>;

/// `p` with the points of `inserts` put into their edges, in order along
/// each edge (repeats once), and every vertex of `p` taken through `moved`.
pub(super) fn with_inserted(
    p: &Polygon<f64>,
    inserts: &Inserts,
    moved: impl Fn(Coord<f64>) -> Coord<f64>,
) -> Polygon<f64> {
    let ring = |r: usize, l: &LineString<f64>| {
        let mut out = Vec::with_capacity(l.0.len());
        for (i, w) in l.0.windows(2).enumerate() {
            out.push(moved(w[0]));
            if let Some(extra) = inserts.get(&(r as u32, i as u32)) {
                out.extend(inner_points_along(w[0], w[1], extra));
            }
        }
        out.push(moved(l.0[l.0.len() - 1]));
        LineString(out)
    };
    Polygon::new(
        ring(0, p.exterior()),
        p.interiors()
            .iter()
            .enumerate()
            .map(|(k, r)| ring(k + 1, r))
            .collect(),
    )
}
