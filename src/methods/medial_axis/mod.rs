//! `MA` — the medial axis (transform) from the Voronoi diagram of the
//! boundary segments (SPEC §3, paper "Medial Axis (Transform)", Fig. 2f).
//!
//! The medial axis of P is the locus of the centres of maximal inscribed
//! discs. It is the part inside P of the Voronoi diagram of the *segments* of
//! ∂P (all rings) and their endpoints, without the edges that come out of
//! concave (reflex) vertices — in the segment Voronoi diagram those are
//! exactly the *secondary* edges, between a segment and its own endpoint.
//! Every node carries its disc radius, and an arc's interior vertices have
//! theirs as their distance to ∂P, so the graph is the Medial Axis
//! Transform; [`crate::graph::widths::medial_axis_transform`] (given the
//! boundary) lists it segment by segment with the local width.
//!
//! # How
//!
//! 1. **Grid.** The diagram is built by [`boostvoronoi`] (Boost.Polygon's
//!    robust sweep; the workspace patches it with closed-form circle events
//!    for a vertex and its own edge, a vertex and two consecutive edges, an
//!    edge with one of its vertices and another vertex, and three
//!    consecutive edges, which the general formulas sent to the exact
//!    big-integer evaluation, and with a treap under its beach line —
//!    `vendor/boostvoronoi/PATCHES.md`), which takes integer input. Coordinates are quantised
//!    relative to the polygon's bounding-box corner on a grid of spacing
//!    `2^-k < extent / 2^26` (**resolution < 1.5e-8 × extent**,
//!    independent of where the polygon lies — 1e7 m coordinates are as exact
//!    as 0). Touches, near-touches and sub-grid slivers that rounding could
//!    turn into crossings are repaired on the grid first (see `quantise`);
//!    input that still self-intersects is rejected with its location.
//! 2. **Diagram.** Infinite edges and secondary edges are dropped. Whether an
//!    edge lies inside P is decided from its sites, not by a point-in-polygon
//!    test: a Voronoi edge of a valid polygon never crosses ∂P, the part of a
//!    segment's cell left of the segment is inside P (interior is left of
//!    every normalised ring), and the cell of a vertex lies wholly inside or
//!    wholly outside. The bisector of two collinear neighbouring segments (the
//!    normal at a straight-angle vertex) is dropped too: its discs touch ∂P
//!    at one point only, so it is not medial.
//! 3. **Arcs.** Edges between a vertex and a segment are parabolic. They are
//!    replaced by polylines whose Hausdorff distance to the exact parabola is
//!    at most the [`ArcTolerance`] (by default 1 % of the local disc radius,
//!    so the quality does not depend on the feature's size). An arc is one
//!    edge: the polyline's inner vertices are its interior, its ends are
//!    nodes with their exact disc radius. (They were nodes each until a
//!    rough rim's millions of arc vertices made the graph its run's largest
//!    allocation; every step merges such chains into one edge anyway.)
//! 4. **Radii.** A node's radius is its distance to its Voronoi sites (the
//!    quantised ∂P), which equals its distance to ∂P within the resolution.
//!
//! ```
//! use geo::polygon;
//! use skeletonise::geometry::PreparedPolygon;
//! use skeletonise::methods::medial_axis::{ArcTolerance, MedialAxis};
//! use skeletonise::methods::{MethodContext, SkeletonMethod};
//! // A 10 × 4 rectangle: centre segment plus four 45° corner legs.
//! let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 4.), (x: 0., y: 4.)];
//! let g = MedialAxis::new(ArcTolerance::default())
//!     .skeletonise(&PreparedPolygon::new(&p).unwrap(), &MethodContext::default())
//!     .unwrap();
//! assert_eq!(g.edges().len(), 5);
//! assert_eq!(g.leg_count(), 4);
//! let widest = g.nodes().iter().map(|n| n.radius).fold(0.0, f64::max);
//! assert!((widest - 2.0).abs() < 1e-8);
//! ```

mod arc;
pub mod cells;
mod quantise;

