//! The step as the registry runs it: its entry (options, needs, layers),
//! its work on each feature — every polygon part partitioned, the rows of
//! `boundaries`, `given` and `areas`, and the pieces each unit grows by,
//! kept — and its finish: the coverage grown, logged, and the area the
//! units held before reported for the run record.

use super::layer::{AREAS, BOUNDARIES, COVERAGE, GIVEN, LAYERS};
use super::{assemble, partition, CoverageRow, Growth, PartPartition, PartitionParams};
use crate::layer::{Cell, StepRow};
use crate::methods::MethodId;
use crate::output::ExtraRow;
use crate::process::step::{
    step_options, FeatureStep, FinishInput, Finished, Kept, Needs, OptionError, StepContext,
    StepEntry, StepFailure, StepInput, StepOutput, StepRows,
};
use geo::{Area, Euclidean, Length};
use std::sync::Arc;

/// The `partition` step's entry.
pub const ENTRY: StepEntry = StepEntry {
    name: "partition",
    after: "collapse",
    description: "the polygon's area given to the units of `input.neighbours` around it: every point to the unit whose bank is nearest, the new boundaries (layer `boundaries`) running down the middle; the units grown by what they received (layer `coverage`), the areas given (layer `given`)",
    schema: || schemars::schema_for!(PartitionParams),
    needs: Needs {
        neighbours: true,
        cells: true,
        merge: true,
        graphs: true,
        finish: true,
        ..Needs::NOTHING
    },
    layers: LAYERS,
    build: |v| {
        let p: PartitionParams = step_options(v)?;
        p.validate()?;
        Ok(Arc::new(Partition(p)))
    },
};

/// The step with its options.
#[derive(Debug)]
struct Partition(PartitionParams);

/// What the step keeps of a feature: the pieces each unit (by FID) grows
/// by.
type Pieces = Vec<(Option<u64>, Growth)>;

impl FeatureStep for Partition {
    fn rows(&self, input: &StepInput<'_>) -> StepRows {
        self.output(input).map(|(rows, _)| rows)
    }

    fn output(&self, input: &StepInput<'_>) -> StepOutput {
        let cov = input.neighbours.ok_or(
            "the pipeline gives no coverage: add `input.neighbours: { source: …, layer: … }`",
        )?;
        let ma = input
            .outcome
            .candidates
            .iter()
            .find(|c| c.method == MethodId::MA)
            .and_then(|c| c.result.as_ref().ok());
        let mut cells = input
            .cells
            .map(|c| std::mem::take(&mut *c.borrow_mut()))
            .unwrap_or_default()
            .into_iter()
            .map(|a| Arc::try_unwrap(a).unwrap_or_else(|a| (*a).clone()).edges);
        let expired = || input.budget.expired();
        let n = input.parts.len();
        let mut parts = Vec::with_capacity(n);
        for (i, p) in input.parts.iter().enumerate() {
            let g = ma.and_then(|m| m.graphs.get(i));
            let part = partition(p, cov, &self.0, g, cells.next(), &expired).map_err(|e| {
                StepFailure(match n > 1 {
                    true => format!("part {i}: {e}"),
                    false => e.to_string(),
                })
            })?;
            parts.push(part);
        }
        let (rows, pieces) = rows_of(parts);
        Ok((rows, Some(Kept(Arc::new(pieces)))))
    }

    fn finish_rows(&self, input: &FinishInput<'_>) -> Result<Finished, StepFailure> {
        let Some(cov) = input.neighbours else {
            return Ok(Finished::default());
        };
        // Taken, not copied: the run holds the only reference to each.
        let pieces: Pieces = input
            .kept
            .take()
            .into_iter()
            .filter_map(|(_, k)| k.0.downcast::<Pieces>().ok())
            .flat_map(|p| Arc::try_unwrap(p).unwrap_or_else(|p| (*p).clone()))
            .collect();
        let coverage = assemble(cov.units(), pieces).map_err(|e| StepFailure(e.to_string()))?;
        log_coverage(&coverage);
        let held = coverage
            .iter()
            .map(|u| u.held)
            .filter(|&a| a > 0.0)
            .sum::<f64>()
            + 0.0;
        let rows = coverage
            .into_iter()
            .map(|u| {
                let row = StepRow {
                    geometry: Some(geo::Geometry::MultiPolygon(u.geometry)),
                    cells: vec![
                        ("received", Cell::Real(u.received)),
                        ("held", Cell::Real(u.held)),
                    ],
                };
                let row = ExtraRow {
                    attributes: u.attributes,
                    src_fid: u.src_fid,
                    ..ExtraRow::summary(row)
                };
                (COVERAGE.name, row)
            })
            .collect();
        Ok(Finished {
            rows,
            figures: vec![(crate::output::name::run::AREA_HELD, held)],
        })
    }

    fn needs(&self, declared: Needs) -> Needs {
        Needs {
            graphs: self.0.width.is_some(),
            ..declared
        }
    }

