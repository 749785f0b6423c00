//! A feature's outcome: every method's candidate, the chosen one, and what
//! the steps after selection add to it (connection legs, collapse, local
//! widths, registered steps' rows); or its rejection.

use super::prepare::prepare_checked;
use super::types::{
    Candidate, CandidateError, FeatureOutcome, ProcessParams, Processed, StageTimes,
};
use super::{candidates, step};
use crate::collapse::collapse_within;
use crate::connect;
use crate::geometry::PreparedPolygon;
use crate::methods::{MethodContext, MethodId};
use crate::score::select::{select, Entry};
use geo::{Geometry, MultiLineString};

/// Processes one feature's geometry through every step.
pub fn process(geom: Option<&Geometry<f64>>, params: &ProcessParams) -> Processed {
    process_checked(geom, params, false)
}

/// [`process`] of a geometry the reader found valid already (`checked`:
/// [`crate::feature::Feature::checked`]; see [`prepare_checked`]).
pub fn process_checked(
    geom: Option<&Geometry<f64>>,
    params: &ProcessParams,
    checked: bool,
) -> Processed {
    let prepared = match prepare_checked(geom, &params.prepare, checked) {
        Ok(p) => p,
        Err(other) => return other.into(),
    };
    let candidates = candidates::computed(&prepared, params);
    let mut processed = choose(candidates, prepared.len(), params);
    if let Processed::Done(o) = &mut processed {
        if let Err(reason) = after_select(o, &prepared, params) {
            return Processed::Rejected(reason.to_string());
        }
    }
    processed
}

/// Why a step after `select` rejects a feature (the text is its reason in
/// `rejected`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The step ran past the steps' deadline (`skeleton.timeout_s` once more
    /// for each polygon part, on a clock of their own).
    #[error("`{step}` ran past `skeleton.timeout_s` ({seconds} s for this polygon: the steps after `select` have the budget once more for each polygon part, on a clock of their own); raise the budget, or leave `{step}` out for such polygons")]
    TimeUp {
        /// The step (its key in the pipeline file).
        step: &'static str,
        /// The deadline, in seconds.
        seconds: f64,
    },
    /// `collapse` draws the medial axis, and the run has no MA.
    #[error("`collapse` draws the medial axis: add MA to `skeleton.methods`")]
    CollapseWithoutMedialAxis,
    /// `collapse` draws the medial axis, and MA failed on this polygon.
    #[error("`collapse` draws the medial axis, and MA failed on this polygon: {0}")]
    MedialAxisFailed(CandidateError),
    /// A registered step rejected the feature
    /// ([`FeatureStep::rows`](step::FeatureStep::rows) failed).
    #[error("`{step}`: {reason}")]
    Step {
        /// The step (its key in the pipeline file).
        step: &'static str,
        /// Why, as the step says.
        reason: String,
    },
}

/// The clock of the steps after `select` on one feature: `skeleton.timeout_s`
/// once more for each polygon part (as each method has it for each part),
/// started when selection is done (a method's own budget covers its work
/// up to its scores). Each step checks it between polygon parts and in its
/// long loops; the feature is rejected naming the step that ran past it.
struct StepClock(MethodContext);

impl StepClock {
    /// The clock of the steps after `select` on a feature of `parts` polygon
    /// parts, started now.
    fn start(params: &ProcessParams, parts: usize) -> Self {
        let mut budget = params.skeleton.budget();
        budget.time = budget.time.map(|t| {
            let s = t.as_secs_f64() * parts.max(1) as f64;
            std::time::Duration::from_secs_f64(s.min(crate::methods::MAX_TIMEOUT_S))
        });
        Self(MethodContext::start(budget))
    }

    /// Fails with [`Self::reason`] once the deadline has passed.
    fn check(&self, step: &'static str) -> Result<(), StepError> {
        match self.0.expired() {
            true => Err(self.reason(step)),
            false => Ok(()),
        }
    }

    /// Why the feature is rejected when `step` ran past the deadline.
    fn reason(&self, step: &'static str) -> StepError {
        StepError::TimeUp {
            step,
            seconds: self.0.budget().time.unwrap_or_default().as_secs_f64(),
        }
    }
}

/// The steps after `select` on one feature, in their order: the connection
/// legs, `collapse`, the local widths (`keep_measures`) and the registered
/// steps (`partition`, `label`, …), within one [`StepClock`].
fn after_select(
    o: &mut FeatureOutcome,
    prepared: &[PreparedPolygon],
    params: &ProcessParams,
) -> Result<(), StepError> {
    let clock = StepClock::start(params, prepared.len());
    if let Some(net) = &params.connect {
        connect_chosen(o, prepared, net, &clock)?;
    }
    if let Some(c) = &params.collapse {
        collapse_chosen(o, prepared, c, params, &clock)?;
    }
    if params.keep_measures {
        measure(o, prepared);
        clock.check("output.measures")?;
    }
    for e in &params.extra {
        registered(o, prepared, e, params, &clock)?;
    }
    Ok(())
}