use super::{MethodContext, MethodError, MethodId, SkeletonMethod};
use crate::geometry::PreparedPolygon;
/// The Medial Axis Transform's pieces, at their old path for the
/// per-feature path (`process`), which imports them from here; their home
/// is [`crate::graph::widths`].
#[doc(no_inline)]
use crate::graph::{NodeId, SkeletonGraph};
use arc::{Parabola, Sample};
use boostvoronoi::prelude::{Builder, Cell, Diagram, SourceCategory, VertexIndex};
use quantise::{orient, Grid, Pt, Seg};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Largest allowed deviation of a polyline from the parabolic arc it
/// approximates (pipeline key `skeleton.arc_tolerance`).
///
/// Written `{relative: 0.01}` or `{absolute: 0.5}`. Tolerances finer than a
/// thousandth of the grid spacing (≈ 1.5e-11 × extent) are raised to it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
pub enum ArcTolerance {
    /// A fraction of the local disc radius (scale-free; default 0.001). A
    /// chord within f·r of the arc shifts the skeleton by at most f·r, so a
    /// bar's distortion z stays below f / (1 − f): the default keeps MA's
    /// distortion Z at about 0.001 or less whatever the data's scale.
    Relative(f64),
    /// CRS units.
    Absolute(f64),
}

impl Default for ArcTolerance {
    fn default() -> Self {
        ArcTolerance::Relative(0.001)
    }
}

impl ArcTolerance {
    /// Checks the value: finite and positive.
    pub fn validate(&self) -> Result<(), String> {
        let (name, v) = match *self {
            ArcTolerance::Relative(v) => ("relative", v),
            ArcTolerance::Absolute(v) => ("absolute", v),
        };
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(format!(
                "`arc_tolerance: {{{name}: {v}}}` must be a positive number, e.g. {{relative: 0.01}} (1 % of the local radius)"
            ))
        }
    }

    /// The allowed deviation (grid units) where the disc radius is `r` (grid units).
    fn at(&self, r: f64, grid: &Grid) -> f64 {
        let t = match *self {
            ArcTolerance::Relative(f) => f * r,
            ArcTolerance::Absolute(d) => d * grid.scale(),
        };
        t.max(TOLERANCE_FLOOR)
    }
}

/// MA's options in the `skeleton` step.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct MedialAxisOptions {
    /// How closely MA's polylines follow its parabolic arcs.
    #[serde(default)]
    pub arc_tolerance: ArcTolerance,
}

impl MedialAxisOptions {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        self.arc_tolerance
            .validate()
            .map_err(|m| ("arc_tolerance".into(), m))
    }
}

/// Finest arc tolerance, in grid units: below the grid spacing the input
/// itself is not known, and this keeps the number of pieces bounded.
const TOLERANCE_FLOOR: f64 = 1e-3;

/// Medial axis from the segment Voronoi diagram.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedialAxis {
    tolerance: ArcTolerance,
}

impl MedialAxis {
    /// A medial axis with the given arc tolerance.
    pub fn new(tolerance: ArcTolerance) -> Self {
        Self { tolerance }
    }
}

impl Default for MedialAxis {
    fn default() -> Self {
        Self::new(ArcTolerance::default())
    }
}

/// The coordinate resolution MA works at for `polygon`: the spacing of the
/// integer grid ∂P is quantised to (CRS units, < 1.5e-8 × extent).
pub fn resolution(polygon: &PreparedPolygon) -> f64 {
    Grid::new(polygon.origin(), polygon.extent())
        .map(|g| g.resolution())
        .unwrap_or(f64::NAN)
}

fn fail(reason: impl Into<String>) -> MethodError {
    MethodError::Failed {
        method: MethodId::MA,
        reason: reason.into(),
    }
}

impl SkeletonMethod for MedialAxis {
    fn id(&self) -> MethodId {
        MethodId::MA
    }

