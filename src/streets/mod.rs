//! The `streets` step: the chosen skeleton as a noded network of pieces —
//! one row per piece between two nodes (junctions of degree ≥ 3, line
//! ends, or a polygon's cut ends), with the degrees of its two nodes kept —
//! and, with a layer of units beside the polygons (`units`: the blocks or
//! plots the street space runs between, any OGR layer of polygons), the
//! FIDs of the units on the piece's left and right. What a street network
//! made from street space needs (with `prune: { junctions: merge }`): the
//! pieces join at one node per junction, and each carries the blocks it
//! separates. It writes the layer `streets`:
//!
//! | column | meaning |
//! |---|---|
//! | source fields | the feature's |
//! | `piece` | index of the piece in the feature |
//! | `start_degree`, `end_degree` | the degree of the piece's first and last node (1: a line end) |
//! | `length` | the piece's length |
//! | `left_fid`, `right_fid` | the unit on the piece's left and right (looking from its start to its end): the unit just beyond the polygon's boundary, across from the piece's middle and its quarter points (the one most of them find); NULL without `units`, or where no unit is there (the data's edge) |
//!
//! and, after the last feature, the layer `street_nodes`: one point per
//! node of the whole network — every feature's pieces together, so that a
//! street space split into parcels is one network — with `degree` (how
//! many pieces end there; a node where two parcels' pieces meet has 2) and
//! `features` (of how many features).
//!
//! ```yaml
//! steps:
//!   - skeleton: {}
//!   - prune: { junctions: merge }
//!   - extend: {}
//!   - score: {}
//!   - select: {}
//!   - streets: { units: { source: plots.gpkg, layer: blocks } }
//! ```

use crate::geometry::vector::norm;
use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;
use crate::layer::{Cell, ColumnType, GeometryKind, LayerSource, StepLayer, StepRow};
use crate::process::step::{
    FeatureStep, FinishInput, Needs, SideLayer, StepEntry, StepInput, StepRows,
};
use geo::{Coord, LineString};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Options of the `streets` step.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StreetsParams {
    /// The units the polygons run between (blocks, plots: any OGR layer of polygons, reprojected to the polygons' CRS): each piece gets the FIDs of the units on its left and right (`left_fid`, `right_fid`). Without it those columns are NULL.
    #[serde(default)]
    pub units: Option<LayerSource>,
}

/// The `streets` and `street_nodes` layers.
pub const STREETS: &[StepLayer] = &[
    StepLayer {
        name: "streets",
        geometry: GeometryKind::LineString,
        fields: Some(crate::layer::Fields::Input),
        columns: &[
            ("piece", ColumnType::Int32),
            ("start_degree", ColumnType::Int32),
            ("end_degree", ColumnType::Int32),
            ("length", ColumnType::Real),
            ("left_fid", ColumnType::Int64),
            ("right_fid", ColumnType::Int64),
        ],
    },
    StepLayer {
        name: "street_nodes",
        geometry: GeometryKind::Point,
        fields: None,
        columns: &[
            ("degree", ColumnType::Int32),
            ("features", ColumnType::Int32),
        ],
    },
];

/// The step (its options are only the side input, which the run reads).
#[derive(Debug)]
struct Streets;

impl FeatureStep for Streets {
    fn rows(&self, input: &StepInput<'_>) -> StepRows {
        let (_, chosen) = input.outcome.chosen();
        let g = SkeletonGraph::from_lines(&chosen.geometry);
        let degrees = g.degrees();
        let mut rows = Vec::new();
        for (k, br) in g.branches().iter().enumerate() {
            if k % 256 == 0 && input.budget.expired() {
                break;
            }
            let line = LineString::from(br.coords.clone());
            let part = part_of(input.parts, &br.coords);
            let (left, right) = match (input.side, part) {
                (Some(units), Some(p)) => sides(&br.coords, p, units),
                _ => (None, None),
            };
            use crate::layer::fid;
            let cells = vec![
                ("piece", crate::layer::int(k)),
                ("start_degree", crate::layer::int(degrees[br.start.index()])),
                ("end_degree", crate::layer::int(degrees[br.end.index()])),
                ("length", Cell::Real(br.length())),
                ("left_fid", fid(left)),
                ("right_fid", fid(right)),
            ];
            let geometry = Some(geo::Geometry::LineString(line));
            rows.push(("streets", StepRow { geometry, cells }));
        }
        Ok(rows)
    }

    fn finish(&self, input: &FinishInput<'_>) -> StepRows {
        use crate::geometry::CoordKey;
        // Every node of the whole network in the order first met: its
        // position, degree and the features it is in.
        let mut index: rustc_hash::FxHashMap<CoordKey, usize> = Default::default();
        let mut nodes: Vec<(Coord<f64>, i64, Vec<Option<u64>>)> = Vec::new();
        for (fid, _, row) in input
            .rows
            .iter()
            .filter(|(_, layer, _)| *layer == "streets")
        {
            let Some(geo::Geometry::LineString(l)) = &row.geometry else {
                continue;
            };
            for end in [l.0.first(), l.0.last()].into_iter().flatten() {
                let k = *index.entry(CoordKey::from(*end)).or_insert_with(|| {
                    nodes.push((*end, 0, Vec::new()));
                    nodes.len() - 1
                });
                nodes[k].1 += 1;
                if !nodes[k].2.contains(fid) {
                    nodes[k].2.push(*fid);
                }
            }
        }
        let rows = nodes
            .into_iter()
            .map(|(c, degree, features)| {
                let cells = vec![
                    ("degree", Cell::Int(degree)),
                    ("features", crate::layer::int(features.len())),
                ];
                let geometry = Some(geo::Geometry::Point(c.into()));
                ("street_nodes", StepRow { geometry, cells })
            })
            .collect();
        Ok(rows)
    }
}

