//! The per-feature work: prepare → skeleton → prune → extend → score →
//! select, on owned `geo` geometry with no I/O and no global state, so that
//! features can be processed in parallel with identical results for any
//! thread count.

use crate::geometry::PreparedPolygon;
use crate::graph::extend::{prune_and_extend, ExtendParams};
use crate::graph::prune::PruneParams;
use crate::methods::medial_axis::{medial_axis_transform, MatSegment};
use crate::methods::{MethodId, Registry, SkeletonParams};
use crate::score::select::{select, SelectParams};
use crate::score::{bars, metrics, Bar, ScoreParams, Scores};
use geo::{Area, Geometry, MultiLineString, Polygon};
use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Options of the `prepare` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PrepareParams {
    /// Repair invalid polygons (GDAL MakeValid) instead of rejecting them.
    pub make_valid: bool,
    /// Polygon parts smaller than this (CRS units²) are skipped; a feature all
    /// of whose parts are skipped is counted as filtered.
    pub min_area: f64,
}

impl PrepareParams {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if self.min_area.is_nan() || self.min_area < 0.0 {
            return Err((
                "min_area".into(),
                "min_area must be ≥ 0 (CRS units²)".into(),
            ));
        }
        Ok(())
    }
}

impl Default for PrepareParams {
    fn default() -> Self {
        Self {
            make_valid: true,
            min_area: 0.0,
        }
    }
}

/// Everything the per-feature work needs: the steps of the pipeline.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProcessParams {
    /// `prepare` step.
    pub prepare: PrepareParams,
    /// `skeleton` step.
    pub skeleton: SkeletonParams,
    /// `prune` step, when present.
    pub prune: Option<PruneParams>,
    /// `extend` step, when present.
    pub extend: Option<ExtendParams>,
    /// `score` step, when present.
    pub score: Option<ScoreParams>,
    /// `select` step, when present.
    pub select: Option<SelectParams>,
    /// Keep every bar (for the diagnostic `bars` layer).
    pub keep_bars: bool,
    /// Keep the local widths of the skeleton (for the `widths` layer).
    pub keep_widths: bool,
    /// The methods `skeleton.methods` may name.
    pub registry: Registry,
}

/// One method's result for one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The method.
    pub method: MethodId,
    /// The skeleton, or why the method failed on this feature.
    pub result: Result<CandidateSkeleton, String>,
}

/// A successful skeleton of one feature (all its polygon parts).
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateSkeleton {
    /// The final skeleton (after pruning and extension).
    pub geometry: MultiLineString<f64>,
    /// The paper's metrics, when the pipeline scores.
    pub scores: Option<Scores>,
    /// Connected components of the final skeleton (summed over parts).
    pub components: usize,
    /// Legs of the raw skeleton, before pruning.
    pub legs_raw: usize,
    /// Legs after pruning and extension.
    pub legs: usize,
    /// Bars, when requested (`part` indices are unique across polygon parts).
    pub bars: Vec<Bar>,
    /// The skeleton's segments with the disc radius at both ends (the medial
    /// axis transform for MA), when requested.
    pub widths: Vec<MatSegment>,
}

/// What the pipeline writes for one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureOutcome {
    /// Every method's candidate, in `methods` order.
    pub candidates: Vec<Candidate>,
    /// Index of the chosen candidate.
    pub chosen: usize,
    /// Polygon parts skeletonised.
    pub parts: usize,
}

impl FeatureOutcome {
    /// The chosen candidate's skeleton.
    pub fn chosen(&self) -> (&MethodId, &CandidateSkeleton) {
        let c = &self.candidates[self.chosen];
        (
            &c.method,
            c.result.as_ref().expect("the chosen candidate succeeded"),
        )
    }
}

/// Result of processing one feature.
#[derive(Debug, Clone, PartialEq)]
pub enum Processed {
    /// Skeletonised.
    Done(FeatureOutcome),
    /// Skipped by `min_area` (counted as filtered, not rejected).
    Filtered,
    /// Could not be processed; the reason goes to the `rejected` layer.
    Rejected(String),
}

/// The polygon parts of a geometry, or why it has none.
pub fn polygon_parts(geom: Option<&Geometry<f64>>) -> Result<Vec<Polygon<f64>>, String> {
    let Some(geom) = geom else {
        return Err("NULL geometry: the feature has no geometry to skeletonise".into());
    };
    let parts = match geom {
        Geometry::Polygon(p) => vec![p.clone()],
        Geometry::MultiPolygon(mp) => mp.0.clone(),
        Geometry::Rect(r) => vec![r.to_polygon()],
        Geometry::Triangle(t) => vec![t.to_polygon()],
        Geometry::GeometryCollection(gc) => {
            let mut v = Vec::new();
            for g in gc.iter() {
                match polygon_parts(Some(g)) {
                    Ok(p) => v.extend(p),
                    Err(_) => {
                        return Err(format!(
                            "geometry collection with a non-polygon member ({}); only polygons can be skeletonised",
                            kind(g)
                        ))
                    }
                }
            }
            v
        }
        other => {
            return Err(format!(
                "{} geometry: only polygons and multipolygons can be skeletonised",
                kind(other)
            ))
        }
    };
    let parts: Vec<Polygon<f64>> = parts
        .into_iter()
        .filter(|p| !p.exterior().0.is_empty())
        .collect();
    if parts.is_empty() {
        return Err("empty geometry: the polygon has no vertices".into());
    }
    Ok(parts)
}

