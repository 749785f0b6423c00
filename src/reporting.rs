//! The report of an output GeoPackage (`skeletonise report OUT.gpkg`, or
//! `output.report` after a run): reads the file back, chooses the features,
//! reads their polygons from the run's input (recorded in
//! `skeletonise_runs`, or given), computes the bars when the file has none,
//! renders the page ([`crate::report`]) and writes it under a temporary name
//! renamed into place.

use crate::config::{InputSpec, LayerRef};
use crate::feature::{Feature, Value};
use crate::io::guard::{Kind, Protected, Target};
use crate::io::readback::OutputFile;
use crate::io::{IoError, Reader};
use crate::output::{BarRow, CandidateRow, SkeletonRow};
use crate::process::{feature_rows, ProcessParams, RowOptions, Skeletons};
use crate::report::{ranked, render, summarise, Key, Report, Section, Selection};
use crate::score::ScoreParams;
use geo::{BoundingRect, Geometry, MultiPolygon};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;
use thiserror::Error;

/// Most feature sections in one report; a selection of more is cut there,
/// and the report says so.
pub const MAX_SECTIONS: usize = 500;

/// Most boundary vertices of a feature whose bars the report computes when
/// the file has none: scoring costs about as much as making the skeleton,
/// so a larger feature is shown without bars (`output.bars: true` writes
/// them during the run).
pub const MAX_SCORED_VERTICES: usize = 50_000;

/// Most source fields shown in a section's heading.
const HEADING_FIELDS: usize = 6;

/// What to report on and where to write it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportJob {
    /// The output GeoPackage of a run.
    pub gpkg: PathBuf,
    /// The HTML file to write.
    pub html: PathBuf,
    /// The features that get a section.
    pub selection: Selection,
    /// Where the polygons are, when not where `skeletonise_runs` says.
    pub polygons: Option<InputSpec>,
    /// Replace an existing report.
    pub overwrite: bool,
}

/// What a report holds.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportSummary {
    /// The file written.
    pub path: PathBuf,
    /// Feature sections.
    pub sections: usize,
    /// Size in bytes.
    pub bytes: usize,
    /// Time to make it.
    pub seconds: f64,
}

/// Why a report could not be made.
#[derive(Debug, Error)]
pub enum ReportError {
    /// Reading the GeoPackage failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// The polygons the run read cannot be opened.
    #[error("cannot open the polygons of `{gpkg}`: {reason}; give them with `--polygons SRC [--polygons-layer LAYER]`")]
    Polygons {
        /// The GeoPackage reported on.
        gpkg: String,
        /// What failed.
        reason: String,
    },
    /// The selection names no feature of the file.
    #[error("nothing to report: {0}")]
    Nothing(String),
    /// The HTML file cannot be written.
    #[error("cannot write the report `{path}`: {reason}")]
    Write {
        /// The report's path.
        path: String,
        /// What failed.
        reason: String,
    },
}