/// The polygon part a piece lies in: the one holding its middle vertex (or
/// the nearest), among the parts whose boxes hold it first.
fn part_of<'a>(parts: &'a [PreparedPolygon], coords: &[Coord<f64>]) -> Option<&'a PreparedPolygon> {
    let mid = middle(coords)?.0;
    let in_box = |p: &PreparedPolygon| {
        let (lo, hi) = (p.boundary().bbox_min(), p.boundary().bbox_max());
        lo.x <= mid.x && mid.x <= hi.x && lo.y <= mid.y && mid.y <= hi.y
    };
    parts
        .iter()
        .find(|p| in_box(p) && p.boundary().contains(mid))
        .or_else(|| {
            parts.iter().min_by(|a, b| {
                a.boundary()
                    .distance(mid)
                    .total_cmp(&b.boundary().distance(mid))
            })
        })
}

/// The point at fraction `f` of a polyline's length and the direction of
/// its segment there.
fn at_fraction(coords: &[Coord<f64>], f: f64) -> Option<(Coord<f64>, Coord<f64>)> {
    let total: f64 = coords.windows(2).map(|w| norm(w[1] - w[0])).sum();
    let mut left = f * total;
    for w in coords.windows(2) {
        let l = norm(w[1] - w[0]);
        if l > 0.0 && (l >= left || w[1] == coords[coords.len() - 1]) {
            let t = (left / l).clamp(0.0, 1.0);
            return Some((w[0] + (w[1] - w[0]) * t, (w[1] - w[0]) / l));
        }
        left -= l;
    }
    None
}

fn middle(coords: &[Coord<f64>]) -> Option<(Coord<f64>, Coord<f64>)> {
    at_fraction(coords, 0.5)
}

/// The units on the left and the right of a piece: across from its middle
/// and its quarter points, the unit just beyond the polygon's boundary in
/// the direction square to the piece; the one most of the three find
/// (the middle's among equals).
fn sides(
    coords: &[Coord<f64>],
    p: &PreparedPolygon,
    units: &SideLayer,
) -> (Option<u64>, Option<u64>) {
    let mut found: [Vec<Option<u64>>; 2] = [Vec::new(), Vec::new()];
    for f in [0.5, 0.25, 0.75] {
        let Some((m, d)) = at_fraction(coords, f) else {
            continue;
        };
        for (k, normal) in [Coord { x: -d.y, y: d.x }, Coord { x: d.y, y: -d.x }]
            .into_iter()
            .enumerate()
        {
            found[k].push(unit_across(m, normal, p, units));
        }
    }
    let vote = |v: &[Option<u64>]| -> Option<u64> {
        let mut best: Option<(usize, Option<u64>)> = None;
        for x in v {
            let n = v.iter().filter(|y| *y == x).count();
            if best.is_none_or(|(m, _)| n > m) {
                best = Some((n, *x));
            }
        }
        best.and_then(|(_, x)| x)
    };
    (vote(&found[0]), vote(&found[1]))
}

/// The unit holding the point just beyond the boundary where the ray from
/// `m` in direction `dir` leaves polygon `p` (a hundredth of the distance,
/// at least a millionth of the polygon's extent, past it).
fn unit_across(
    m: Coord<f64>,
    dir: Coord<f64>,
    p: &PreparedPolygon,
    units: &SideLayer,
) -> Option<u64> {
    use geo::Intersects;
    let hit = p.boundary().first_hit(m, dir, 0.0, f64::INFINITY)?;
    let step = (0.01 * hit.t).max(1e-6 * p.extent());
    let q = hit.point + dir * step;
    let rect = geo::Rect::new(q, q);
    let point = geo::Point(q);
    units
        .near(rect)
        .into_iter()
        .map(|i| &units.features()[i])
        .find(|(_, g)| g.intersects(&point))
        .and_then(|(fid, _)| *fid)
}

/// The `streets` step's entry in the step registry.
pub const ENTRY: StepEntry = StepEntry {
    name: "streets",
    after: "select",
    description: "the chosen skeleton as a noded network: one row per piece between nodes, with both nodes' degrees and, with `units`, the units on its left and right (layer `streets`)",
    schema: || schemars::schema_for!(StreetsParams),
    needs: Needs {
        medial_axis: false,
        lonlat: false,
        side: Some("units"),
        finish: true,
        ..Needs::NOTHING
    },
    layers: STREETS,
    build: |v| {
        let _: StreetsParams = crate::process::step::step_options(v)?;
        Ok(Arc::new(Streets))
    },
};
