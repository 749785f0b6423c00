//! The per-feature work: prepare → skeleton → prune → extend → score →
//! select, on owned `geo` geometry with no I/O and no global state, so that
//! features can be processed in parallel with identical results for any
//! thread count.

mod candidates;
pub mod clock;
pub mod merge;
pub mod rows;

pub use rows::{feature_rows, FeatureRows, RowOptions, Skeletons, Status};

/// `f` over `items`, results in the items' order: in parallel, or on the
/// calling thread when `parallel` is false (work too small to be worth
/// splitting, or a caller that keeps to one thread). The same results
/// either way.
pub fn map_in_order<T: Sync, U: Send>(
    items: &[T],
    parallel: bool,
    f: impl Fn(usize, &T) -> U + Sync + Send,
) -> Vec<U> {
    use rayon::prelude::*;
    if parallel {
        items.par_iter().enumerate().map(|(i, t)| f(i, t)).collect()
    } else {
        items.iter().enumerate().map(|(i, t)| f(i, t)).collect()
    }
}

use crate::collapse::{collapse, CollapseParams, PartCollapse};
use crate::connect;
use crate::geometry::PreparedPolygon;
use crate::graph::extend::ExtendParams;
use crate::graph::prune::PruneParams;
use crate::methods::medial_axis::MatSegment;
use crate::methods::{MethodId, Registry, SkeletonParams};
use crate::score::select::{select, SelectParams};
use crate::score::{Bar, ScoreParams, Scores};
use geo::{Area, Geometry, MultiLineString, Polygon};
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
    /// A feature with more boundary vertices than this is rejected with the
    /// reason, before any method runs (0: no limit).
    pub max_vertices: usize,
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
            max_vertices: 5_000_000,
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
    /// `collapse` step, when present: the chosen skeleton collapses the
    /// polygon where it is narrow.
    pub collapse: Option<CollapseParams>,
    /// `input.connect`: the line network the chosen skeleton gets legs to.
    pub connect: Option<std::sync::Arc<connect::Network>>,
    /// `score` step, when present.
    pub score: Option<ScoreParams>,
    /// `select` step, when present.
    pub select: Option<SelectParams>,
    /// Keep every bar (for the diagnostic `bars` layer).
    pub keep_bars: bool,
    /// Keep the local widths of the skeleton (for the `widths` layer).
    pub keep_widths: bool,
    /// The local width at every vertex of the written lines (M values,
    /// `output.measures: width`).
    pub keep_measures: bool,
    /// The methods `skeleton.methods` may name.
    pub registry: Registry,
}

impl ProcessParams {
    /// Every step with its defaults, as a pipeline file that lists
    /// `prepare`, `skeleton`, `prune`, `extend`, `score` and `select` with
    /// no options runs them.
    pub fn all_steps() -> Self {
        Self {
            prune: Some(PruneParams::default()),
            extend: Some(ExtendParams::default()),
            score: Some(ScoreParams::default()),
            select: Some(SelectParams::default()),
            ..Self::default()
        }
    }
}

/// One method's result for one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The method.
    pub method: MethodId,
    /// The skeleton, or why the method failed on this feature.
    pub result: Result<CandidateSkeleton, String>,
    /// How long each step took for this method.
    pub time: StageTimes,
}

/// Thread CPU time one method spent on one feature, step by step (summed over
/// polygon parts). Measurements, not results: any two compare equal, so
/// that two runs' results can be compared whatever the clock said.
#[derive(Debug, Clone, Copy, Default)]
pub struct StageTimes {
    /// The raw skeleton.
    pub skeleton: std::time::Duration,
    /// Pruning and extension (for the reference method: also the structure
    /// every other method is pruned to; for the others: conforming to it).
    pub prune_extend: std::time::Duration,
    /// Bars, hits, sides and metrics (the rays all methods share are split
    /// evenly between them).
    pub score: std::time::Duration,
}