/// Checks that the report `html` can be written ([`crate::io::guard`]): an
/// `.html` path, no directory, device or FIFO, none of the `protected`
/// sources (the GeoPackage reported on, the polygons read, the run's
/// input), an existing file only with `overwrite`. Creates nothing.
pub fn check_path(
    html: &Path,
    overwrite: bool,
    protected: &[Protected<'_>],
) -> Result<(), IoError> {
    Target {
        path: html,
        kind: Kind::Report,
        overwrite,
        protected,
    }
    .check()
}

/// Makes the report of `job.gpkg` and writes it to `job.html`.
pub fn write_report(job: &ReportJob) -> Result<ReportSummary, ReportError> {
    let clock = Instant::now();
    let gpkg = job.gpkg.display().to_string();
    let mut protected = vec![Protected::new("the GeoPackage reported on", &gpkg)];
    if let Some(p) = &job.polygons {
        protected.push(Protected::new("the polygons source", &p.source));
    }
    check_path(&job.html, job.overwrite, &protected)?;
    let file = OutputFile::open(&job.gpkg)?;
    if let Some(run) = file.run() {
        protected.push(Protected::new("the run's input", &run.input_source));
        check_path(&job.html, job.overwrite, &protected)?;
    }
    let mut notes = Vec::new();
    let has_candidates = file.has_layer(crate::output::CANDIDATES.name);
    if !has_candidates {
        notes.push(
            "The file has no candidates layer: only the chosen skeleton is shown. Run with `output.candidates: true` to compare the methods."
                .to_string(),
        );
    }
    let all = candidates(&file, has_candidates, None, false)?;
    let keys = choose(&file, &all, &job.selection, &mut notes)?;
    let sections = sections(&file, job, has_candidates, &keys, &mut notes)?;
    let run = file.run().cloned();
    let title = match &run {
        Some(r) if !r.name.is_empty() && r.name != r.input_layer => {
            format!("skeletonise report · {} · {}", r.name, r.input_layer)
        }
        Some(r) => format!("skeletonise report · {}", r.input_layer),
        None => format!("skeletonise report · {}", job.gpkg.display()),
    };
    let features = crate::report::by_feature(&all).len();
    let report = Report {
        title,
        run,
        units: file.units(),
        features,
        summary: summarise(&all),
        selection: job.selection.describe(),
        sections,
        notes,
    };
    let html = render(&report);
    write_atomically(&job.html, job.overwrite, &html)?;
    Ok(ReportSummary {
        path: job.html.clone(),
        sections: report.sections.len(),
        bytes: html.len(),
        seconds: clock.elapsed().as_secs_f64(),
    })
}

/// Writes `text` under a new temporary name (never through a link or over
/// a file) and renames it into place; the temporary file is removed on
/// every failure.
fn write_atomically(path: &Path, overwrite: bool, text: &str) -> Result<(), ReportError> {
    let fail = |e: std::io::Error| ReportError::Write {
        path: path.display().to_string(),
        reason: e.to_string(),
    };
    let target = Target {
        path,
        kind: Kind::Report,
        overwrite,
        protected: &[],
    };
    crate::io::signals::remove_stale(path);
    let tmp = target.temporary(std::process::id())?;
    crate::io::signals::register(&tmp);
    let r = crate::io::guard::create_new(&tmp, text.as_bytes())
        .and_then(|_| std::fs::rename(&tmp, path));
    if r.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    crate::io::signals::unregister(&tmp);
    r.map_err(fail)
}

/// Every candidate row passing `filter`, or without a candidates layer the
/// skeleton rows as the only (chosen) candidates.
fn candidates(
    file: &OutputFile,
    has_candidates: bool,
    filter: Option<&str>,
    geometry: bool,
) -> Result<Vec<CandidateRow>, IoError> {
    if has_candidates {
        return file.candidates(filter, geometry);
    }
    Ok(file
        .skeletons(filter, geometry)?
        .into_iter()
        .map(|s| CandidateRow {
            src_fid: s.src_fid,
            polygon_part: s.polygon_part,
            method: s.method,
            geometry: geometry.then_some(s.geometry),
            scores: s.scores,
            chosen: true,
            components: s.components,
            legs_raw: s.legs,
            legs: s.legs,
            error: None,
        })
        .collect())
}

/// The features to show with their disagreement, in the order shown.
fn choose(
    file: &OutputFile,
    all: &[CandidateRow],
    selection: &Selection,
    notes: &mut Vec<String>,
) -> Result<Vec<(Key, f64)>, ReportError> {
    let ranking = ranked(all);
    let dis: HashMap<Key, f64> = ranking.iter().copied().collect();
    let with_dis = |k: Key| dis.get(&k).map(|&d| (k, d));
    let mut keys: Vec<(Key, f64)> = match selection {
        Selection::Top(n) => ranking.into_iter().take(*n).collect(),
        Selection::Fids(fids) => {
            let mut v = Vec::new();
            let mut seen = std::collections::HashSet::new();
            let mut unknown = Vec::new();
            // Each FID once, in the order first given.
            for &fid in fids.iter().filter(|f| seen.insert(**f)) {
                let found: Vec<(Key, f64)> = ranking
                    .iter()
                    .filter(|(k, _)| k.0 == Some(fid))
                    .copied()
                    .collect();
                if found.is_empty() {
                    tracing::warn!("source FID {fid} is not in `{}`", file.path());
                    notes.push(format!("Source FID {fid} is not in the file."));
                    unknown.push(fid.to_string());
                }
                v.extend(found);
            }
            if v.is_empty() {
                return Err(ReportError::Nothing(format!(
                    "none of the source FIDs {} is in `{}`; `ogrinfo {} {} -sql \"SELECT src_fid FROM {}\"` lists them",
                    unknown.join(", "),
                    file.path(),
                    file.path(),
                    file.skeleton_layer(),
                    file.skeleton_layer()
                )));
            }
            v
        }
        Selection::Where(w) => file
            .skeletons(Some(w), false)?
            .iter()
            .filter_map(|s| with_dis((s.src_fid, s.polygon_part)))
            .collect(),
    };
    if keys.len() > MAX_SECTIONS {
        notes.push(format!(
            "{} features match; the first {MAX_SECTIONS} are shown.",
            keys.len()
        ));
        keys.truncate(MAX_SECTIONS);
    }
    Ok(keys)
}

/// `src_fid IN (…)` for the keys.
fn fid_filter(keys: &[(Key, f64)]) -> String {
    let mut fids: Vec<u64> = keys.iter().filter_map(|(k, _)| k.0).collect();
    fids.sort_unstable();
    fids.dedup();
    let list: Vec<String> = fids.iter().map(u64::to_string).collect();
    format!("src_fid IN ({})", list.join(","))
}

/// The input the polygons come from: the job's, or the run's record.
fn polygon_spec(file: &OutputFile, job: &ReportJob) -> Result<InputSpec, ReportError> {
    if let Some(spec) = &job.polygons {
        return Ok(spec.clone());
    }
    let fail = |reason: &str| ReportError::Polygons {
        gpkg: file.path().to_string(),
        reason: reason.to_string(),
    };
    let run = file
        .run()
        .filter(|r| !r.input_source.is_empty())
        .ok_or_else(|| fail("its `skeletonise_runs` table does not record the input source (the file was written by an older version)"))?;
    Ok(InputSpec {
        source: run.input_source.clone(),
        layer: Some(LayerRef::Name(run.input_layer.clone())),
        where_: None,
        bbox: None,
        reproject: run.input_reproject.clone(),
        merge_adjacent: false,
        merge_by: None,
        connect: None,
        neighbours: None,
    })
}

/// The polygons of the keys by source FID; a feature that stands for
/// several (`input.merge_adjacent`: its `members`) gets their union, as the
/// run dissolved them.
fn polygons(
    file: &OutputFile,
    job: &ReportJob,
    keys: &[(Key, f64)],
    members: &HashMap<u64, Vec<u64>>,
) -> Result<(HashMap<u64, Geometry<f64>>, String), ReportError> {
    let spec = polygon_spec(file, job)?;
    let reader = Reader::open(&spec).map_err(|e| ReportError::Polygons {
        gpkg: file.path().to_string(),
        reason: match e {
            IoError::Geographic { layer, crs, .. } => IoError::Geographic {
                layer,
                crs,
                fix: "give `--reproject EPSG:<code>`",
            },
            e => e,
        }
        .to_string(),
    })?;
    let shown: Vec<u64> = keys.iter().filter_map(|(k, _)| k.0).collect();
    let mut fids: Vec<u64> = shown
        .iter()
        .flat_map(|f| members.get(f).cloned().unwrap_or_else(|| vec![*f]))
        .collect();
    fids.sort_unstable();
    fids.dedup();
    let mut read: HashMap<u64, Feature> = reader
        .read_fids(&fids, true)?
        .into_iter()
        .filter_map(|f| Some((f.fid?, f)))
        .collect();
    let by_fid = shown
        .iter()
        .filter_map(|&fid| {
            let feature = match members.get(&fid) {
                Some(m) if m.len() > 1 => {
                    let group: Vec<Feature> =
                        m.iter().filter_map(|f| read.get(f).cloned()).collect();
                    (group.len() == m.len()).then(|| crate::process::merge::dissolve(group))?
                }
                _ => read.remove(&fid)?,
            };
            Some((fid, feature.geometry?))
        })
        .collect();
    Ok((
        by_fid,
        format!("{} (layer {})", spec.source, reader.info().layer),
    ))
}

/// The polygon of a key: the feature's geometry, or with `explode` its
/// polygon part (as the run numbered them).
fn polygon_of(geom: &Geometry<f64>, part: Option<usize>) -> Option<MultiPolygon<f64>> {
    let all = match geom {
        Geometry::Polygon(p) => MultiPolygon(vec![p.clone()]),
        Geometry::MultiPolygon(mp) => mp.clone(),
        _ => return None,
    };
    match part {
        None => Some(all),
        Some(i) => all.0.get(i).map(|p| MultiPolygon(vec![p.clone()])),
    }
}

/// The source fields with a value, for a heading.
fn heading(fields: &[String], row: Option<&SkeletonRow>) -> Vec<(String, String)> {
    let Some(row) = row else { return Vec::new() };
    fields
        .iter()
        .zip(&row.attributes)
        .filter_map(|(n, v)| match v {
            Value::Null => None,
            v => v.as_text().map(|t| (n.clone(), t)),
        })
        .take(HEADING_FIELDS)
        .collect()
}

/// Every selected feature's section: candidates with their skeletons, the
/// polygon, headings and bars.
fn sections(
    file: &OutputFile,
    job: &ReportJob,
    has_candidates: bool,
    keys: &[(Key, f64)],
    notes: &mut Vec<String>,
) -> Result<Vec<Section>, ReportError> {
    if keys.is_empty() {
        return Ok(Vec::new());
    }
    let filter = fid_filter(keys);
    let mut cands: HashMap<Key, Vec<CandidateRow>> = HashMap::new();
    for c in candidates(file, has_candidates, Some(&filter), true)? {
        cands
            .entry((c.src_fid, c.polygon_part))
            .or_default()
            .push(c);
    }
    let fields = file.source_fields()?;
    let rows: HashMap<Key, SkeletonRow> = file
        .skeletons(Some(&filter), false)?
        .into_iter()
        .map(|r| ((r.src_fid, r.polygon_part), r))
        .collect();
    let (polys, source) = polygons(file, job, keys, &members(&rows))?;
    let stored_bars = file.has_layer(crate::output::BARS.name);
    let bars = stored_bars_of(file, &filter)?;
    if !stored_bars {
        notes.push("The file has no bars layer: the bars shown were computed from the written skeletons for the features shown (`output.bars: true` writes them for every feature).".into());
    }
    let mut missing = 0;
    let mut out: Vec<Section> = keys
        .iter()
        .map(|&(key, dis)| {
            let polygon = key.0.and_then(|f| polys.get(&f)).and_then(|g| polygon_of(g, key.1));
            let mut s = Section {
                src_fid: key.0,
                polygon_part: key.1,
                attributes: heading(&fields, rows.get(&key)),
                polygon,
                candidates: cands.remove(&key).unwrap_or_default(),
                bars: Vec::new(),
                disagreement: dis,
                notes: Vec::new(),
            };
            if s.polygon.is_none() {
                missing += 1;
                s.notes.push(format!("The polygon of this feature is not in {source}."));
            } else if !skeletons_inside(&s) {
                s.notes.push(format!("The skeletons lie outside this polygon: is {source} the input of the run? (`--polygons` gives another)"));
            }
            if let Some(b) = key.0.and_then(|f| bars.get(&f)) {
                s.bars = bars_of_part(b, s.polygon.as_ref(), key.1.is_some());
            }
            s
        })
        .collect();
    if missing > 0 {
        notes.push(format!(
            "{missing} of the features shown have no polygon in {source}."
        ));
    }
    if !stored_bars {
        out.par_iter_mut().for_each(compute_bars);
    }
    Ok(out)
}

/// The members of every merged feature (`input.merge_adjacent`) by its
/// source FID, from its `members` column.
fn members(rows: &HashMap<Key, SkeletonRow>) -> HashMap<u64, Vec<u64>> {
    rows.values()
        .filter_map(|r| {
            let list = r.members.as_deref()?;
            let fids: Vec<u64> = list
                .split(',')
                .filter_map(|x| x.trim().parse().ok())
                .collect();
            Some((r.src_fid?, fids))
        })
        .collect()
}

/// The stored bars passing `filter` by source FID (none without a bars
/// layer).
fn stored_bars_of(file: &OutputFile, filter: &str) -> Result<HashMap<u64, Vec<BarRow>>, IoError> {
    let mut bars: HashMap<u64, Vec<BarRow>> = HashMap::new();
    if file.has_layer(crate::output::BARS.name) {
        for b in file.bars(Some(filter))? {
            if let Some(f) = b.src_fid {
                bars.entry(f).or_default().push(b);
            }
        }
    }
    Ok(bars)
}

/// Whether the chosen skeleton lies within the polygon's bounding box
/// (grown by 1 % of its extent).
fn skeletons_inside(s: &Section) -> bool {
    let (Some(p), Some(lines)) = (
        s.polygon.as_ref().and_then(|p| p.bounding_rect()),
        s.candidates
            .iter()
            .find(|c| c.chosen)
            .and_then(|c| c.geometry.as_ref())
            .and_then(|g| g.bounding_rect()),
    ) else {
        return true;
    };
    let tol = 0.01 * p.width().max(p.height());
    lines.min().x >= p.min().x - tol
        && lines.min().y >= p.min().y - tol
        && lines.max().x <= p.max().x + tol
        && lines.max().y <= p.max().y + tol
}

/// The stored bars of a feature that belong to this section: all, or with
/// `explode` those that start within the polygon part's bounding box.
fn bars_of_part(bars: &[BarRow], polygon: Option<&MultiPolygon<f64>>, part: bool) -> Vec<BarRow> {
    let rect = polygon.and_then(|p| p.bounding_rect());
    match (part, rect) {
        (true, Some(r)) => bars
            .iter()
            .filter(|b| {
                b.geometry.0.first().is_some_and(|o| {
                    o.x >= r.min().x && o.x <= r.max().x && o.y >= r.min().y && o.y <= r.max().y
                })
            })
            .cloned()
            .collect(),
        _ => bars.to_vec(),
    }
}

/// The bars `output.bars: true` would have written for this section's
/// skeletons: every candidate scored again through the per-feature path.
fn compute_bars(s: &mut Section) {
    let Some(polygon) = &s.polygon else { return };
    let vertices = polygon
        .0
        .iter()
        .map(|p| p.exterior().0.len() + p.interiors().iter().map(|r| r.0.len()).sum::<usize>())
        .sum::<usize>();
    if vertices > MAX_SCORED_VERTICES {
        s.notes.push(format!("No bars: the polygon has {vertices} vertices, more than the {MAX_SCORED_VERTICES} the report scores itself; `output.bars: true` writes them during the run."));
        return;
    }
    let feature = Feature::from_geometry(s.src_fid, Geometry::MultiPolygon(polygon.clone()));
    let params = ProcessParams {
        score: Some(ScoreParams::default()),
        keep_bars: true,
        ..ProcessParams::default()
    };
    let opts = RowOptions {
        bars: true,
        ..RowOptions::default()
    };
    for c in &s.candidates {
        let Some(lines) = c.geometry.as_ref().filter(|_| c.error.is_none()) else {
            continue;
        };
        let skeletons = Skeletons::Given {
            label: &c.method,
            lines: Some(lines),
        };
        s.bars
            .extend(feature_rows(&feature, skeletons, &params, opts).rows.bars);
    }
}
