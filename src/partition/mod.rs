//! The `partition` step: a collapsed polygon's area given to the units
//! around it, the new boundary between two of them running down the
//! middle — administrative boundaries along rivers, land-cover
//! generalisation.
//!
//! Every boundary segment of the collapsed polygon P is *owned* by the unit
//! of `input.neighbours` whose boundary it lies on (within `1e-9 × extent`;
//! a unit vertex on one of P's edges — a T-junction — splits that edge
//! there); bank no unit touches is *unowned* (the sea, the coverage's edge,
//! a hole that is no unit). The Voronoi diagram of P's boundary segments
//! gives every point of P to the segment nearest to it; every point goes to
//! the owner of its nearest segment. So the new boundary between two units
//! is the medial axis between their banks (centred by construction: z = 0
//! up to the arc tolerance), it starts where the two meet on the bank —
//! along the angle's bisector at a convex meeting point, the normal at a
//! straight one — and where they meet at a reflex vertex, the part of P
//! nearest to that vertex is split between them along the bisector of
//! their two edges' normals.
//!
//! With `unowned: keep` (the default) the area nearest to unowned bank is a
//! remainder polygon of its own (an `areas` row, `kind = unowned`); with
//! `nearest` each such piece goes to the owned piece it borders along the
//! longest stretch. With `width` only the narrow parts are given away:
//! what is narrow is decided on the medial axis's discs as `collapse`
//! decides it (`narrow`), its cuts are noded with the new boundaries, and
//! the faces in the wide parts stay polygons (`kind = wide`). The new
//! boundaries written are the edges between faces that go to different
//! owners.
//! Weights (a unit's "attractiveness", as SPLITAREA has it) are left out:
//! a weighted distance makes the boundaries curves that are neither the
//! medial axis nor exactly shared, and the step would no longer be exact.

mod assemble;
mod cut;
mod layer;
mod narrow;
mod owners;
mod split;
mod step;

pub use crate::neighbours::{Coverage, Unit};
pub use assemble::{assemble, Growth};
pub use layer::{CoverageRow, AREAS, BOUNDARIES, COVERAGE, GIVEN, LAYERS};
pub use split::Owner;
pub use step::ENTRY;

use crate::geometry::coverage::{coverage_union, RingEdges};
use crate::geometry::vector::norm;
use crate::geometry::CoordKey;
use crate::geometry::{tolerance::SAME_POINT, PreparedPolygon};
use crate::graph::SkeletonGraph;
use crate::methods::medial_axis::cells::{cell_edges, CellEdge};
use crate::methods::medial_axis::ArcTolerance;
use crate::narrow::CollapseParams;
use geo::{Area, Coord, LineString, MultiLineString, Polygon};
use rustc_hash::FxHashMap;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What happens to area nearest to bank no unit owns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Unowned {
    /// A remainder polygon of its own (`areas`, `kind = unowned`).
    #[default]
    Keep,
    /// The owned part it borders along the longest stretch takes it.
    Nearest,
}

/// What happens where a unit overlaps a collapsed polygon.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Overlap {
    /// The polygon is cut out of the unit first, and what the unit held of
    /// it is given by the rule like the rest of the polygon (units that
    /// contain their share of a river, as administrative data have them).
    #[default]
    Cut,
    /// The polygon is rejected, with the place and the unit.
    Reject,
}

/// Options of the `partition` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PartitionParams {
    /// Units that overlap a collapsed polygon (real administrative units contain their share of the river or lake): `cut` (default) cuts the polygon out of them first and gives its area by the rule, so the new boundary runs down the middle of the water whatever the legal line inside it; `reject` rejects such a polygon, naming the unit and the place.
    #[serde(default)]
    pub overlap: Overlap,
    /// What happens to area nearest to bank no unit owns (the sea, the coverage's edge, holes that are no unit): `keep` (default) makes it a remainder polygon in `areas` (`kind = unowned`); `nearest` gives it to the owned part it borders along the longest stretch.
    #[serde(default)]
    pub unowned: Unowned,
    /// Give away only the narrow parts (CRS units, as `collapse`'s `width`): where the medial axis's local width 2r is above it the polygon stays a polygon of its own (`areas`, `kind = wide`), cut across where it meets the given parts. Needs MA among `skeleton.methods`. Default: the whole polygon is given away.
    #[serde(default)]
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width: Option<f64>,
    /// With `width`: the band around it as a fraction of it (default 0.2), as in `collapse`.
    #[serde(default = "default_tolerance")]
    #[schemars(range(min = 0), extend("exclusiveMaximum" = 1))]
    pub tolerance: f64,
    /// With `width`: the shortest narrow or wide stretch of the medial axis (CRS units; default `width`), as in `collapse`.
    #[serde(default)]
    #[schemars(range(min = 0))]
    pub min_length: Option<f64>,
}