    fn skeletonise(
        &self,
        polygon: &PreparedPolygon,
        _ctx: &MethodContext,
    ) -> Result<SkeletonGraph, MethodError> {
        self.tolerance.validate().map_err(fail)?;
        match quantised(polygon)? {
            Some((grid, segs, diagram)) => {
                let plan = Extractor::new(&diagram, &segs, &grid, self.tolerance).plan()?;
                // The diagram (six half-edges a boundary vertex) is not
                // needed for the graph.
                drop(diagram);
                Ok(plan.graph(&segs, &grid, self.tolerance))
            }
            None => Ok(SkeletonGraph::new()),
        }
    }

    fn skeletonise_with_cells(
        &self,
        polygon: &PreparedPolygon,
        _ctx: &MethodContext,
    ) -> Result<(SkeletonGraph, Option<cells::DiagramCells>), MethodError> {
        self.tolerance.validate().map_err(fail)?;
        match quantised(polygon)? {
            Some((grid, segs, diagram)) => {
                let plan = Extractor::new(&diagram, &segs, &grid, self.tolerance).plan()?;
                let clock = crate::clock::CpuClock::start();
                let edges =
                    Extractor::new(&diagram, &segs, &grid, ArcTolerance::default()).cell_edges()?;
                let time = clock.elapsed();
                drop(diagram);
                let cells = cells::DiagramCells { edges, time };
                Ok((plan.graph(&segs, &grid, self.tolerance), Some(cells)))
            }
            None => Ok((
                SkeletonGraph::new(),
                Some(cells::DiagramCells {
                    edges: Vec::new(),
                    time: std::time::Duration::ZERO,
                }),
            )),
        }
    }
}

/// ∂P on its grid and the Voronoi diagram of its segments (`None` for a
/// boundary of fewer than three segments on the grid).
fn quantised(polygon: &PreparedPolygon) -> Result<Option<(Grid, Vec<Seg>, Diagram)>, MethodError> {
    let grid = Grid::new(polygon.origin(), polygon.extent()).ok_or_else(|| {
        fail(format!(
            "the polygon's extent {} cannot be quantised",
            polygon.extent()
        ))
    })?;
    let segs = quantise::segments(&grid, polygon.rings()).map_err(|c| {
        let w = grid.world(c.at[0] as f64, c.at[1] as f64);
        fail(format!(
            "the boundary intersects itself near ({}, {}) at the method's resolution of {:e} CRS units; repair the polygon (`prepare: {{ make_valid: true }}`)",
            w.x,
            w.y,
            grid.resolution()
        ))
    })?;
    if segs.len() < 3 {
        return Ok(None);
    }
    let diagram = voronoi(&segs)?;
    Ok(Some((grid, segs, diagram)))
}

/// The segment Voronoi diagram; boostvoronoi's errors and panics become a
/// [`MethodError`].
fn voronoi(segs: &[Seg]) -> Result<Diagram, MethodError> {
    let lines: Vec<[i32; 4]> = segs
        .iter()
        .map(|s| [s.a[0], s.a[1], s.b[0], s.b[1]].map(|v| v as i32))
        .collect();
    let built = std::panic::catch_unwind(|| {
        Builder::<i32>::default()
            .with_segments(lines.iter())
            .and_then(|b| b.build())
    });
    match built {
        Ok(Ok(d)) => Ok(d),
        Ok(Err(e)) => Err(fail(format!(
            "the segment Voronoi diagram failed: {e} ({e:?})"
        ))),
        Err(panic) => {
            let msg = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("unknown panic");
            Err(fail(format!(
                "the segment Voronoi diagram panicked ({msg}); please report the feature"
            )))
        }
    }
}

/// The site of a Voronoi cell.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Site {
    Point(Pt),
    Segment(usize),
}

fn fpt(p: Pt) -> [f64; 2] {
    [p[0] as f64, p[1] as f64]
}

/// Signed distance-like side of `q` relative to `a → b` (positive = left).
fn side(s: &Seg, q: [f64; 2]) -> f64 {
    let (a, b) = (fpt(s.a), fpt(s.b));
    (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0])
}