fn kind(g: &Geometry<f64>) -> &'static str {
    match g {
        Geometry::Point(_) => "point",
        Geometry::MultiPoint(_) => "multipoint",
        Geometry::Line(_) | Geometry::LineString(_) => "line",
        Geometry::MultiLineString(_) => "multilinestring",
        Geometry::Polygon(_) => "polygon",
        Geometry::MultiPolygon(_) => "multipolygon",
        Geometry::GeometryCollection(_) => "geometry collection",
        Geometry::Rect(_) => "rectangle",
        Geometry::Triangle(_) => "triangle",
    }
}

/// Processes one feature's geometry through every step.
pub fn process(geom: Option<&Geometry<f64>>, params: &ProcessParams) -> Processed {
    let parts = match polygon_parts(geom) {
        Ok(p) => p,
        Err(e) => return Processed::Rejected(e),
    };
    let parts: Vec<Polygon<f64>> = parts
        .into_iter()
        .filter(|p| params.prepare.min_area <= 0.0 || p.unsigned_area() >= params.prepare.min_area)
        .collect();
    if parts.is_empty() {
        return Processed::Filtered;
    }
    let mut prepared = Vec::with_capacity(parts.len());
    for (i, p) in parts.iter().enumerate() {
        match PreparedPolygon::new(p) {
            Ok(pp) => prepared.push(pp),
            Err(e) if parts.len() > 1 => return Processed::Rejected(format!("part {i}: {e}")),
            Err(e) => return Processed::Rejected(e.to_string()),
        }
    }
    if let Some(reason) = invalidity(&prepared) {
        return Processed::Rejected(reason);
    }
    let multi = prepared.len() > 1;
    let per_part: Vec<Vec<Result<PartSkeleton, String>>> = prepared
        .iter()
        .enumerate()
        .map(|(i, p)| {
            part_skeletons(p, params)
                .into_iter()
                .map(|r| r.map_err(|e| if multi { format!("part {i}: {e}") } else { e }))
                .collect()
        })
        .collect();
    let candidates: Vec<Candidate> = params
        .skeleton
        .methods
        .par_iter()
        .enumerate()
        .map(|(k, &m)| Candidate {
            method: m,
            result: candidate(k, &prepared, &per_part, params),
        })
        .collect();
    let scores: Vec<Option<Scores>> = candidates
        .iter()
        .map(|c| match &c.result {
            Ok(s) if !s.geometry.0.is_empty() => Some(s.scores.unwrap_or_default()),
            _ => None,
        })
        .collect();
    let chosen = match (&params.select, params.score.is_some()) {
        (Some(sel), true) => select(&scores, sel),
        _ => None,
    }
    .or_else(|| scores.iter().position(Option::is_some));
    match chosen {
        Some(chosen) => Processed::Done(FeatureOutcome {
            candidates,
            chosen,
            parts: prepared.len(),
        }),
        None => Processed::Rejected(rejection(&candidates)),
    }
}

/// Why no candidate could be written.
fn rejection(candidates: &[Candidate]) -> String {
    let reasons: Vec<String> = candidates
        .iter()
        .map(|c| match &c.result {
            Err(e) => format!("{}: {e}", c.method),
            Ok(_) => format!("{}: empty skeleton", c.method),
        })
        .collect();
    reasons.join("; ")
}

/// One method's finished skeleton of one polygon part.
#[derive(Debug, Clone)]
struct PartSkeleton {
    graph: crate::graph::SkeletonGraph,
    legs_raw: usize,
}

/// Every method's finished skeleton of one polygon part, in `methods`
/// order: raw skeletons in parallel, then the reference pruned and extended,
/// then the others pruned to its structure (or each on its own).
fn part_skeletons(
    p: &PreparedPolygon,
    params: &ProcessParams,
) -> Vec<Result<PartSkeleton, String>> {
    use crate::graph::prune::{PruneMode, Structure as Sharing};
    use crate::graph::structure::{conform, Structure};
    let methods = &params.skeleton.methods;
    let raws: Vec<Result<crate::graph::SkeletonGraph, String>> = methods
        .par_iter()
        .map(|&m| {
            params
                .registry
                .build(m, &params.skeleton)?
                .skeletonise(p)
                .map_err(|e| e.to_string())
        })
        .collect();
    let finish = |raw: &crate::graph::SkeletonGraph| {
        prune_and_extend(raw, p, params.prune.as_ref(), params.extend.as_ref())
    };
    let shared = params
        .prune
        .filter(|pr| pr.mode != PruneMode::None && pr.structure == Sharing::Shared);
    let reference = shared.and_then(|_| {
        params.skeleton.reference_order().into_iter().find_map(|m| {
            methods
                .iter()
                .position(|&x| x == m)
                .filter(|&k| raws[k].is_ok())
        })
    });
    let structure = reference.map(|k| {
        let g = finish(raws[k].as_ref().expect("the reference succeeded"));
        let trunk = params.prune.is_some_and(|pr| pr.mode == PruneMode::Trunk);
        (k, Structure::of(&g, p, trunk), g)
    });
    raws.par_iter()
        .enumerate()
        .map(|(k, raw)| {
            let raw = raw.as_ref().map_err(Clone::clone)?;
            let g = match &structure {
                Some((r, _, g)) if *r == k => g.clone(),
                Some((_, s, _)) => conform(raw, s, p),
                None => finish(raw),
            };
            Ok(PartSkeleton {
                graph: g,
                legs_raw: raw.leg_count(),
            })
        })
        .collect()
}

