//! The kinetic wavefront: supporting lines of the original edges and the
//! active wavefront vertices kept in circular doubly linked lists.
//!
//! Handles are typed indices into `Vec`s ([`LineId`], [`VertexId`]), never
//! pointers. Vertices are immutable once created except for their links and
//! their `active` flag: an event deactivates the vertices it consumes and
//! creates new ones, so an event that names a vertex is still valid exactly
//! when that vertex is still active (lazy invalidation, no version counter
//! needed).

use crate::geometry::vector::{cross, dot, hypot};
use geo::Coord;

pub use handle::{LineId, VertexId};

/// The handles, in a module of their own so that their number is read and
/// made only through `index` and `from_index`.
mod handle {
    #[cfg(doc)]
    use super::Wavefront;

    /// Index of a supporting line (one per original boundary edge).
    ///
    /// Invariant: `LineId::from_index(i)` indexes [`Wavefront::lines`].
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    pub struct LineId(u32);

    /// Index of a wavefront vertex.
    ///
    /// Invariant: `VertexId::from_index(i)` indexes [`Wavefront::vertices`];
    /// vertices are never removed, only deactivated.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    pub struct VertexId(u32);

    impl LineId {
        /// The handle of the line at position `i` (below 2³²).
        #[inline]
        pub fn from_index(i: usize) -> Self {
            debug_assert!(u32::try_from(i).is_ok(), "line index {i}");
            Self(i as u32)
        }

        /// Its position in [`Wavefront::lines`].
        #[inline]
        pub fn index(self) -> usize {
            self.0 as usize
        }
    }

    impl VertexId {
        /// The handle of the vertex at position `i` (below 2³²).
        #[inline]
        pub fn from_index(i: usize) -> Self {
            debug_assert!(u32::try_from(i).is_ok(), "vertex index {i}");
            Self(i as u32)
        }

        /// Its position in [`Wavefront::vertices`].
        #[inline]
        pub fn index(self) -> usize {
            self.0 as usize
        }
    }
}

/// The supporting line of one original edge and its motion: at time `t` the
/// wavefront edge lies on `normal · x = c + t`.
///
/// Invariant: `dir` and `normal` are unit vectors, `normal` is `dir` turned
/// left (towards the interior of P, since every ring has P on its left).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// Start of the original edge (local coordinates).
    pub a: Coord<f64>,
    /// End of the original edge (local coordinates).
    pub b: Coord<f64>,
    /// Unit direction a → b.
    pub dir: Coord<f64>,
    /// Unit inward normal.
    pub normal: Coord<f64>,
    /// `normal · a`.
    pub c: f64,
}

impl Line {
    /// The line through the edge `a → b` (which must have non-zero length).
    pub fn new(a: Coord<f64>, b: Coord<f64>) -> Self {
        let d = b - a;
        let len = hypot(d);
        let dir = Coord {
            x: d.x / len,
            y: d.y / len,
        };
        let normal = Coord {
            x: -dir.y,
            y: dir.x,
        };
        Self {
            a,
            b,
            dir,
            normal,
            c: dot(normal, a),
        }
    }

    /// Signed distance of `p` in front of the wavefront of this line at time `t`.
    pub fn ahead(&self, p: Coord<f64>, t: f64) -> f64 {
        dot(self.normal, p) - self.c - t
    }
}

/// A wavefront vertex: the intersection of its two wavefront edges, moving
/// at constant velocity from `start` (at time `t0`) while active.
///
/// Invariant: while `active`, `prev`/`next` are active and link back to it;
/// `left` is the line of the edge from `prev` to this vertex, `right` the
/// line of the edge to `next`; `vel · normal = 1` for both lines (`vel` is
/// `None` only for a fold, resolved before the vertex takes part in events).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    /// Position at creation (local coordinates).
    pub start: Coord<f64>,
    /// Creation time (offset distance).
    pub t0: f64,
    /// Velocity, `None` when the two lines are antiparallel (a fold).
    pub vel: Option<Coord<f64>>,
    /// Line of the incoming wavefront edge.
    pub left: LineId,
    /// Line of the outgoing wavefront edge.
    pub right: LineId,
    /// Previous vertex in its wavefront ring.
    pub prev: VertexId,
    /// Next vertex in its wavefront ring.
    pub next: VertexId,
    /// Still part of the wavefront.
    pub active: bool,
    /// The wavefront turns right here (interior angle above 180°).
    pub reflex: bool,
    /// For input vertices, the exact original coordinate (absolute).
    pub exact: Option<Coord<f64>>,
}

