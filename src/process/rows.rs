//! From one input feature to its output rows: the one per-feature path of
//! every command. `run` computes the skeletons with the pipeline's methods;
//! `score` takes them from another tool's lines ([`Skeletons`]); both go
//! through the same steps from `score` on and give the same rows.

use super::{process_checked, process_given, FeatureOutcome, ProcessParams, Processed, StageTimes};
use crate::collapse::AreaRow;
use crate::connect::ConnectionRow;
use crate::feature::Feature;
use crate::methods::MethodId;
use crate::output::{BarRow, CandidateRow, RejectedRow, Rows, SkeletonRow, WidthRow};
use geo::{Geometry, MultiLineString};

/// Where a feature's skeletons come from.
#[derive(Debug, Clone, Copy)]
pub enum Skeletons<'a> {
    /// Computed by the pipeline's methods.
    Computed,
    /// Made by another tool (`label` goes to the `method` attribute); `None`
    /// when no line was joined to the feature.
    Given {
        /// The other tool's name.
        label: &'a str,
        /// Its lines for this feature.
        lines: Option<&'a MultiLineString<f64>>,
    },
}

/// Which optional rows to make (the `output` section's switches).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RowOptions {
    /// One row per polygon part.
    pub explode: bool,
    /// Every method's row in `candidates`.
    pub candidates: bool,
    /// Every bar in `bars`.
    pub bars: bool,
    /// The chosen skeleton's local widths in `widths`.
    pub widths: bool,
    /// M values (local width) on the skeleton layer's lines.
    pub measures: bool,
    /// The chosen skeleton's pieces in `network` (with `input.connect`).
    pub network: bool,
}

impl RowOptions {
    /// What a run with `plan` keeps of every feature.
    pub fn of(plan: &crate::output::Plan) -> Self {
        use crate::output::When;
        Self {
            explode: plan.holds(When::Explode),
            candidates: plan.holds(When::Candidates),
            bars: plan.holds(When::Bars),
            widths: plan.holds(When::Widths),
            measures: plan.holds(When::Measures),
            network: plan.holds(When::Connect),
        }
    }
}

/// How a feature counts in the run's summary.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Status {
    /// Written, with the method chosen for each row.
    Written(Vec<String>),
    /// Listed in `rejected` (any polygon part rejected).
    Rejected,
    /// Skipped by `min_area`.
    Filtered,
}

/// A feature's rows and how it counts.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureRows {
    /// The rows, layer by layer.
    pub rows: Rows,
    /// How the feature counts.
    pub status: Status,
    /// Each method's step times on this feature (all its units).
    pub times: Vec<(MethodId, StageTimes)>,
    /// The CPU time on this feature of each registered step, by the step's
    /// name (all its units).
    pub step_times: Vec<(&'static str, std::time::Duration)>,
}

/// One polygon (or polygon part) through the per-feature path, its
/// skeletons computed or given. A panic is a bug; it must cost this
/// feature, never the run.
/// `checked`: the reader found the geometry valid already
/// ([`Feature::checked`]).
fn fenced(
    geom: Option<&Geometry<f64>>,
    checked: bool,
    skeletons: Skeletons<'_>,
    params: &ProcessParams,
) -> Processed {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match skeletons {
        Skeletons::Computed => process_checked(geom, params, checked),
        Skeletons::Given { label, lines } => match lines {
            Some(l) => process_given(geom, l, label, params),
            None => Processed::Rejected(format!(
                "{label}: no skeleton lines joined to this polygon; check the join key or the skeletons' location"
            )),
        },
    }))
    .unwrap_or_else(|_| {
        Processed::Rejected(
            "internal error while processing this feature; the run went on — please report it".into(),
        )
    })
}