fn default_tolerance() -> f64 {
    0.2
}

impl Default for PartitionParams {
    fn default() -> Self {
        Self {
            overlap: Overlap::Cut,
            unowned: Unowned::Keep,
            width: None,
            tolerance: default_tolerance(),
            min_length: None,
        }
    }
}

impl PartitionParams {
    /// The `collapse` options that decide what is narrow, with `width`.
    pub fn narrow(&self) -> Option<CollapseParams> {
        self.width.map(|width| CollapseParams {
            width,
            tolerance: self.tolerance,
            min_length: self.min_length,
            mode: crate::narrow::CollapseMode::Partial,
            min_area: 0.0,
        })
    }

    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if self.width.is_none()
            && (self.min_length.is_some() || self.tolerance != default_tolerance())
        {
            return Err((
                "width".into(),
                "`tolerance` and `min_length` say which parts are narrow: give `width` too, or remove them".into(),
            ));
        }
        if let Some(c) = self.narrow() {
            c.validate()?;
        }
        Ok(())
    }
}

/// A piece of a collapsed polygon given to a unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Given {
    /// The unit (an index into the coverage).
    pub unit: u32,
    /// The unit's FID.
    pub fid: Option<u64>,
    /// The piece.
    pub polygon: Polygon<f64>,
}

/// The new boundary between two owners inside one collapsed polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct NewBoundary {
    /// The owner on the lines' left, walking them.
    pub left: Owner,
    /// The owner on their right.
    pub right: Owner,
    /// The FIDs of the units on the left and right (`None`: unowned).
    pub fids: [Option<u64>; 2],
    /// The lines.
    pub lines: MultiLineString<f64>,
}

/// A unit changed by a collapsed polygon beside what it was given: snapped
/// onto its bank, or cut where it held some of it.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitChange {
    /// The unit (an index into the coverage).
    pub unit: u32,
    /// The unit's FID.
    pub fid: Option<u64>,
    /// How it was snapped onto the bank.
    pub edits: crate::geometry::overlay::Edits,
    /// What it held of the polygon (cut out of it).
    pub held: Vec<Polygon<f64>>,
}

/// One collapsed polygon part, partitioned.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartPartition {
    /// The units snapped or cut (`overlap: cut`) by this part.
    pub units: Vec<UnitChange>,
    /// The pieces given to units.
    pub given: Vec<Given>,
    /// The new boundaries, one per pair of owners.
    pub boundaries: Vec<NewBoundary>,
    /// What no unit takes (`unowned: keep`).
    pub remainders: Vec<Polygon<f64>>,
    /// With `width`: the wide parts, kept as polygons, each with the number
    /// of cuts on its boundary.
    pub wide: Vec<(Polygon<f64>, usize)>,
}

/// Where a face of the partitioned polygon goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Side {
    /// To a unit, or to none (unowned).
    To(Owner),
    /// It stays: a wide part.
    Wide,
}