impl PartialEq for StageTimes {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::ops::AddAssign for StageTimes {
    fn add_assign(&mut self, o: Self) {
        self.skeleton += o.skeleton;
        self.prune_extend += o.prune_extend;
        self.score += o.score;
    }
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
    /// The finished skeleton graph of every polygon part, when the pipeline
    /// collapses (the `collapse` step works on graphs).
    pub graphs: Vec<crate::graph::SkeletonGraph>,
    /// Something the scores alone do not tell (e.g. a given skeleton that
    /// leaves its polygon), for the row's `note`.
    pub note: Option<String>,
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
    /// The chosen skeleton's collapse, part by part, when the pipeline has a
    /// `collapse` step.
    pub collapse: Option<Vec<PartCollapse>>,
    /// The legs added to the chosen skeleton for `input.connect`.
    pub connections: Vec<connect::ConnectionLeg>,
    /// With `output.measures: width`: the local width at every vertex of the
    /// chosen skeleton, line by line.
    pub measures: Option<Vec<Vec<f64>>>,
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
    let prepared = match prepare(geom, &params.prepare) {
        Ok(p) => p,
        Err(other) => return other,
    };
    let candidates = candidates::computed(&prepared, params);
    let mut processed = choose(candidates, prepared.len(), params);
    if let (Some(net), Processed::Done(o)) = (&params.connect, &mut processed) {
        connect_chosen(o, &prepared, net);
    }
    if let (Some(c), Processed::Done(o)) = (&params.collapse, &mut processed) {
        let legs: Vec<(geo::Coord<f64>, geo::Coord<f64>)> = o
            .connections
            .iter()
            .filter_map(|l| Some((*l.leg.0.first()?, *l.leg.0.last()?)))
            .collect();
        let (_, chosen) = o.chosen();
        o.collapse = Some(
            chosen
                .graphs
                .iter()
                .zip(&prepared)
                .map(|(g, p)| collapse(g, p, c, &legs))
                .collect(),
        );
    }
    if let (true, Processed::Done(o)) = (params.keep_measures, &mut processed) {
        measure(o, &prepared);
    }
    processed
}

/// The local width 2r (r: distance to the nearest polygon part's boundary)
/// at every vertex of the outcome's lines, for M values.
fn measure(o: &mut FeatureOutcome, prepared: &[PreparedPolygon]) {
    let widths = |lines: &[geo::LineString<f64>]| -> Vec<Vec<f64>> {
        lines
            .iter()
            .map(|l| {
                l.0.iter()
                    .map(|&c| {
                        2.0 * prepared
                            .iter()
                            .map(|p| p.boundary().distance(c))
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect()
            })
            .collect()
    };
    let (_, chosen) = o.chosen();
    o.measures = Some(widths(&chosen.geometry.0));
    for c in o.collapse.iter_mut().flatten() {
        c.collapsed_measures = widths(&c.collapsed);
        c.kept_measures = widths(&c.kept);
    }
}

/// The chosen skeleton with a leg to every connection point of the
/// network (its scores stay those of the skeleton without them).
fn connect_chosen(o: &mut FeatureOutcome, prepared: &[PreparedPolygon], net: &connect::Network) {
    let chosen = o.chosen;
    let Ok(c) = &mut o.candidates[chosen].result else {
        return;
    };
    let mut lines = Vec::new();
    let (mut legs, mut components) = (0, 0);
    for (g, p) in c.graphs.iter_mut().zip(prepared) {
        let (with_legs, added) = connect::add_legs(g, p, &net.points(p));
        *g = with_legs;
        o.connections.extend(added);
        legs += g.leg_count();
        components += g.components();
        lines.extend(g.to_multilinestring().0);
    }
    c.geometry = MultiLineString(lines);
    c.legs = legs;
    c.components = components;
}

/// Scores skeleton lines made by another tool (`label`) for one feature's
/// geometry: the same steps as [`process`] from `score` on, with the lines
/// in place of the methods' skeletons.
pub fn process_given(
    geom: Option<&Geometry<f64>>,
    lines: &MultiLineString<f64>,
    label: &str,
    params: &ProcessParams,
) -> Processed {
    let prepared = match prepare(geom, &params.prepare) {
        Ok(p) => p,
        Err(other) => return other,
    };
    if lines.0.iter().all(|l| l.0.len() < 2) {
        return Processed::Rejected(format!("{label}: no skeleton lines joined to this polygon"));
    }
    let (outside, total) = length_outside(lines, &prepared);
    if total > 0.0 && outside > 0.5 * total {
        return Processed::Rejected(format!(
            "{label}: {:.0} % of the skeleton's length lies outside its polygon, so it is not this polygon's skeleton; check the join (`--skeleton-key`/`--polygon-key`, or the location) and that both layers are in the same CRS",
            100.0 * outside / total
        ));
    }
    let clock = clock::CpuClock::start();
    let mut given = candidates::given(&prepared, lines, params);
    if outside > 1e-6 * total {
        given.note = Some(format!(
            "{:.2} % of the skeleton's length ({outside:.3} CRS units) lies outside the polygon; bars cannot hit it there",
            100.0 * outside / total
        ));
    }
    let result = Ok(given);
    let candidate = Candidate {
        method: MethodId::EXTERNAL,
        result,
        time: StageTimes {
            score: clock.elapsed(),
            ..StageTimes::default()
        },
    };
    choose(vec![candidate], prepared.len(), params)
}

/// The length of `lines` outside every polygon part, and their whole
/// length: each segment is split where it crosses a boundary and every
/// piece is placed by its midpoint.
fn length_outside(lines: &MultiLineString<f64>, parts: &[PreparedPolygon]) -> (f64, f64) {
    let (mut outside, mut total) = (0.0, 0.0);
    for w in lines.0.iter().flat_map(|l| l.0.windows(2)) {
        let (a, b) = (w[0], w[1]);
        let len = crate::geometry::norm(b - a);
        if len == 0.0 {
            continue;
        }
        total += len;
        let mut ts = vec![0.0, 1.0];
        for p in parts {
            let bd = p.boundary();
            for i in bd.segments_near(a, b) {
                let s = &bd.segments()[i];
                if let Some(t) = crate::geometry::boundary::segment_parameter(a, b, s.a, s.b) {
                    ts.push(t);
                }
            }
        }
        ts.sort_by(f64::total_cmp);
        for t in ts.windows(2).filter(|t| t[1] > t[0]) {
            let m = a + (b - a) * (0.5 * (t[0] + t[1]));
            if !parts.iter().any(|p| p.boundary().contains(m)) {
                outside += (t[1] - t[0]) * len;
            }
        }
    }
    (outside, total)
}

/// The polygon parts of a feature's geometry, normalised and checked, or
/// what becomes of the feature instead (rejected, or filtered by
/// `min_area`).
pub fn prepare(
    geom: Option<&Geometry<f64>>,
    params: &PrepareParams,
) -> Result<Vec<PreparedPolygon>, Processed> {
    let parts = polygon_parts(geom).map_err(Processed::Rejected)?;
    let parts: Vec<Polygon<f64>> = parts
        .into_iter()
        .filter(|p| params.min_area <= 0.0 || p.unsigned_area() >= params.min_area)
        .collect();
    if parts.is_empty() {
        return Err(Processed::Filtered);
    }
    let vertices: usize = parts
        .iter()
        .map(|p| p.exterior().0.len() + p.interiors().iter().map(|r| r.0.len()).sum::<usize>())
        .sum();
    if params.max_vertices > 0 && vertices > params.max_vertices {
        return Err(Processed::Rejected(format!(
            "the polygon has {vertices} vertices, more than `prepare.max_vertices` = {}; raise it, or simplify the polygon first",
            params.max_vertices
        )));
    }
    let mut prepared = Vec::with_capacity(parts.len());
    for (i, p) in parts.iter().enumerate() {
        match PreparedPolygon::new(p) {
            Ok(pp) => prepared.push(pp),
            Err(e) => return Err(Processed::Rejected(part_reason(i, parts.len(), &e))),
        }
    }
    if let Some(reason) = invalidity(&prepared, params.make_valid) {
        return Err(Processed::Rejected(reason));
    }
    Ok(prepared)
}

/// A reason for polygon part `i` of `n`: prefixed with the part when there
/// is more than one.
pub(crate) fn part_reason(i: usize, n: usize, reason: &dyn std::fmt::Display) -> String {
    if n > 1 {
        format!("part {i}: {reason}")
    } else {
        reason.to_string()
    }
}

/// The outcome for a feature's candidates: the chosen one by `select` (or
/// the first with a skeleton), or the rejection when none has one.
fn choose(candidates: Vec<Candidate>, parts: usize, params: &ProcessParams) -> Processed {
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
            parts,
            collapse: None,
            connections: Vec::new(),
            measures: None,
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

/// The reason a prepared polygon is invalid, if it is (self-intersection,
/// crossing or touching rings, holes outside the shell). The fix suggested
/// depends on whether `make_valid` already ran.
fn invalidity(parts: &[PreparedPolygon], make_valid: bool) -> Option<String> {
    let fix = if make_valid {
        "GDAL's MakeValid left it so; repair the source geometry"
    } else {
        "enable `prepare: { make_valid: true }` to repair it"
    };
    parts.iter().enumerate().find_map(|(i, p)| {
        crate::geometry::validity::problem(p)
            .map(|err| part_reason(i, parts.len(), &format!("invalid polygon: {err}; {fix}")))
    })
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

    /// A coarse L: six vertices, arms 6 wide.
    fn l_shape() -> geo::Polygon<f64> {
        polygon![
            (x: 0., y: 0.), (x: 40., y: 0.), (x: 40., y: 6.), (x: 6., y: 6.),
            (x: 6., y: 30.), (x: 0., y: 30.)
        ]
    }

    /// Every listed method's candidates on an L-shaped polygon with every
    /// step, the reference given.
    fn candidates_of(
        methods: Vec<MethodId>,
        reference: MethodId,
        max_points: usize,
    ) -> Vec<Candidate> {
        let mut p = ProcessParams::all_steps();
        p.skeleton.methods = methods;
        p.skeleton.reference = reference;
        p.skeleton.voronoi.max_points = max_points;
        let r = process(Some(&Geometry::Polygon(l_shape())), &p);
        let Processed::Done(o) = r else {
            panic!("the L-shape is skeletonised: {r:?}")
        };
        o.candidates
    }

    /// The end points of the lines, sorted.
    fn ends(c: &CandidateSkeleton) -> Vec<(f64, f64)> {
        let mut e: Vec<(f64, f64)> = c
            .geometry
            .0
            .iter()
            .flat_map(|l| [l.0[0], l.0[l.0.len() - 1]])
            .map(|p| (p.x, p.y))
            .collect();
        e.sort_by(|a, b| a.partial_cmp(b).unwrap());
        e
    }

    #[test]
    fn a_method_alone_is_the_method_as_the_reference_of_others() {
        // Alone, a method is finished on its own (no structure to share):
        // the skeleton it gives as the reference the others conform to. (VD
        // of the L's six vertices alone has nothing left after pruning.)
        let all = [
            MethodId::MA,
            MethodId::STSK,
            MethodId::DVD,
            MethodId::CDT,
            MethodId::VD,
        ];
        for m in &all[..4] {
            let m = *m;
            let alone = candidates_of(vec![m], m, 2_000_000);
            let with_all = candidates_of(all.to_vec(), m, 2_000_000);
            let k = all.iter().position(|&x| x == m).unwrap();
            let (a, b) = (alone[0].result.as_ref(), with_all[k].result.as_ref());
            let (a, b) = (a.unwrap(), b.unwrap());
            assert!(!a.geometry.0.is_empty(), "{m}");
            assert_eq!(a.geometry, b.geometry, "{m}");
            assert_eq!((a.legs, a.legs_raw), (b.legs, b.legs_raw), "{m}");
        }
    }

    #[test]
    fn a_failed_reference_hands_over_to_the_next_in_the_reference_order() {
        // DVD is the reference but cannot densify into 5 points: StSk, next in
        // the order (CDT comes later), gives the structure, as it does when it
        // is the only method, and CDT's legs reach its contacts.
        let c = candidates_of(
            vec![MethodId::DVD, MethodId::CDT, MethodId::STSK],
            MethodId::DVD,
            5,
        );
        assert!(c[0]
            .result
            .as_ref()
            .is_err_and(|e| e.contains("max_points")));
        let (cdt, stsk) = (c[1].result.as_ref().unwrap(), c[2].result.as_ref().unwrap());
        let alone = candidates_of(vec![MethodId::STSK], MethodId::STSK, 5);
        let alone = alone[0].result.as_ref().unwrap();
        assert!(!stsk.geometry.0.is_empty());
        assert_eq!(stsk.geometry, alone.geometry);
        assert_eq!(ends(cdt), ends(stsk));
        let own = candidates_of(vec![MethodId::CDT], MethodId::CDT, 5);
        assert_ne!(
            ends(own[0].result.as_ref().unwrap()),
            ends(stsk),
            "the test tells them apart"
        );
        // The reference listed after another method: DVD (densified now)
        // reaches CDT's contacts.
        let c = candidates_of(vec![MethodId::DVD, MethodId::CDT], MethodId::CDT, 100_000);
        let (dvd, cdt) = (c[0].result.as_ref().unwrap(), c[1].result.as_ref().unwrap());
        assert_eq!(cdt.geometry, own[0].result.as_ref().unwrap().geometry);
        assert!(dvd.legs_raw > cdt.legs, "{dvd:?}");
        assert_eq!(ends(dvd), ends(cdt));
    }

    #[test]
    fn a_coarse_polygons_legs_reach_the_contacts_through_the_interior() {
        // On the six-vertex L, CDT's leaves lie on the corners next to
        // StSk's contacts: joined to them, they would run along the shore.
        let c = candidates_of(vec![MethodId::STSK, MethodId::CDT], MethodId::STSK, 5);
        let (stsk, cdt) = (c[0].result.as_ref().unwrap(), c[1].result.as_ref().unwrap());
        assert_eq!(ends(cdt), ends(stsk));
        let boundary = crate::geometry::Boundary::new(&l_shape());
        for line in &cdt.geometry.0 {
            for w in line.0.windows(2) {
                let mid = (w[0] + w[1]) * 0.5;
                assert!(
                    boundary.distance(mid) > 1e-3,
                    "{:?} runs along the shore",
                    w
                );
            }
        }
    }

    #[test]
    fn more_vertices_than_max_vertices_is_rejected_before_any_method() {
        let p = ProcessParams {
            prepare: PrepareParams {
                max_vertices: 3,
                ..PrepareParams::default()
            },
            ..ProcessParams::all_steps()
        };
        let sq = polygon![(x: 0., y: 0.), (x: 1., y: 0.), (x: 1., y: 1.), (x: 0., y: 1.)];
        let r = process(Some(&Geometry::Polygon(sq)), &p);
        assert!(
            matches!(r, Processed::Rejected(ref s) if s.contains("max_vertices")),
            "{r:?}"
        );
    }

    #[test]
    fn min_area_filters() {
        let p = ProcessParams {
            prepare: PrepareParams {
                min_area: 100.0,
                ..PrepareParams::default()
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