/// Distance from `q` to a site (grid units).
fn site_distance(site: Site, segs: &[Seg], q: [f64; 2]) -> f64 {
    match site {
        Site::Point(p) => {
            let p = fpt(p);
            (q[0] - p[0]).hypot(q[1] - p[1])
        }
        Site::Segment(i) => {
            let (a, b) = (fpt(segs[i].a), fpt(segs[i].b));
            let d = [b[0] - a[0], b[1] - a[1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            let t = (((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0);
            (q[0] - a[0] - t * d[0]).hypot(q[1] - a[1] - t * d[1])
        }
    }
}

/// Voronoi edges shorter than this (grid units) are contracted to a point:
/// rounding to the grid perturbs junctions by about one unit.
const CONTRACT: f64 = 4.0;

/// A Voronoi edge kept for the medial axis: its vertices and the cells of
/// its two sites (20 bytes: a rough rim keeps millions of them).
#[derive(Debug, Clone, Copy)]
struct Kept {
    v0: VertexIndex,
    v1: VertexIndex,
    cells: [u32; 2],
    curved: bool,
}

/// The root of `x` in the union-find forest `rep` (paths halved).
fn find(rep: &mut [usize], mut x: usize) -> usize {
    while rep[x] != x {
        rep[x] = rep[rep[x]];
        x = rep[x];
    }
    x
}

/// Walks the diagram once and builds the skeleton graph.
struct Extractor<'a> {
    diagram: &'a Diagram,
    segs: &'a [Seg],
    grid: &'a Grid,
    tolerance: ArcTolerance,
    /// Whether a vertex's cell lies inside P, once known.
    point_cell_inside: Vec<Option<bool>>,
}

impl<'a> Extractor<'a> {
    fn new(diagram: &'a Diagram, segs: &'a [Seg], grid: &'a Grid, tolerance: ArcTolerance) -> Self {
        Self {
            diagram,
            segs,
            grid,
            tolerance,
            point_cell_inside: vec![None; diagram.cells().len()],
        }
    }

    fn site(&self, cell: &Cell) -> Site {
        let i = cell.source_index().usize();
        match cell.source_category() {
            SourceCategory::Segment => Site::Segment(i),
            SourceCategory::SegmentStart => Site::Point(self.segs[i].a),
            SourceCategory::SegmentEnd => Site::Point(self.segs[i].b),
            // Only segments are fed to the builder.
            SourceCategory::SinglePoint => Site::Point(self.segs[i].a),
        }
    }

    /// The sites of a kept edge's two cells.
    fn sites(&self, k: &Kept) -> (Site, Site) {
        let cells = self.diagram.cells();
        let [c0, c1] = k.cells.map(|c| &cells[c as usize]);
        (self.site(c0), self.site(c1))
    }

    fn vertex(&self, v: VertexIndex) -> [f64; 2] {
        self.vertex_at(v.usize())
    }

    fn vertex_at(&self, v: usize) -> [f64; 2] {
        let v = &self.diagram.vertices()[v];
        [v.x(), v.y()]
    }

    /// What the graph is made of, read from the diagram (which the caller
    /// may then drop): the kept edges between two clusters and the
    /// clusters' nodes in the order the graph makes them.
    fn plan(mut self) -> Result<Plan, MethodError> {
        let kept = self.inside_edges(false)?;
        let mut rep = self.representatives(&kept);
        // The kept edges between two clusters, with their ends.
        // A cluster's node is made where an edge first reaches it, placed
        // by that edge's first site.
        let mut made = vec![false; self.diagram.vertices().len()];
        let mut nodes = Vec::new();
        let mut joined = Vec::with_capacity(kept.len());
        for k in &kept {
            let (r0, r1) = (find(&mut rep, k.v0.usize()), find(&mut rep, k.v1.usize()));
            if r0 == r1 {
                continue;
            }
            let (s0, s1) = self.sites(k);
            for v in [r0, r1] {
                if !std::mem::replace(&mut made[v], true) {
                    let (pos, r) = self.position(v, s0);
                    nodes.push((pos, self.grid.length(r)));
                }
            }
            let arc = match (k.curved, s0, s1) {
                (true, Site::Point(q), Site::Segment(s))
                | (true, Site::Segment(s), Site::Point(q)) => Some((q, s as u32)),
                _ => None,
            };
            joined.push(Joined {
                r: [r0, r1].map(|r| r as u32),
                p: [self.vertex_at(r0), self.vertex_at(r1)],
                arc,
            });
        }
        Ok(Plan {
            joined,
            nodes,
            vertices: made.len(),
        })
    }

    /// The representative of every Voronoi vertex after contracting the
    /// edges shorter than the grid can resolve (the several Voronoi
    /// vertices a near-regular junction splits into), never moving a vertex
    /// more than [`CONTRACT`] from its cluster's representative: a union-find
    /// forest to [`find`] in.
    fn representatives(&self, kept: &[Kept]) -> Vec<usize> {
        let mut rep: Vec<usize> = (0..self.diagram.vertices().len()).collect();
        for k in kept {
            let (a, b) = (find(&mut rep, k.v0.usize()), find(&mut rep, k.v1.usize()));
            if a != b {
                let (pa, pb) = (self.vertex_at(a), self.vertex_at(b));
                if (pa[0] - pb[0]).hypot(pa[1] - pb[1]) < CONTRACT {
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    rep[hi] = lo;
                }
            }
        }
        rep
    }

    /// The finite edges inside P, once each: the primary ones that are
    /// medial, or with `all` every one (secondary edges, between a segment
    /// and its endpoint, and the normals at straight-angle vertices too:
    /// the boundaries of every site's cell).
    fn inside_edges(&mut self, all: bool) -> Result<Vec<Kept>, MethodError> {
        let d = self.diagram;
        let edges = d.edges();
        let mut kept = Vec::new();
        for (i, e) in edges.iter().enumerate() {
            let twin = e
                .twin()
                .map_err(|err| fail(format!("malformed Voronoi diagram: {err}")))?;
            if twin.usize() < i || !(all || e.is_primary()) {
                continue;
            }
            let (Some(v0), Some(v1)) = (e.vertex0(), edges[twin.usize()].vertex0()) else {
                continue; // infinite: outside P
            };
            let (Ok(c0), Ok(c1)) = (e.cell(), edges[twin.usize()].cell()) else {
                return Err(fail("malformed Voronoi diagram: edge without cell"));
            };
            let (cell0, cell1) = (&d.cells()[c0.usize()], &d.cells()[c1.usize()]);
            let (s0, s1) = (self.site(cell0), self.site(cell1));
            let (p0, p1) = (self.vertex(v0), self.vertex(v1));
            if p0 == p1 {
                continue;
            }
            let mid = [0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1])];
            // With `all`: the normal at a straight-angle vertex between
            // Voronoi vertices on both sides of ∂P (the cells cut it at the
            // vertex).
            let straddles = all
                && match (s0, s1) {
                    (Site::Point(q), Site::Segment(s)) | (Site::Segment(s), Site::Point(q)) => {
                        let sg = &self.segs[s];
                        (sg.a == q || sg.b == q) && side(sg, p0) * side(sg, p1) < 0.0
                    }
                    _ => false,
                };
            let inside = straddles
                || match (s0, s1) {
                    (Site::Segment(s), _) | (_, Site::Segment(s)) => side(&self.segs[s], mid) > 0.0,
                    _ => self.point_cell_is_inside(cell0) || self.point_cell_is_inside(cell1),
                };
            if !inside {
                continue;
            }
            if let (false, Site::Segment(a), Site::Segment(b)) = (all, s0, s1) {
                if self.straight_angle(a, b) {
                    continue;
                }
            }
            kept.push(Kept {
                v0,
                v1,
                cells: [c0.u32(), c1.u32()],
                curved: e.is_curved(),
            });
        }
        Ok(kept)
    }

    /// True for two neighbouring collinear segments: their bisector is the
    /// normal at the straight-angle vertex between them.
    fn straight_angle(&self, a: usize, b: usize) -> bool {
        let (s, t) = (self.segs[a], self.segs[b]);
        let shares = s.a == t.a || s.a == t.b || s.b == t.a || s.b == t.b;
        shares && orient(s.a, s.b, t.a) == 0 && orient(s.a, s.b, t.b) == 0
    }

    /// Whether the cell of a point site lies inside P, from any of its edges
    /// shared with a segment cell (the cell never straddles ∂P).
    fn point_cell_is_inside(&mut self, cell: &Cell) -> bool {
        if let Some(known) = self.point_cell_inside[cell.id().usize()] {
            return known;
        }
        let d = self.diagram;
        let mut verdict = false;
        for e in d.cell_edge_iterator(cell.id()) {
            let edge = &d.edges()[e.usize()];
            let Ok(twin) = edge.twin() else { continue };
            let twin_edge = &d.edges()[twin.usize()];
            let Ok(tc) = twin_edge.cell() else { continue };
            let Site::Segment(s) = self.site(&d.cells()[tc.usize()]) else {
                continue;
            };
            let (Some(v0), Some(v1)) = (edge.vertex0(), twin_edge.vertex0()) else {
                // Reaches infinity: the cell is outside.
                verdict = false;
                break;
            };
            let (p0, p1) = (self.vertex(v0), self.vertex(v1));
            let m = [0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1])];
            let sd = side(&self.segs[s], m);
            if sd != 0.0 {
                verdict = sd > 0.0;
                break;
            }
        }
        self.point_cell_inside[cell.id().usize()] = Some(verdict);
        verdict
    }

    /// Where Voronoi vertex `v`, whose disc touches `site`, lies in world
    /// coordinates, and its disc radius (grid units).
    fn position(&self, v: usize, site: Site) -> (geo::Coord<f64>, f64) {
        let p = self.vertex_at(v);
        let r = site_distance(site, self.segs, p);
        let pos = match (r == 0.0, site) {
            // On ∂P (a convex corner): the input vertex itself, not its rounding.
            (true, Site::Segment(s)) if p == fpt(self.segs[s].a) => self.segs[s].wa,
            (true, Site::Segment(s)) if p == fpt(self.segs[s].b) => self.segs[s].wb,
            (true, Site::Point(q)) if p == fpt(q) => self
                .segs
                .iter()
                .find(|s| s.a == q)
                .map_or_else(|| self.grid.world(p[0], p[1]), |s| s.wa),
            _ => self.grid.world(p[0], p[1]),
        };
        (pos, r)
    }
}