/// `1 + n1 · n2` below this makes two lines a fold (antiparallel): the
/// vertex speed `sqrt(2 / (1 + n1·n2))` would exceed about 1.4 million.
/// Nearly antiparallel lines above it keep their (fast) vertex: zipping
/// them up as a fold would end traces off their offset lines.
pub const FOLD_EPS: f64 = 1e-12;

/// Velocity of the intersection of two lines moving along their unit
/// normals at unit speed: `(n1 + n2) / (1 + n1·n2)`, `None` for a fold.
pub fn velocity(l1: &Line, l2: &Line) -> Option<Coord<f64>> {
    let d = 1.0 + dot(l1.normal, l2.normal);
    if d < FOLD_EPS {
        return None;
    }
    Some(Coord {
        x: (l1.normal.x + l2.normal.x) / d,
        y: (l1.normal.y + l2.normal.y) / d,
    })
}

/// All lines and vertices of the propagating wavefront.
#[derive(Debug, Default)]
pub struct Wavefront {
    /// Supporting lines, one per original edge.
    pub lines: Vec<Line>,
    /// Every vertex ever created.
    pub vertices: Vec<Vertex>,
    /// Per line, the vertices created with that line as `right` (the start
    /// vertices of its wavefront pieces); stale entries are skipped on use.
    pub pieces: Vec<Vec<VertexId>>,
}

impl Wavefront {
    /// One vertex.
    pub fn v(&self, id: VertexId) -> &Vertex {
        &self.vertices[id.index()]
    }

    /// One vertex, mutable.
    pub fn v_mut(&mut self, id: VertexId) -> &mut Vertex {
        &mut self.vertices[id.index()]
    }

    /// One line.
    pub fn line(&self, id: LineId) -> &Line {
        &self.lines[id.index()]
    }

    /// Position of vertex `id` at time `t`.
    pub fn pos(&self, id: VertexId, t: f64) -> Coord<f64> {
        let v = self.v(id);
        match v.vel {
            Some(s) => v.start + s * (t - v.t0),
            None => v.start,
        }
    }

    /// Creates an (unlinked) active vertex at `start`, time `t0`, between
    /// lines `left` and `right`.
    pub fn add_vertex(
        &mut self,
        start: Coord<f64>,
        t0: f64,
        left: LineId,
        right: LineId,
        exact: Option<Coord<f64>>,
    ) -> VertexId {
        let (l1, l2) = (*self.line(left), *self.line(right));
        let vel = velocity(&l1, &l2);
        let reflex = vel.is_some() && cross(l1.dir, l2.dir) < 0.0;
        let id = VertexId::from_index(self.vertices.len());
        self.vertices.push(Vertex {
            start,
            t0,
            vel,
            left,
            right,
            prev: id,
            next: id,
            active: true,
            reflex,
            exact,
        });
        self.pieces[right.index()].push(id);
        id
    }

    /// Links `a → b`.
    pub fn link(&mut self, a: VertexId, b: VertexId) {
        self.v_mut(a).next = b;
        self.v_mut(b).prev = a;
    }

    /// Whether `line` still has a piece in the wavefront (dropping the
    /// stale entries of its list). A line without one never gets one back:
    /// new vertices take their lines from active ones.
    pub fn line_alive(&mut self, line: LineId) -> bool {
        let vertices = &self.vertices;
        let pieces = &mut self.pieces[line.index()];
        pieces.retain(|&x| vertices[x.index()].active);
        !pieces.is_empty()
    }

    /// Deactivates a vertex.
    pub fn kill(&mut self, id: VertexId) {
        self.v_mut(id).active = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_of_a_right_angle_and_a_fold() {
        let bottom = Line::new(Coord { x: 0.0, y: 0.0 }, Coord { x: 1.0, y: 0.0 });
        let right = Line::new(Coord { x: 1.0, y: 0.0 }, Coord { x: 1.0, y: 1.0 });
        let s = velocity(&bottom, &right).unwrap();
        assert!((s.x + 1.0).abs() < 1e-15 && (s.y - 1.0).abs() < 1e-15);
        let back = Line::new(Coord { x: 1.0, y: 0.0 }, Coord { x: 0.0, y: 0.0 });
        assert!(velocity(&bottom, &back).is_none());
        let same = Line::new(Coord { x: 1.0, y: 0.0 }, Coord { x: 2.0, y: 0.0 });
        let s = velocity(&bottom, &same).unwrap();
        assert_eq!(s, Coord { x: 0.0, y: 1.0 });
    }
}