/// Why a polygon part cannot be partitioned (the text is the feature's
/// rejection reason).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PartitionError {
    /// The polygon overlaps a unit and `overlap: reject` asks to refuse it.
    #[error("the polygon overlaps unit {fid} of `input.neighbours` ({area} CRS units² of it lie inside the unit) near ({x:.3}, {y:.3}); with `partition: {{overlap: cut}}` (the default) the unit's share is cut out of it and given by the rule, or remove the overlap from the coverage")]
    Overlap {
        /// The unit's FID, or `(no fid)`.
        fid: String,
        /// The area inside the unit, to four significant digits.
        area: String,
        /// Where (x).
        x: f64,
        /// Where (y).
        y: f64,
    },
    /// A unit near the polygon cannot be cut exactly by it.
    #[error(transparent)]
    Unit(#[from] UnitError),
    /// With `width`, the part's medial axis is needed and missing.
    #[error("a partition with `width` needs the part's medial axis")]
    NoMedialAxis,
    /// The polygon with the units' meeting points could not be prepared (a
    /// degenerate polygon).
    #[error(transparent)]
    Geometry(#[from] crate::geometry::GeometryError),
    /// The cells of the polygon's segment Voronoi diagram could not be made.
    #[error(transparent)]
    Cells(#[from] crate::methods::MethodError),
    /// The new boundaries do not split the polygon into faces (a bug).
    #[error("the new boundaries do not split the polygon ({0}); please report this feature")]
    Split(#[from] crate::geometry::arrangement::SplitError),
    /// `expired()` stopped the partition (the caller, which owns the
    /// clock, gives the reason).
    #[error("partition stopped: its time is up")]
    Stopped,
}

/// Why a unit of `input.neighbours` cannot be cut by a polygon, or written
/// once it has grown (`fid`: its FID, or
/// `(no fid)`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UnitError {
    /// Its pieces inside and outside the polygon do not add up to it.
    #[error("unit {fid} of `input.neighbours` could not be cut exactly by the polygon (its pieces add up to {parts}, not {whole}); check the unit's validity, or try another `input.neighbours.snap`")]
    NotCutExactly {
        /// The unit.
        fid: String,
        /// The area of its pieces.
        parts: f64,
        /// Its area.
        whole: f64,
    },
    /// Grown by what it was given, a part is not a valid polygon.
    #[error("unit {fid} of `input.neighbours` is not valid once the collapsed polygons' areas are cut out of it and given to it ({why}); check that the units form a coverage (no overlap between units) and that `input.neighbours.snap` is below the narrowest part of the units")]
    NotValidGrown {
        /// The unit.
        fid: String,
        /// What is wrong with the part.
        why: String,
    },
    /// Grown, its area is not its own less what it held plus what it was
    /// given.
    #[error("unit {fid} of `input.neighbours` would be written with an area of {got}, not {want} (its area less what it held of the collapsed polygons plus what it was given); please report this with the data")]
    AreaNotKept {
        /// The unit.
        fid: String,
        /// The area it would have.
        got: f64,
        /// The area it should have.
        want: f64,
    },
}

/// Fails with [`PartitionError::Stopped`] once `expired()`.
fn stop_if(expired: &dyn Fn() -> bool) -> Result<(), PartitionError> {
    match expired() {
        true => Err(PartitionError::Stopped),
        false => Ok(()),
    }
}

/// Partitions polygon part `p` between the units of `cov` (see the module
/// documentation), or says why it cannot be. With `width`, `ma` is the
/// part's medial axis (its discs say what is narrow); `cells`, when given,
/// the cells of the segment Voronoi diagram of `p`'s boundary inside it
/// (as [`cell_edges`] makes them; the medial axis's diagram), which it is
/// then split along without a diagram of its own. `expired()` is asked
/// between the stages (the units near the part, the narrow parts, the
/// cells, the faces); once it says the time is up the partition stops with
/// [`PartitionError::Stopped`].
pub fn partition(
    p: &PreparedPolygon,
    cov: &Coverage,
    params: &PartitionParams,
    ma: Option<&SkeletonGraph>,
    cells: Option<Vec<CellEdge>>,
    expired: &dyn Fn() -> bool,
) -> Result<PartPartition, PartitionError> {
    let tol = SAME_POINT * p.extent();
    let near = cut::Near::of(p, cov, cov.snap_for(p.extent()), tol)?;
    if params.overlap == Overlap::Reject {
        if let Some((k, area, at)) = near.first_overlap(tol) {
            let fid = crate::feature::fid_text(cov.units()[k as usize].fid);
            return Err(PartitionError::Overlap {
                fid,
                area: crate::numbers::sig(area, 4),
                x: at.x,
                y: at.y,
            });
        }
    }
    let local = near.coverage(cov);
    stop_if(expired)?;
    let snapped = match near.polygon == *p.polygon() {
        true => None,
        false => Some(PreparedPolygon::new(&near.polygon)?),
    };
    let mut out = partition_cut(
        snapped.as_ref().unwrap_or(p),
        p,
        &local,
        params,
        ma,
        cells,
        expired,
    )?;
    let global = |o: Owner| o.map(|i| near.units[i as usize].index);
    for g in &mut out.given {
        g.unit = near.units[g.unit as usize].index;
    }
    for b in &mut out.boundaries {
        (b.left, b.right) = (global(b.left), global(b.right));
    }
    out.units = near
        .units
        .into_iter()
        .filter(|u| !u.edits.is_empty() || !u.held.is_empty())
        .map(|u| UnitChange {
            unit: u.index,
            fid: cov.units()[u.index as usize].fid,
            edits: u.edits,
            held: u.held,
        })
        .collect();
    Ok(out)
}

/// [`partition`] of `p` (`original`, snapped) between the units of `cov`,
/// which meet it along its bank; `cells` those of `original`'s diagram,
/// when given.
fn partition_cut(
    p: &PreparedPolygon,
    original: &PreparedPolygon,
    cov: &Coverage,
    params: &PartitionParams,
    ma: Option<&SkeletonGraph>,
    cells: Option<Vec<CellEdge>>,
    expired: &dyn Fn() -> bool,
) -> Result<PartPartition, PartitionError> {
    let tol = SAME_POINT * p.extent();
    let mut owned = owners::owned(p, original.polygon(), cov, tol);
    let mut cuts: Vec<Vec<Coord<f64>>> = Vec::new();
    let mut wide_parts: Vec<Polygon<f64>> = Vec::new();
    if let Some(c) = params.narrow() {
        let ma = ma.ok_or(PartitionError::NoMedialAxis)?;
        let n = crate::narrow::collapse(ma, original, &c, &[]);
        if n.collapsed.is_empty() {
            // Wide everywhere: nothing is given away.
            return Ok(PartPartition {
                wide: vec![(owned.polygon, 0)],
                ..PartPartition::default()
            });
        }
        wide_parts = n.areas.into_iter().map(|a| a.polygon).collect();
        let ends: Vec<Coord<f64>> = n
            .cuts
            .iter()
            .flat_map(|l| [l.0[0], l.0[l.0.len() - 1]])
            .collect();
        let (with_ends, at) = owned.with_points(&ends, tol);
        owned = with_ends;
        for (k, l) in n.cuts.iter().enumerate() {
            let mut line = l.0.clone();
            let last = line.len() - 1;
            line[0] = at[2 * k].unwrap_or(line[0]);
            line[last] = at[2 * k + 1].unwrap_or(line[last]);
            cuts.push(line);
        }
    }
    stop_if(expired)?;
    // The diagram of the polygon as it came (the points the units were
    // snapped onto are split points of its edges, as their T-junctions).
    let edges = match (owned.base == *original.polygon(), cells) {
        (true, Some(cells)) => cells,
        (true, None) => cell_edges(original, ArcTolerance::default())?,
        (false, _) => cell_edges(&PreparedPolygon::new(&owned.base)?, ArcTolerance::default())?,
    };
    let prepared = PreparedPolygon::new(&owned.polygon)?;
    stop_if(expired)?;
    let (pieces, vertices) = split::pieces(&owned, edges);
    let mut lines: Vec<Vec<Coord<f64>>> = pieces.into_iter().map(|q| q.line).collect();
    narrow::node(&mut cuts, &mut lines, tol);
    let chords: Vec<LineString<f64>> = lines
        .into_iter()
        .chain(cuts.iter().cloned())
        .map(LineString)
        .collect();
    stop_if(expired)?;
    let faces = split::faces(&prepared, &owned, &vertices, &chords)?;
    stop_if(expired)?;
    let mut sides: Vec<Side> = faces
        .iter()
        .map(|f| match narrow::is_wide(&f.face.polygon, &wide_parts) {
            true => Side::Wide,
            false => Side::To(f.owner),
        })
        .collect();
    let adjacency = Adjacency::of(&faces);
    if params.unowned == Unowned::Nearest {
        adjacency.give_unowned(&mut sides);
    }
    Ok(assemble_part(cov, faces, &sides, &adjacency, &cuts))
}

/// The partition of a part from its faces and where each goes.
fn assemble_part(
    cov: &Coverage,
    faces: Vec<split::OwnedFace>,
    sides: &[Side],
    adjacency: &Adjacency,
    cuts: &[Vec<Coord<f64>>],
) -> PartPartition {
    let fid = |o: Owner| o.and_then(|u| cov.units()[u as usize].fid);
    let mut out = PartPartition {
        boundaries: boundaries(adjacency.pieces(sides)),
        ..PartPartition::default()
    };
    for b in &mut out.boundaries {
        b.fids = [fid(b.left), fid(b.right)];
    }
    let (mut unowned, mut wide) = (Vec::new(), Vec::new());
    for (f, side) in faces.into_iter().zip(sides) {
        match side {
            Side::To(Some(unit)) => out.given.push(Given {
                unit: *unit,
                fid: fid(Some(*unit)),
                polygon: f.face.polygon,
            }),
            Side::To(None) => unowned.push(f.face.polygon),
            Side::Wide => wide.push(f.face.polygon),
        }
    }
    out.remainders = coverage_union(&unowned);
    let cut_ends: rustc_hash::FxHashSet<CoordKey> = cuts
        .iter()
        .flat_map(|l| [l[0], l[l.len() - 1]])
        .map(CoordKey::from)
        .collect();
    out.wide = coverage_union(&wide)
        .into_iter()
        .map(|w| {
            let n = w
                .exterior()
                .0
                .iter()
                .chain(w.interiors().iter().flat_map(|r| &r.0))
                .filter(|c| cut_ends.contains(&CoordKey::from(**c)))
                .count();
            (w, n / 2)
        })
        .collect();
    out
}

/// Which faces meet along which chord edges: every directed edge of a
/// face's rings (the face on its left) whose reverse is another face's.
struct Adjacency {
    /// `(edge from, edge to, face on its left, face on its right)`.
    shared: Vec<(Coord<f64>, Coord<f64>, usize, usize)>,
}

impl Adjacency {
    fn of(faces: &[split::OwnedFace]) -> Self {
        let polygons: Vec<&Polygon<f64>> = faces.iter().map(|f| &f.face.polygon).collect();
        let shared = RingEdges::of(&polygons).shared();
        Self { shared }
    }

    /// `unowned: nearest`: every unowned face given to the owned face it
    /// borders along the longest stretch, until none borders one.
    fn give_unowned(&self, sides: &mut [Side]) {
        loop {
            let mut border: FxHashMap<(usize, Owner), f64> = FxHashMap::default();
            for &(a, b, i, j) in &self.shared {
                if let (Side::To(None), Side::To(Some(u))) = (sides[i], sides[j]) {
                    *border.entry((i, Some(u))).or_default() += norm(b - a);
                }
            }
            if border.is_empty() {
                return;
            }
            let mut best: FxHashMap<usize, (Owner, f64)> = FxHashMap::default();
            for ((i, o), l) in border {
                let e = best.entry(i).or_insert((o, l));
                if l > e.1 || (l == e.1 && o < e.0) {
                    *e = (o, l);
                }
            }
            for (i, (o, _)) in best {
                sides[i] = Side::To(o);
            }
        }
    }

    /// The new boundaries: the edges between faces that go to different
    /// owners (a wide part's edges are none), each once, the owner of the
    /// face on its left and of the one on its right.
    fn pieces(&self, sides: &[Side]) -> Vec<split::Piece> {
        let mut out: Vec<split::Piece> = Vec::new();
        for &(a, b, i, j) in &self.shared {
            let (Side::To(left), Side::To(right)) = (sides[i], sides[j]) else {
                continue;
            };
            if left == right || i > j {
                continue;
            }
            match out.last_mut() {
                Some(p) if p.left == left && p.right == right && p.line.last() == Some(&a) => {
                    p.line.push(b)
                }
                _ => out.push(split::Piece {
                    line: vec![a, b],
                    left,
                    right,
                }),
            }
        }
        out
    }
}

/// The pieces grouped by pair of owners (each oriented with the smaller
/// owner on its left) and joined end to end into lines.
fn boundaries(pieces: Vec<split::Piece>) -> Vec<NewBoundary> {
    let mut by_pair: std::collections::BTreeMap<(Owner, Owner), Vec<Vec<geo::Coord<f64>>>> =
        Default::default();
    for mut q in pieces {
        if q.left > q.right {
            q.line.reverse();
            std::mem::swap(&mut q.left, &mut q.right);
        }
        by_pair.entry((q.left, q.right)).or_default().push(q.line);
    }
    by_pair
        .into_iter()
        .map(|((left, right), lines)| NewBoundary {
            left,
            right,
            fids: [None, None],
            lines: MultiLineString(join(lines).into_iter().map(LineString).collect()),
        })
        .collect()
}

/// Lines joined where one ends and another begins at a point no third line
/// touches (all lines run the same way: the pair's smaller owner on the
/// left).
fn join(lines: Vec<Vec<geo::Coord<f64>>>) -> Vec<Vec<geo::Coord<f64>>> {
    use rustc_hash::FxHashMap;
    let key = |c: &geo::Coord<f64>| CoordKey::from(c);
    let mut degree: FxHashMap<CoordKey, usize> = FxHashMap::default();
    let mut starting: FxHashMap<CoordKey, usize> = FxHashMap::default();
    let mut ending: FxHashMap<CoordKey, usize> = FxHashMap::default();
    for (i, l) in lines.iter().enumerate() {
        *degree.entry(key(&l[0])).or_default() += 1;
        *degree.entry(key(&l[l.len() - 1])).or_default() += 1;
        starting.insert(key(&l[0]), i);
        ending.insert(key(&l[l.len() - 1]), i);
    }
    let joins = |k: &CoordKey| degree[k] == 2;
    let mut used = vec![false; lines.len()];
    let mut out = Vec::new();
    for i in 0..lines.len() {
        if used[i] {
            continue;
        }
        // Back to the first line of the chain (a ring: any of its lines).
        let mut first = i;
        loop {
            let s = key(&lines[first][0]);
            match ending
                .get(&s)
                .copied()
                .filter(|&j| joins(&s) && !used[j] && j != i)
            {
                Some(j) if j != first => first = j,
                _ => break,
            }
            if first == i {
                break;
            }
        }
        let mut chain = lines[first].clone();
        used[first] = true;
        loop {
            let e = key(&chain[chain.len() - 1]);
            match starting.get(&e).copied().filter(|&j| joins(&e) && !used[j]) {
                Some(j) => {
                    used[j] = true;
                    chain.extend_from_slice(&lines[j][1..]);
                }
                None => break,
            }
        }
        out.push(chain);
    }
    out
}

/// The area of every piece given to each unit.
pub fn given_area(p: &PartPartition) -> Vec<(u32, f64)> {
    let mut by: std::collections::BTreeMap<u32, f64> = Default::default();
    for g in &p.given {
        *by.entry(g.unit).or_default() += g.polygon.unsigned_area();
    }
    by.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::{polygon, MultiPolygon};

    fn unit(fid: u64, p: Polygon<f64>) -> Unit {
        Unit {
            fid: Some(fid),
            geometry: MultiPolygon(vec![p]),
            attributes: Vec::new(),
        }
    }

    /// A 100 × 10 canal with a unit along each side.
    fn canal() -> (PreparedPolygon, Coverage) {
        let c = polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 10.), (x: 0., y: 10.)];
        let cov = Coverage::new(vec![
            unit(
                1,
                polygon![(x: 0., y: -20.), (x: 100., y: -20.), (x: 100., y: 0.), (x: 0., y: 0.)],
            ),
            unit(
                2,
                polygon![(x: 0., y: 10.), (x: 100., y: 10.), (x: 100., y: 30.), (x: 0., y: 30.)],
            ),
            unit(
                3,
                polygon![(x: -20., y: 0.), (x: 0., y: 0.), (x: 0., y: 10.), (x: -20., y: 10.)],
            ),
            unit(
                4,
                polygon![(x: 100., y: 0.), (x: 120., y: 0.), (x: 120., y: 10.), (x: 100., y: 10.)],
            ),
        ]);
        (PreparedPolygon::new(&c).unwrap(), cov)
    }

    #[test]
    fn a_canal_between_two_units_is_split_on_its_centre_line() {
        let (p, cov) = canal();
        let r = partition(&p, &cov, &PartitionParams::default(), None, None, &|| false).unwrap();
        let areas = given_area(&r);
        assert_eq!(areas.len(), 4, "{areas:?}");
        for (unit, area) in areas {
            let want = if unit < 2 { 475.0 } else { 25.0 };
            assert!((area - want).abs() < 1e-6, "unit {unit}: {area}");
        }
        assert!(r.remainders.is_empty());
        let ab = r
            .boundaries
            .iter()
            .find(|b| (b.left, b.right) == (Some(0), Some(1)))
            .expect("a boundary between the two sides");
        assert_eq!(ab.lines.0.len(), 1);
        for c in &ab.lines.0[0].0 {
            assert!((c.y - 5.0).abs() < 1e-9, "{c:?}");
        }
    }

    #[test]
    fn a_third_unit_on_one_bank_starts_its_boundaries_at_the_meeting_point() {
        // The bottom bank split at x = 40 between units 1 and 5 (a
        // straight-angle T-junction): the normal at x = 40 up to the centre
        // line separates them.
        let c = polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 10.), (x: 0., y: 10.)];
        let cov = Coverage::new(vec![
            unit(
                1,
                polygon![(x: 0., y: -20.), (x: 40., y: -20.), (x: 40., y: 0.), (x: 0., y: 0.)],
            ),
            unit(
                5,
                polygon![(x: 40., y: -20.), (x: 100., y: -20.), (x: 100., y: 0.), (x: 40., y: 0.)],
            ),
            unit(
                2,
                polygon![(x: 0., y: 10.), (x: 100., y: 10.), (x: 100., y: 30.), (x: 0., y: 30.)],
            ),
        ]);
        let p = PreparedPolygon::new(&c).unwrap();
        let r = partition(&p, &cov, &PartitionParams::default(), None, None, &|| false).unwrap();
        let normal = r
            .boundaries
            .iter()
            .find(|b| (b.left, b.right) == (Some(0), Some(1)))
            .expect("units 1 and 5 meet");
        let line = &normal.lines.0[0].0;
        assert!(line.iter().all(|c| (c.x - 40.0).abs() < 1e-9), "{line:?}");
        assert!(line.iter().any(|c| c.y == 0.0) && line.iter().any(|c| (c.y - 5.0).abs() < 1e-9));
        // The ends of the canal (x = 0, x = 100) belong to no unit.
        assert_eq!(r.remainders.len(), 2);
        let total: f64 = r
            .given
            .iter()
            .map(|g| g.polygon.unsigned_area())
            .sum::<f64>()
            + r.remainders.iter().map(|g| g.unsigned_area()).sum::<f64>();
        assert!((total - 1000.0).abs() < 1e-9, "{total}");
    }

    #[test]
    fn units_meeting_inside_a_slanted_bank_are_split_on_its_exact_normal_from_the_medial_axis_cells(
    ) {
        // A canal at 30° whose bottom bank two units share, meeting at a
        // point no grid holds (1/3 of the way along): their boundary is the
        // bank's normal there, and the medial axis's own cells give the same
        // partition as a diagram made for it.
        let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let at = |x: f64, y: f64| geo::Coord {
            x: 1000.0 + x * c - y * s,
            y: 2000.0 + x * s + y * c,
        };
        let ring = |pts: &[(f64, f64)]| {
            Polygon::new(
                geo::LineString(pts.iter().map(|&(x, y)| at(x, y)).collect()),
                vec![],
            )
        };
        let t = 100.0 / 3.0;
        let canal = ring(&[(0., 0.), (100., 0.), (100., 10.), (0., 10.), (0., 0.)]);
        let cov = Coverage::new(vec![
            unit(
                1,
                ring(&[(0., -20.), (t, -20.), (t, 0.), (0., 0.), (0., -20.)]),
            ),
            unit(
                5,
                ring(&[(t, -20.), (100., -20.), (100., 0.), (t, 0.), (t, -20.)]),
            ),
            unit(
                2,
                ring(&[(0., 10.), (100., 10.), (100., 30.), (0., 30.), (0., 10.)]),
            ),
        ]);
        let p = PreparedPolygon::new(&canal).unwrap();
        let params = PartitionParams::default();
        let own = partition(&p, &cov, &params, None, None, &|| false).unwrap();
        let ma = crate::methods::medial_axis::MedialAxis::default();
        let (_, cells) = crate::methods::SkeletonMethod::skeletonise_with_cells(
            &ma,
            &p,
            &crate::methods::MethodContext::default(),
        )
        .unwrap();
        let cells = cells.expect("the medial axis keeps its cells").edges;
        let shared = partition(&p, &cov, &params, None, Some(cells), &|| false).unwrap();
        assert_eq!(own, shared);
        let normal = own
            .boundaries
            .iter()
            .find(|b| (b.left, b.right) == (Some(0), Some(1)))
            .expect("units 1 and 5 meet");
        let line = &normal.lines.0[0].0;
        let (first, last) = (line[0], line[line.len() - 1]);
        let d = last - first;
        // Along the bank's normal (-sin, cos), from the bank to the centre.
        assert!((d.x * c + d.y * s).abs() < 1e-9, "{line:?}");
        // To the centre line, as the diagram's grid places it.
        assert!((d.x.hypot(d.y) - 5.0).abs() < 1e-6, "{line:?}");
    }

    #[test]
    fn a_polygon_over_a_unit_is_refused_with_overlap_reject() {
        let (p, _) = canal();
        let cov = Coverage::new(vec![unit(
            9,
            polygon![(x: 50., y: 2.), (x: 60., y: 2.), (x: 60., y: 20.), (x: 50., y: 20.)],
        )]);
        let reject = PartitionParams {
            overlap: Overlap::Reject,
            ..PartitionParams::default()
        };
        let e = partition(&p, &cov, &reject, None, None, &|| false).unwrap_err();
        assert!(matches!(e, PartitionError::Overlap { .. }), "{e:?}");
        let e = e.to_string();
        assert!(e.contains("overlaps unit 9"), "{e}");
        assert!(e.contains("80 CRS units²"), "{e}");
        // A partition whose time is up stops with its own variant.
        let r = PartitionParams::default();
        assert_eq!(
            partition(&p, &cov, &r, None, None, &|| true).unwrap_err(),
            PartitionError::Stopped
        );
    }

    /// The canal's units with the legal line inside the water, at y = 3.
    fn covering_units() -> Coverage {
        Coverage::new(vec![
            unit(
                1,
                polygon![(x: 0., y: -20.), (x: 100., y: -20.), (x: 100., y: 3.), (x: 0., y: 3.)],
            ),
            unit(
                2,
                polygon![(x: 0., y: 3.), (x: 100., y: 3.), (x: 100., y: 30.), (x: 0., y: 30.)],
            ),
            unit(
                3,
                polygon![(x: -20., y: -20.), (x: 0., y: -20.), (x: 0., y: 30.), (x: -20., y: 30.)],
            ),
            unit(
                4,
                polygon![(x: 100., y: -20.), (x: 120., y: -20.), (x: 120., y: 30.), (x: 100., y: 30.)],
            ),
        ])
    }

    #[test]
    fn units_that_cover_the_canal_are_cut_and_share_it_down_the_middle() {
        let (p, _) = canal();
        let cov = covering_units();
        let r = partition(&p, &cov, &PartitionParams::default(), None, None, &|| false).unwrap();
        let areas = given_area(&r);
        assert_eq!(areas.len(), 4, "{areas:?}");
        for (unit, area) in areas {
            let want = if unit < 2 { 475.0 } else { 25.0 };
            assert!((area - want).abs() < 1e-6, "unit {unit}: {area}");
        }
        let held: Vec<(u32, f64)> = r
            .units
            .iter()
            .filter(|u| !u.held.is_empty())
            .map(|u| (u.unit, crate::geometry::overlay::area(&u.held)))
            .collect();
        assert_eq!(held.len(), 2, "{held:?}");
        assert!((held[0].1 - 300.0).abs() < 1e-9 && (held[1].1 - 700.0).abs() < 1e-9);
        let ab = r
            .boundaries
            .iter()
            .find(|b| (b.left, b.right) == (Some(0), Some(1)))
            .expect("a boundary between the two sides");
        assert!(ab.lines.0[0].0.iter().all(|c| (c.y - 5.0).abs() < 1e-9));
        // The coverage: the units' land and their shares, area conserved.
        let mut grown = Vec::new();
        for g in &r.given {
            grown.push((g.fid, Growth::Given(g.polygon.clone())));
        }
        for u in &r.units {
            grown.extend(u.held.iter().map(|h| (u.fid, Growth::Held(h.clone()))));
        }
        let rows = assemble(cov.units(), grown).unwrap();
        let area: Vec<f64> = rows.iter().map(|c| c.geometry.unsigned_area()).collect();
        for (got, want) in area.iter().zip([2475.0, 2475.0, 1025.0, 1025.0]) {
            assert!((got - want).abs() < 1e-9, "{area:?}");
        }
        assert_eq!(rows[0].held, 300.0);
        assert!(rows.iter().all(|c| c.geometry.0.len() == 1));
    }

    #[test]
    fn a_lake_with_an_island_inside_a_unit_goes_back_to_it_whole() {
        // No unit boundary near the lake: it becomes a hole of the unit,
        // the island a part of it, and the lake is given back whole.
        let lake = Polygon::new(
            geo::LineString::from(vec![
                (10., 10.),
                (30., 10.),
                (30., 20.),
                (10., 20.),
                (10., 10.),
            ]),
            vec![geo::LineString::from(vec![
                (15., 12.),
                (15., 18.),
                (20., 18.),
                (20., 12.),
                (15., 12.),
            ])],
        );
        let p = PreparedPolygon::new(&lake).unwrap();
        let cov = Coverage::new(vec![unit(
            1,
            polygon![(x: 0., y: 0.), (x: 40., y: 0.), (x: 40., y: 30.), (x: 0., y: 30.)],
        )]);
        let r = partition(&p, &cov, &PartitionParams::default(), None, None, &|| false).unwrap();
        assert_eq!(given_area(&r), vec![(0, 170.0)]);
        assert_eq!(r.units.len(), 1);
        assert_eq!(crate::geometry::overlay::area(&r.units[0].held), 170.0);
        let mut grown: Vec<(Option<u64>, Growth)> = r
            .given
            .iter()
            .map(|g| (g.fid, Growth::Given(g.polygon.clone())))
            .collect();
        grown.extend(
            r.units[0]
                .held
                .iter()
                .map(|h| (Some(1), Growth::Held(h.clone()))),
        );
        let rows = assemble(cov.units(), grown).unwrap();
        assert_eq!(rows[0].geometry.unsigned_area(), 1200.0);
        assert_eq!(rows[0].geometry.0.len(), 1);
        assert!(rows[0].geometry.0[0].interiors().is_empty());
    }
}