/// A kept edge of the Voronoi diagram between the clusters `r` (their
/// representatives, at `p`), with its arc's point and segment sites when
/// it is a parabolic arc.
struct Joined {
    r: [u32; 2],
    p: [[f64; 2]; 2],
    arc: Option<(Pt, u32)>,
}

/// [`Plan::graph`] samples the arcs on every core from this many edges
/// on (fewer: on the calling thread — most polygons, in a run that has a
/// thread per feature already).
const ARCS_IN_PARALLEL: usize = 1 << 15;

/// The arcs are sampled this many edges at a time, each batch stored in
/// one vector of the exact size: no vector per arc, no doubling slack.
const ARC_BATCH: usize = 1 << 16;

/// The skeleton graph's parts, without the Voronoi diagram they came from.
struct Plan {
    joined: Vec<Joined>,
    /// The clusters' nodes (position, radius in CRS units), in the order
    /// the edges first reach them.
    nodes: Vec<(geo::Coord<f64>, f64)>,
    /// The diagram's number of vertices.
    vertices: usize,
}

/// The interior samples of a batch of edges, edge after edge: edge `i`'s
/// are `samples[ends[i - 1]..ends[i]]` (from 0 for the first).
struct Arcs {
    samples: Vec<Sample>,
    ends: Vec<usize>,
}

