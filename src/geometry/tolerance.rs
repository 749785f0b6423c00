//! Every tolerance of the geometry, the graph, the methods, the scores and
//! the collapse step, in one table.
//!
//! Two kinds:
//!
//! * **Relative to the polygon** — multiplied by
//!   [`super::PreparedPolygon::extent`] (the larger side of the bounding
//!   box), so that the same decisions are taken at any scale and in any CRS:
//!   `tol = SAME_POINT * polygon.extent()`.
//! * **Rounding margins** — relative to the magnitude of a computed value,
//!   so that a bound computed in floating point stays a bound: a lower
//!   bound is shrunk by it and an upper bound widened, which can make a
//!   search look at more candidates but never changes its answer.
//!
//! | constant | value | kind | for |
//! |---|---|---|---|
//! | [`SAME_POINT`] | 10⁻⁹ | × extent | one point; on ∂P (SPEC §3) |
//! | [`ON_BOUNDARY_END`] | 10⁻⁷ | × extent | a line end on ∂P |
//! | [`ROUND_OFF`] | 10⁻⁷ | × extent | a second input's vertex on ∂P |
//! | [`BAR_ORIGIN`] | 10⁻⁶ | × extent | a bar's hit at its own origin |
//! | [`TRACE_CROSSING`] | 10⁻⁶ | × extent | the straight skeleton's verification |
//! | [`VERTEX_SNAP`] | 10⁻¹² | × extent | a chord end at a boundary vertex |
//! | [`BOUND_MARGIN`] | 10⁻⁹ | rounding | bounds of distances in searches |
//! | [`BOX_SLACK`] | 10⁻¹² | rounding | the extents of an oriented box |
//! | [`ROOT_MARGIN`] | 10⁻¹⁵ | rounding | comparing distances by their squares |
//! | [`SLAB_SLACK`] | 4 ε | rounding | a ray's entry into a box by reciprocals |
//! | [`SHORT_OF_END`] | 10⁻⁶ | × a segment's length | a segment stopped short of ∂P |
//!
//! The values are those the outputs were made with; changing one changes
//! outputs (`tests/all/golden.rs`).

/// Two points closer than `SAME_POINT × extent` are one, and a point that
/// close to ∂P is on it (SPEC §3: points within 10⁻⁹ × extent of P count as
/// in P). The straight skeleton's every "same place / same time" decision
/// (times are offset distances, so lengths too); Voronoi's "on ∂P" and its
/// merging of coincident vertices; leg extension's "a leaf on ∂P"; the
/// arrangement's "a chord end on ∂P"; the collapse step's touches and snaps
/// to a boundary vertex.
pub const SAME_POINT: f64 = 1e-9;

/// A line end (a skeleton leaf, an end of a structure's line) within
/// `ON_BOUNDARY_END × extent` of ∂P is on it: above the coarsest coordinate
/// resolution of any method (MA's grid, ≤ 1.5 × 10⁻⁸ × extent), so every
/// method's leaves that reach ∂P count as reaching it.
pub const ON_BOUNDARY_END: f64 = 1e-7;

/// A vertex of a second input (a unit of `input.neighbours`, a line end of
/// `input.connect`) within `ROUND_OFF × extent` of ∂P is on it whatever
/// side of it round-off put it: the default snap, 1 cm on a 100 km river,
/// far above what a reprojection between two CRSs moves a vertex by
/// (nanometres for a round trip through EPSG:4326; a millimetre for
/// degrees stored to 8 decimals) and below anything drawn.
pub const ROUND_OFF: f64 = 1e-7;

/// A bar's hit closer than `BAR_ORIGIN × extent` to the bar's origin is the
/// origin itself (SPEC §6.2): the boundary vertex a bar starts from.
pub const BAR_ORIGIN: f64 = 1e-6;

/// The straight skeleton's verification of a pass: a trace end farther
/// than `TRACE_CROSSING × extent` outside P, or two traces crossing that
/// far from their ends and from each other's lines, rejects the pass;
/// closer is rounding.
pub const TRACE_CROSSING: f64 = 1e-6;

/// A chord end within `VERTEX_SNAP × extent` of a boundary vertex is that
/// vertex (the polygon split by `super::arrangement` keeps source vertices
/// bit for bit).
pub const VERTEX_SNAP: f64 = 1e-12;

/// Relative margin of a bound computed in floating point: lower bounds of
/// the boundary index (a box, an oriented box, a box's part in a
/// half-plane) and the stretch a line end's width search may skip are
/// shrunk by it, and known upper bounds (a seed distance, a radius bound)
/// widened by it, so that rounding never makes a bound cut an answer off.
pub const BOUND_MARGIN: f64 = 1e-9;

/// Relative widening of an oriented box's extents at construction: rounding
/// in the projections of its points and of a query's is far below
/// `BOX_SLACK` times the magnitudes involved.
pub const BOX_SLACK: f64 = 1e-12;

/// Squares of distances that differ by more than `ROOT_MARGIN` (relative)
/// order their roots the same way (each root is rounded by a relative 2⁻⁵³
/// at most): closer squares are compared by their roots
/// (`super::segment::nearer_2`).
pub const ROOT_MARGIN: f64 = 1e-15;

/// Relative widening of a ray's parameter interval in a box computed with
/// the reciprocals of its direction: a product by a rounded reciprocal is
/// within two units in the last place of the quotient, so the widened
/// interval holds the quotient's.
pub const SLAB_SLACK: f64 = 4.0 * f64::EPSILON;

/// A segment from a point to a boundary point reaches that point when it
/// crosses nothing once stopped `SHORT_OF_END` of its length short of it: a
/// point computed on a boundary segment lies on it only up to rounding, and
/// would "cross" it.
pub const SHORT_OF_END: f64 = 1e-6;
