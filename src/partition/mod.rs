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
//! remainder polygon of its own (an `areas` row, `kind = unowned`).
//! Weights (a unit's "attractiveness", as SPLITAREA has it) are left out:
//! a weighted distance makes the boundaries curves that are neither the
//! medial axis nor exactly shared, and the step would no longer be exact.

mod assemble;
mod layer;
mod owners;
mod split;

pub use assemble::assemble;
pub use layer::{BoundaryRow, CoverageRow, GivenRow, BOUNDARIES, COVERAGE, GIVEN};
pub use owners::{Coverage, Unit};
pub use split::Owner;

use crate::geometry::{tolerance::SAME_POINT, PreparedPolygon};
use crate::methods::medial_axis::{cells::cell_edges, ArcTolerance};
use geo::{Area, LineString, MultiLineString, Polygon};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What happens to area nearest to bank no unit owns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Unowned {
    /// A remainder polygon of its own (`areas`, `kind = unowned`).
    #[default]
    Keep,
}

/// Options of the `partition` step.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PartitionParams {
    /// What happens to area nearest to bank no unit owns (the sea, the coverage's edge, holes that are no unit): `keep` (default) makes it a remainder polygon in `areas` (`kind = unowned`).
    #[serde(default)]
    pub unowned: Unowned,
}

impl PartitionParams {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
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

/// One collapsed polygon part, partitioned.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartPartition {
    /// The pieces given to units.
    pub given: Vec<Given>,
    /// The new boundaries, one per pair of owners.
    pub boundaries: Vec<NewBoundary>,
    /// What no unit takes (`unowned: keep`).
    pub remainders: Vec<Polygon<f64>>,
}

/// Partitions polygon part `p` between the units of `cov` (see the module
/// documentation), or says why it cannot be.
pub fn partition(
    p: &PreparedPolygon,
    cov: &Coverage,
    _params: &PartitionParams,
) -> Result<PartPartition, String> {
    let tol = SAME_POINT * p.extent();
    let owned = owners::owned(p, cov, tol)?;
    let prepared = PreparedPolygon::new(&owned.polygon).map_err(|e| e.to_string())?;
    let edges = cell_edges(&prepared, ArcTolerance::default()).map_err(|e| e.to_string())?;
    let pieces = split::pieces(&owned, edges);
    let faces = split::faces(&owned, &pieces)?;
    let mut out = PartPartition::default();
    let fid = |o: Owner| o.and_then(|u| cov.units()[u as usize].fid);
    for f in faces {
        match f.owner {
            Some(unit) => out.given.push(Given {
                unit,
                fid: fid(Some(unit)),
                polygon: f.face.polygon,
            }),
            None => out.remainders.push(f.face.polygon),
        }
    }
    out.boundaries = boundaries(pieces);
    for b in &mut out.boundaries {
        b.fids = [fid(b.left), fid(b.right)];
    }
    Ok(out)
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
    let key = |c: &geo::Coord<f64>| (c.x.to_bits(), c.y.to_bits());
    let mut degree: FxHashMap<(u64, u64), usize> = FxHashMap::default();
    let mut starting: FxHashMap<(u64, u64), usize> = FxHashMap::default();
    let mut ending: FxHashMap<(u64, u64), usize> = FxHashMap::default();
    for (i, l) in lines.iter().enumerate() {
        *degree.entry(key(&l[0])).or_default() += 1;
        *degree.entry(key(&l[l.len() - 1])).or_default() += 1;
        starting.insert(key(&l[0]), i);
        ending.insert(key(&l[l.len() - 1]), i);
    }
    let joins = |k: &(u64, u64)| degree[k] == 2;
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
        let r = partition(&p, &cov, &PartitionParams::default()).unwrap();
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
        let r = partition(&p, &cov, &PartitionParams::default()).unwrap();
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
    fn a_polygon_over_a_unit_is_refused() {
        let (p, _) = canal();
        let cov = Coverage::new(vec![unit(
            9,
            polygon![(x: 50., y: 2.), (x: 60., y: 2.), (x: 60., y: 20.), (x: 50., y: 20.)],
        )]);
        let e = partition(&p, &cov, &PartitionParams::default()).unwrap_err();
        assert!(e.contains("overlaps the interior of unit 9"), "{e}");
    }
}