impl Plan {
    /// The graph: every joined edge in order, its clusters' nodes made where
    /// it first reaches them, its arc's samples as its interior.
    fn graph(self, segs: &[Seg], grid: &Grid, tolerance: ArcTolerance) -> SkeletonGraph {
        let Plan {
            joined,
            nodes,
            vertices,
        } = self;
        let sample = |j: &Joined| {
            j.arc
                .and_then(|(q, s)| arc_samples(segs, grid, tolerance, j.p, q, s as usize))
                .unwrap_or_default()
        };
        // The arcs' samples first (on every core for a large diagram: a
        // rough rim's medial axis has millions of them), then the graph,
        // with room for exactly all of it.
        let batches: Vec<Arcs> = joined
            .chunks(ARC_BATCH)
            .map(|batch| {
                let arcs: Vec<Vec<Sample>> = if joined.len() >= ARCS_IN_PARALLEL {
                    use rayon::prelude::*;
                    batch.par_iter().map(sample).collect()
                } else {
                    batch.iter().map(sample).collect()
                };
                let mut samples = Vec::with_capacity(arcs.iter().map(Vec::len).sum());
                let ends = arcs
                    .into_iter()
                    .map(|a| {
                        samples.extend(a);
                        samples.len()
                    })
                    .collect();
                Arcs { samples, ends }
            })
            .collect();
        let clusters: Vec<[u32; 2]> = joined.iter().map(|j| j.r).collect();
        drop(joined);
        let mut graph = SkeletonGraph::new();
        graph.reserve(nodes.len(), clusters.len());
        let mut node_of: Vec<Option<NodeId>> = vec![None; vertices];
        let mut nodes = nodes.into_iter();
        let mut node = |graph: &mut SkeletonGraph, v: u32| {
            *node_of[v as usize].get_or_insert_with(|| {
                let (pos, r) = nodes.next().expect("the plan has a node for every cluster");
                graph.add_node(pos, r, None)
            })
        };
        let arcs = batches.iter().flat_map(|b| {
            b.ends.iter().scan(0, |start, &end| {
                Some(&b.samples[std::mem::replace(start, end)..end])
            })
        });
        // An arc's samples are its edge's interior vertices: a rough rim's
        // medial axis has six times as many of them as Voronoi vertices.
        // Their radius is their distance to ∂P; the largest radius on an
        // arc is at one of its ends (a parabola's distance to its focus
        // grows away from its apex), so the widest node is still a node.
        for (r, arc) in clusters.iter().zip(arcs) {
            let n0 = node(&mut graph, r[0]);
            let n1 = node(&mut graph, r[1]);
            let interior = arc.iter().map(|smp| grid.world(smp.x, smp.y)).collect();
            graph.add_edge(n0, n1, interior);
        }
        graph
    }
}