/// Method `k`'s candidate over all polygon parts: scored, with bars and
/// widths when asked for.
fn candidate(
    k: usize,
    parts: &[PreparedPolygon],
    per_part: &[Vec<Result<PartSkeleton, String>>],
    params: &ProcessParams,
) -> Result<CandidateSkeleton, String> {
    let mut lines = Vec::new();
    let mut all_bars = Vec::new();
    let mut widths = Vec::new();
    let (mut components, mut legs_raw, mut legs) = (0, 0, 0);
    let mut part_offset = 0;
    for (p, results) in parts.iter().zip(per_part) {
        let part = results[k].as_ref().map_err(Clone::clone)?;
        let g = &part.graph;
        legs_raw += part.legs_raw;
        legs += g.leg_count();
        components += g.components();
        if params.score.is_some() {
            let mut b = bars(p, g);
            for bar in &mut b {
                if let Some(h) = &mut bar.hit {
                    h.part += part_offset;
                }
            }
            part_offset += g.branches().len();
            all_bars.extend(b);
        }
        if params.keep_widths {
            widths.extend(medial_axis_transform(g, Some(p.boundary())));
        }
        lines.extend(g.to_multilinestring().0);
    }
    let scores = params.score.map(|_| metrics(&all_bars));
    if !params.keep_bars {
        all_bars.clear();
    }
    Ok(CandidateSkeleton {
        geometry: MultiLineString(lines),
        scores,
        components,
        legs_raw,
        legs,
        bars: all_bars,
        widths,
    })
}

/// The reason a prepared polygon is invalid, if it is (self-intersection,
/// crossing or touching rings, holes outside the shell).
fn invalidity(parts: &[PreparedPolygon]) -> Option<String> {
    for (i, p) in parts.iter().enumerate() {
        if let Some(err) = crate::geometry::validity::problem(p) {
            let prefix = if parts.len() > 1 {
                format!("part {i}: ")
            } else {
                String::new()
            };
            return Some(format!(
                "{prefix}invalid polygon: {err}; enable `prepare: {{ make_valid: true }}` to repair it"
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::{point, polygon};

    #[test]
    fn non_polygons_are_rejected_with_reason() {
        let p = ProcessParams::default();
        let r = process(Some(&Geometry::Point(point!(x: 1., y: 2.))), &p);
        assert!(matches!(r, Processed::Rejected(ref s) if s.contains("point")));
        assert!(matches!(process(None, &p), Processed::Rejected(ref s) if s.contains("NULL")));
    }

    #[test]
    fn bow_tie_is_rejected_as_invalid() {
        let p = ProcessParams::default();
        let bow = polygon![(x: 0., y: 0.), (x: 4., y: 4.), (x: 4., y: 0.), (x: 0., y: 6.)];
        let r = process(Some(&Geometry::Polygon(bow)), &p);
        assert!(
            matches!(r, Processed::Rejected(ref s) if s.contains("invalid")),
            "{r:?}"
        );
    }

    #[test]
    fn rectangle_gets_a_cdt_skeleton() {
        let p = ProcessParams {
            skeleton: SkeletonParams {
                methods: vec![MethodId::CDT],
                ..Default::default()
            },
            ..Default::default()
        };
        let r = process(
            Some(&Geometry::Polygon(
                polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)],
            )),
            &p,
        );
        let Processed::Done(o) = r else {
            panic!("{r:?}")
        };
        assert_eq!(o.chosen().0, &MethodId::CDT);
        assert!(!o.chosen().1.geometry.0.is_empty());
    }

    #[test]
    fn min_area_filters() {
        let p = ProcessParams {
            prepare: PrepareParams {
                make_valid: true,
                min_area: 100.0,
            },
            ..Default::default()
        };
        let r = process(
            Some(&Geometry::Polygon(
                polygon![(x: 0., y: 0.), (x: 1., y: 0.), (x: 1., y: 1.)],
            )),
            &p,
        );
        assert_eq!(r, Processed::Filtered);
    }
}