    fn check(&self, context: &StepContext<'_>) -> Result<(), OptionError> {
        if context.steps.contains(&"collapse") {
            return Err((
                String::new(),
                "a pipeline has `partition` (the area given to the neighbours) or `collapse` (lines and kept areas), not both: remove one".into(),
            ));
        }
        if self.0.width.is_some() && !context.methods.contains(&MethodId::MA) {
            return Err((
                "width".into(),
                "`width` gives away only the narrow parts, measured by the medial axis's inscribed discs: add MA to `skeleton.methods` (any method may still be chosen for the skeleton layer)".into(),
            ));
        }
        Ok(())
    }
}

/// The rows of a partitioned feature — its new boundaries, the area given
/// to each unit, the wide parts kept (`areas`, `kind = wide`) and what no
/// unit takes (`kind = unowned`) — and the pieces the units grow by.
fn rows_of(parts: Vec<PartPartition>) -> (Vec<(&'static str, StepRow)>, Pieces) {
    use crate::layer::fid;
    let mut rows = Vec::new();
    let mut pieces = Vec::new();
    // (area given, area held) by unit.
    let mut given: std::collections::BTreeMap<Option<u64>, (f64, f64)> = Default::default();
    for p in parts {
        for b in p.boundaries {
            let length: f64 = b.lines.0.iter().map(|l| Euclidean.length(l)).sum();
            rows.push((
                BOUNDARIES.name,
                StepRow {
                    geometry: Some(geo::Geometry::MultiLineString(b.lines)),
                    cells: vec![
                        ("left_fid", fid(b.fids[0])),
                        ("right_fid", fid(b.fids[1])),
                        ("length", Cell::Real(length)),
                    ],
                },
            ));
        }
        for g in p.given {
            given.entry(g.fid).or_default().0 += g.polygon.unsigned_area();
            pieces.push((g.fid, Growth::Given(g.polygon)));
        }
        for u in p.units {
            if !u.held.is_empty() {
                let held: f64 = u.held.iter().map(|h| h.unsigned_area()).sum();
                given.entry(u.fid).or_default().1 += held;
            }
            pieces.extend(u.held.into_iter().map(|h| (u.fid, Growth::Held(h))));
            if !u.edits.is_empty() {
                pieces.push((u.fid, Growth::Snapped(u.edits)));
            }
        }
        let kept = p.wide.into_iter().map(|(w, cuts)| (w, cuts, "wide"));
        let remainders = p.remainders.into_iter().map(|r| (r, 0, "unowned"));
        rows.extend(kept.chain(remainders).map(|(polygon, cuts, kind)| {
            (
                AREAS.name,
                StepRow {
                    geometry: Some(geo::Geometry::Polygon(polygon)),
                    cells: vec![
                        ("cuts", crate::layer::int(cuts)),
                        ("kind", Cell::Text(kind.into())),
                    ],
                },
            )
        }));
    }
    rows.extend(given.into_iter().map(|(unit, (area, held))| {
        (
            GIVEN.name,
            StepRow {
                geometry: None,
                cells: vec![
                    ("unit_fid", fid(unit)),
                    ("area", Cell::Real(area)),
                    ("held", Cell::Real(held)),
                ],
            },
        )
    }));
    (rows, pieces)
}

/// Logs what the partition gave: how many units grew and by how much, what
/// they held of the collapsed polygons before, and the units that lie wholly
/// in them.
fn log_coverage(coverage: &[CoverageRow]) {
    let grew: Vec<f64> = coverage
        .iter()
        .map(|c| c.received)
        .filter(|&a| a > 0.0)
        .collect();
    tracing::info!(
        units = coverage.len(),
        grown = grew.len(),
        area_given = grew.iter().sum::<f64>(),
        "partition: {} of {} units grew by {:.6e} (CRS units²), the others are written unchanged",
        grew.len(),
        coverage.len(),
        grew.iter().sum::<f64>()
    );
    let held: Vec<f64> = coverage
        .iter()
        .map(|c| c.held)
        .filter(|&a| a > 0.0)
        .collect();
    if !held.is_empty() {
        tracing::info!(
            units_held = held.len(),
            area_held = held.iter().sum::<f64>(),
            "partition: {} units held {:.6e} (CRS units²) of the collapsed polygons before: cut out of them and given by the rule (`held` in layers `given` and `coverage`)",
            held.len(),
            held.iter().sum::<f64>()
        );
    }
    let landless: Vec<String> = coverage
        .iter()
        .filter(|c| c.held > 0.0 && c.geometry.0.is_empty())
        .map(|c| crate::feature::fid_text(c.src_fid))
        .collect();
    if !landless.is_empty() {
        tracing::info!(
            units = %landless.join(","),
            "partition: {} units lie wholly in the collapsed polygons (FIDs {}): they get nothing and are written with an empty geometry",
            landless.len(),
            landless.join(", ")
        );
    }
}