/// A registered step on one feature: what it [needs](step::Needs) taken
/// from the outcome and the run, its rows and what it keeps added to the
/// outcome, its CPU time (with the time of MA's diagram cells it reads).
fn registered(
    o: &mut FeatureOutcome,
    prepared: &[PreparedPolygon],
    e: &step::Extra,
    params: &ProcessParams,
    clock: &StepClock,
) -> Result<(), StepError> {
    let needs = e.step.needs(e.entry.needs);
    let started = crate::clock::CpuClock::start();
    // The diagram's cells are taken from MA's candidate, which no later
    // step reads.
    let cells: Vec<step::DiagramCells> = match needs.cells {
        true => o
            .candidates
            .iter_mut()
            .find(|c| c.method == MethodId::MA)
            .and_then(|c| c.result.as_mut().ok())
            .map(|m| std::mem::take(&mut m.cells))
            .filter(|c| c.len() == prepared.len())
            .unwrap_or_default(),
        false => Vec::new(),
    };
    let cells_time: std::time::Duration = cells.iter().map(|c| c.time).sum();
    let has_cells = !cells.is_empty();
    let cells = std::cell::RefCell::new(cells);
    let medial_axis = o
        .candidates
        .iter()
        .find(|c| c.method == MethodId::MA && needs.medial_axis)
        .and_then(|c| c.result.as_ref().ok())
        .map(|c| c.raw.as_slice())
        .filter(|raw| raw.len() == prepared.len());
    let made = e.step.output(&step::StepInput {
        parts: prepared,
        outcome: o,
        lonlat: params.lonlat.as_ref().filter(|_| needs.lonlat),
        medial_axis,
        side: e.side.as_deref(),
        neighbours: params.neighbours.as_deref().filter(|_| needs.neighbours),
        cells: has_cells.then_some(&cells),
        budget: &clock.0,
    });
    o.step_times.push((
        e.entry.name,
        super::StepTime(started.elapsed() + cells_time),
    ));
    clock.check(e.entry.name)?;
    let (rows, kept) = e.entry.checked_output(made).map_err(|f| StepError::Step {
        step: e.entry.name,
        reason: f.0,
    })?;
    o.extra.extend(rows);
    o.kept.extend(kept.map(|k| (e.entry.name, k)));
    Ok(())
}

/// `collapse` on the medial axis's lines: with `collapse` the skeleton
/// layer is MA's, whichever `select` preferred among the other listed
/// methods (their scores stay in the candidates); the chosen skeleton's
/// connection legs are added to MA's when it was another.
fn collapse_chosen(
    o: &mut FeatureOutcome,
    prepared: &[PreparedPolygon],
    c: &crate::collapse::CollapseParams,
    params: &ProcessParams,
    clock: &StepClock,
) -> Result<(), StepError> {
    let k = match o.candidates.iter().position(|c| c.method == MethodId::MA) {
        Some(k) => match &o.candidates[k].result {
            Ok(_) => k,
            Err(e) => return Err(StepError::MedialAxisFailed(e.clone())),
        },
        None => return Err(StepError::CollapseWithoutMedialAxis),
    };
    if o.chosen != k {
        o.chosen = k;
        if let Some(net) = &params.connect {
            o.connections.clear();
            connect_chosen(o, prepared, net, clock)?;
        }
    }
    let legs: Vec<(geo::Coord<f64>, geo::Coord<f64>)> = o
        .connections
        .iter()
        .filter_map(|l| Some((*l.leg.0.first()?, *l.leg.0.last()?)))
        .collect();
    let (_, chosen) = o.chosen();
    let mut parts = Vec::with_capacity(prepared.len());
    let expired = || clock.0.expired();
    for (g, p) in chosen.graphs.iter().zip(prepared) {
        let part = collapse_within(g, p, c, &legs, &expired);
        clock.check("collapse")?;
        // `None` only when the deadline passed (checked just above).
        parts.push(part.ok_or_else(|| clock.reason("collapse"))?);
    }
    o.collapse = Some(parts);
    Ok(())
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
fn connect_chosen(
    o: &mut FeatureOutcome,
    prepared: &[PreparedPolygon],
    net: &connect::Network,
    clock: &StepClock,
) -> Result<(), StepError> {
    let chosen = o.chosen;
    let Ok(c) = &mut o.candidates[chosen].result else {
        return Ok(());
    };
    let mut lines = Vec::new();
    let (mut legs, mut components) = (0, 0);
    let expired = || clock.0.expired();
    for (g, p) in c.graphs.iter_mut().zip(prepared) {
        let added = connect::add_legs(g, p, &net.points(p), &expired);
        clock.check("input.connect")?;
        // `None` only when the deadline passed (checked just above).
        let (with_legs, added) = added.ok_or_else(|| clock.reason("input.connect"))?;
        *g = with_legs;
        o.connections.extend(added);
        legs += g.leg_count();
        components += g.components();
        lines.extend(g.to_multilinestring().0);
    }
    c.geometry = MultiLineString(lines);
    c.legs = legs;
    c.components = components;
    Ok(())
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
    let prepared = match prepare_checked(geom, &params.prepare, false) {
        Ok(p) => p,
        Err(other) => return other.into(),
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
    let clock = crate::clock::CpuClock::start();
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
                if let Some(t) = crate::geometry::segment::segment_parameter(a, b, s.a, s.b) {
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

/// The outcome for a feature's candidates: the chosen one by `select` (or
/// the first with a skeleton), or the rejection when none has one.
fn choose(candidates: Vec<Candidate>, parts: usize, params: &ProcessParams) -> Processed {
    let scores: Vec<Option<Entry>> = candidates
        .iter()
        .map(|c| match &c.result {
            Ok(s) if !s.geometry.0.is_empty() => Some(Entry {
                scores: s.scores.unwrap_or_default(),
                components: s.components,
            }),
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
            extra: Vec::new(),
            kept: Vec::new(),
            step_times: Vec::new(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::{MethodError, SkeletonParams};
    use crate::process::{CandidateSkeleton, PrepareParams};
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
        assert!(matches!(
            c[0].result,
            Err(CandidateError::Method(MethodError::TooManyPoints { .. }))
        ));
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