/// The interior samples of the parabolic edge from `p[0]` to `p[1]`
/// between the point site `point` and the segment `seg` (grid units), or
/// `None` when it is degenerate (drawn straight).
fn arc_samples(
    segs: &[Seg],
    grid: &Grid,
    tolerance: ArcTolerance,
    p: [[f64; 2]; 2],
    point: Pt,
    seg: usize,
) -> Option<Vec<Sample>> {
    let s = segs[seg];
    let par = Parabola::new(fpt(point), fpt(s.a), fpt(s.b))?;
    Some(par.samples(par.abscissa(p[0]), par.abscissa(p[1]), |r| {
        tolerance.at(r, grid)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    /// A rectangle with a hole: the graph's invariants, and every node's
    /// radius is its disc's (its distance to ∂P, within the grid).
    #[test]
    fn a_rectangle_with_a_hole_keeps_the_graphs_invariants() {
        let p = polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 6.), (x: 0., y: 6.)],
            interiors: [[(x: 4., y: 2.), (x: 4., y: 4.), (x: 6., y: 4.), (x: 6., y: 2.)]],
        );
        let pp = PreparedPolygon::new(&p).unwrap();
        let g = crate::methods::checked_skeleton(&MedialAxis::default(), &pp);
        assert!(!g.is_empty());
        let tol = 4.0 * resolution(&pp);
        for n in g.nodes() {
            assert!(
                (n.radius - pp.boundary().distance(n.pos)).abs() <= tol,
                "{n:?}"
            );
        }
    }
}