/// The output rows of one feature (see the module documentation).
pub fn feature_rows(
    f: &Feature,
    skeletons: Skeletons<'_>,
    params: &ProcessParams,
    opts: RowOptions,
) -> FeatureRows {
    let mut rows = Rows::default();
    if let Some(e) = &f.geometry_error {
        rows.rejected.extend(rejected(f, e.clone()));
        return FeatureRows {
            rows,
            status: Status::Rejected,
            times: Vec::new(),
            step_times: Vec::new(),
        };
    }
    let mut methods = Vec::new();
    let mut times: Vec<(MethodId, StageTimes)> = Vec::new();
    let mut step_times: Vec<(&'static str, std::time::Duration)> = Vec::new();
    let mut reasons: Vec<String> = Vec::new();
    for (part, geom) in units(f.geometry.as_ref(), opts.explode) {
        let processed = fenced(geom.as_ref(), f.checked, skeletons, params);
        let label = match skeletons {
            Skeletons::Computed => None,
            Skeletons::Given { label, .. } => Some(label),
        };
        match processed {
            Processed::Done(o) => {
                for c in &o.candidates {
                    match times.iter_mut().find(|(m, _)| *m == c.method) {
                        Some((_, t)) => *t += c.time,
                        None => times.push((c.method, c.time)),
                    }
                }
                for &(name, t) in &o.step_times {
                    super::run::add_time(&mut step_times, name, t.0);
                }
                methods.push(outcome_rows(f, part, &o, label, opts, &mut rows));
            }
            Processed::Filtered => {}
            Processed::Rejected(reason) => {
                reasons.push(match part {
                    Some(i) if opts.explode => format!("part {i}: {reason}"),
                    _ => reason,
                });
            }
        }
    }
    // A feature is written whole or rejected whole: with `explode`, a part
    // that cannot be processed rejects the feature (one row, every part's
    // reason; a row per member of a merged group), and its other parts'
    // rows are not written.
    if !reasons.is_empty() {
        rows = Rows::default();
        rows.rejected.extend(rejected(f, reasons.join("; ")));
        methods.clear();
    }
    let status = if !rows.rejected.is_empty() {
        Status::Rejected
    } else if methods.is_empty() {
        Status::Filtered
    } else {
        Status::Written(methods)
    };
    FeatureRows {
        rows,
        status,
        times,
        step_times,
    }
}

/// The units of work of a feature: the whole geometry, or with `explode`
/// each polygon part (numbered).
fn units(
    geom: Option<&Geometry<f64>>,
    explode: bool,
) -> Vec<(Option<usize>, Option<Geometry<f64>>)> {
    match (geom, explode) {
        (Some(Geometry::MultiPolygon(mp)), true) if !mp.0.is_empty() => {
            mp.0.iter()
                .enumerate()
                .map(|(i, p)| (Some(i), Some(Geometry::Polygon(p.clone()))))
                .collect()
        }
        (g, true) => vec![(Some(0), g.cloned())],
        (g, false) => vec![(None, g.cloned())],
    }
}

/// Why a scored skeleton has no scores, if it has none.
fn score_note(s: &crate::score::Scores) -> Option<String> {
    match (s.bars, s.hits) {
        (0, _) => Some("the polygon has no bars to score its skeleton with; the scores are NULL".into()),
        (n, 0) => Some(format!(
            "none of the {n} bars hits the skeleton: the lines are too short or too far off the polygon's middle for a bar to reach them, or the polygon is too thin to score at its scale (bars shorter than a millionth of its extent); the scores are NULL"
        )),
        _ => None,
    }
}

/// The row's note: the candidate's own and why its scores are missing.
fn notes(c: &crate::process::CandidateSkeleton) -> Option<String> {
    let parts: Vec<String> = c
        .note
        .iter()
        .cloned()
        .chain(c.scores.and_then(|s| score_note(&s)))
        .collect();
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// The `rejected` rows of a feature: one, or for a group of merged
/// features one per member, each with its own FID and source geometry.
fn rejected(f: &Feature, reason: String) -> Vec<RejectedRow> {
    if f.members.is_empty() {
        return vec![RejectedRow {
            src_fid: f.fid,
            reason,
            wkb: f.source_wkb.clone(),
        }];
    }
    let all = members_text(f).unwrap_or_default();
    f.members
        .iter()
        .enumerate()
        .map(|(i, &fid)| RejectedRow {
            src_fid: Some(fid),
            reason: format!("{reason} (merged features {all})"),
            wkb: f.member_wkb.get(i).cloned().flatten(),
        })
        .collect()
}

/// The source FIDs a feature stands for, comma-separated (its own when it
/// merged none).
fn members_text(f: &Feature) -> Option<String> {
    let fids: Vec<String> = if f.members.is_empty() {
        f.fid.iter().map(u64::to_string).collect()
    } else {
        f.members.iter().map(u64::to_string).collect()
    };
    (!fids.is_empty()).then(|| fids.join(","))
}

/// Appends the rows of one processed unit; returns the chosen method's name.
fn outcome_rows(
    f: &Feature,
    part: Option<usize>,
    o: &FeatureOutcome,
    label: Option<&str>,
    opts: RowOptions,
    rows: &mut Rows,
) -> String {
    let name = |m: crate::methods::MethodId| label.map_or_else(|| m.to_string(), str::to_string);
    let (method, chosen) = o.chosen();
    let method = name(*method);
    let members = members_text(f);
    let row = |geometry: MultiLineString<f64>,
               collapsed: Option<bool>,
               measures: Option<Vec<Vec<f64>>>| SkeletonRow {
        src_fid: f.fid,
        polygon_part: part,
        attributes: f.attributes.clone(),
        geometry,
        method: method.clone(),
        scores: chosen.scores,
        components: chosen.components,
        legs: chosen.legs,
        repaired: f.repaired,
        note: notes(chosen),
        collapsed,
        members: members.clone(),
        measures,
    };
    match &o.collapse {
        None => rows
            .skeletons
            .push(row(chosen.geometry.clone(), None, o.measures.clone())),
        Some(parts) => collapse_rows(f, part, parts, o, &members, &row, rows),
    }
    rows.connections
        .extend(o.connections.iter().map(|c| ConnectionRow {
            src_fid: f.fid,
            line_fid: c.line_fid,
            geometry: c.leg.clone(),
        }));
    if opts.network {
        for g in &chosen.graphs {
            rows.network
                .extend(crate::connect::skeleton_rows(g, &o.connections, f.fid));
        }
    }
    if opts.widths {
        rows.widths.extend(chosen.widths.iter().map(|w| WidthRow {
            src_fid: f.fid,
            method: method.clone(),
            geometry: w.line,
            width_start: w.width_start(),
            width_end: w.width_end(),
        }));
    }
    candidate_rows(f, part, o, &name, opts, rows);
    for (layer, row) in &o.extra {
        rows.extra
            .entry(layer)
            .or_default()
            .push(crate::output::ExtraRow {
                src_fid: f.fid,
                polygon_part: part,
                members: members.clone(),
                attributes: f.attributes.clone(),
                row: row.clone(),
            });
    }
    rows.kept
        .extend(o.kept.iter().map(|(step, k)| (*step, f.fid, k.clone())));
    method
}

/// Makes a feature's skeleton row from its lines, `collapsed` and M values.
type SkeletonRowOf<'a> =
    dyn Fn(MultiLineString<f64>, Option<bool>, Option<Vec<Vec<f64>>>) -> SkeletonRow + 'a;

/// The rows of a collapsed polygon part: its collapsed lines, the
/// centreline through its kept areas (one of them at least, so that every
/// feature written has a skeleton row), and the kept areas.
fn collapse_rows(
    f: &Feature,
    part: Option<usize>,
    parts: &[crate::collapse::PartCollapse],
    o: &FeatureOutcome,
    members: &Option<String>,
    row: &SkeletonRowOf,
    rows: &mut Rows,
) {
    let collapsed: Vec<_> = parts.iter().flat_map(|c| c.collapsed.clone()).collect();
    let kept: Vec<_> = parts.iter().flat_map(|c| c.kept.clone()).collect();
    let m = |of: fn(&crate::collapse::PartCollapse) -> &Vec<Vec<f64>>| {
        o.measures
            .as_ref()
            .map(|_| parts.iter().flat_map(|c| of(c).clone()).collect::<Vec<_>>())
    };
    let any_collapsed = !collapsed.is_empty();
    if any_collapsed {
        rows.skeletons.push(row(
            MultiLineString(collapsed),
            Some(true),
            m(|c| &c.collapsed_measures),
        ));
    }
    // Every feature written has a skeleton row.
    if !kept.is_empty() || !any_collapsed {
        rows.skeletons.push(row(
            MultiLineString(kept),
            Some(false),
            m(|c| &c.kept_measures),
        ));
    }
    rows.areas
        .extend(parts.iter().flat_map(|c| &c.areas).map(|a| AreaRow {
            src_fid: f.fid,
            polygon_part: part,
            attributes: f.attributes.clone(),
            geometry: a.polygon.clone(),
            cuts: a.cuts,
            members: members.clone(),
        }));
}

/// Every method's `candidates` row and `bars` rows of one polygon part (as
/// the options ask).
fn candidate_rows(
    f: &Feature,
    part: Option<usize>,
    o: &FeatureOutcome,
    name: &dyn Fn(crate::methods::MethodId) -> String,
    opts: RowOptions,
    rows: &mut Rows,
) {
    for (i, c) in o.candidates.iter().enumerate() {
        let cname = name(c.method);
        let ok = c.result.as_ref().ok();
        if opts.candidates {
            rows.candidates.push(CandidateRow {
                src_fid: f.fid,
                polygon_part: part,
                method: cname.clone(),
                geometry: ok.map(|s| s.geometry.clone()),
                scores: ok.and_then(|s| s.scores),
                chosen: i == o.chosen,
                components: ok.map_or(0, |s| s.components),
                legs_raw: ok.map_or(0, |s| s.legs_raw),
                legs: ok.map_or(0, |s| s.legs),
                error: c.result.as_ref().err().map(ToString::to_string),
            });
        }
        if let (true, Some(s)) = (opts.bars, ok) {
            rows.bars.extend(s.bars.iter().map(|b| BarRow {
                src_fid: f.fid,
                method: cname.clone(),
                geometry: geo::LineString(vec![b.origin, b.hit.map_or(b.origin, |h| h.point)]),
                d_left: b.hit.map(|h| h.d_left),
                d_right: b.hit.map(|h| h.d_right),
                delta_d: b.hit.map(|h| h.delta_d()),
                z: b.hit.map(|h| h.z()),
                branch: b.hit.map(|h| h.part),
            }));
        }
    }
}
