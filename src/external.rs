//! Scoring skeletons made by other tools (GRASS `v.voronoi -s`, PostGIS
//! `ST_ApproximateMedialAxis`, `pygeoops.centerline`, …) with the same
//! metrics: `skeletonise score --polygons SRC --skeletons SRC -o OUT.gpkg`.
//!
//! Skeleton features are joined to polygons either by key (a skeleton field
//! whose value equals the polygon's FID or a polygon field) or by location
//! (the polygon that contains a skeleton feature's first segment midpoint).
//! Every polygon gets one row in the output's skeleton layer with the merged
//! linework and its scores; polygons without a skeleton are listed in
//! `rejected`. The scoring itself is the pipeline's own
//! ([`crate::pipeline::run_job`] with [`crate::pipeline::Given`] skeletons).

use crate::config::{InputSpec, OnError, OutputSpec};
use crate::feature::Feature;
use crate::io::guard::Protected;
use crate::io::reader::Reader;
use crate::pipeline::{run_job, Given, Job, RunError, RunOptions, RunSummary};
use crate::process::{PrepareParams, ProcessParams};
use crate::score::{join, ScoreParams};
use geo::{LineString, MultiLineString};
use std::collections::HashMap;

/// How skeleton features find their polygon.
#[derive(Debug, Clone, PartialEq)]
pub enum Join {
    /// Skeleton field `skeleton_field` equals the polygon's `polygon_field`
    /// (`None` = the polygon's FID).
    Key {
        /// Field of the polygon layer; `None` for the FID.
        polygon_field: Option<String>,
        /// Field of the skeleton layer.
        skeleton_field: String,
    },
    /// The polygon containing the midpoint of the skeleton's first segment.
    Location,
}

/// What to score and where to write it.
#[derive(Debug, Clone, PartialEq)]
pub struct ScoreJob {
    /// The polygons.
    pub polygons: InputSpec,
    /// The skeletons (lines).
    pub skeletons: InputSpec,
    /// How to join them.
    pub join: Join,
    /// Label written to the `method` attribute (e.g. the other tool's name).
    pub label: String,
    /// The output.
    pub output: OutputSpec,
}

fn key_text(f: &Feature, field: Option<usize>) -> Option<String> {
    match field {
        None => f.fid.map(|x| x.to_string()),
        Some(i) => f.attributes.get(i).and_then(|a| a.as_text()),
    }
}

fn field_index(r: &Reader, name: &str, what: &str) -> Result<usize, RunError> {
    r.info()
        .fields
        .iter()
        .position(|f| f.name == name)
        .ok_or_else(|| {
            RunError::Io(crate::io::IoError::Gdal {
                context: format!("{what} layer `{}`", r.info().layer),
                reason: format!(
                    "has no field `{name}`; fields: {}",
                    r.info()
                        .fields
                        .iter()
                        .map(|f| f.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })
        })
}

fn read_all(r: &mut Reader) -> Result<Vec<Feature>, RunError> {
    let mut v = Vec::new();
    r.read::<RunError>(4096, false, |b| {
        v.extend(b);
        Ok(())
    })?;
    Ok(v)
}

/// Scores the skeletons of `job` and writes the output GeoPackage: the
/// skeleton lines are joined to their polygons, then the polygons go
/// through the same run as a pipeline's, with the joined lines in place of
/// the methods' skeletons.
pub fn score_external(job: &ScoreJob, keep_bars: bool) -> Result<RunSummary, RunError> {
    // Before reading anything: the output must not be one of the inputs.
    crate::io::writer::check_output(
        &job.output,
        &[
            Protected::new("the polygons source", &job.polygons.source),
            Protected::new("the skeletons source", &job.skeletons.source),
        ],
    )?;
    let (lines, unjoined) = join(job)?;
    report(
        &unjoined,
        &job.skeletons.source,
        lines.values().any(|l| !l.0.is_empty()),
    )?;
    let given = Given {
        label: job.label.clone(),
        lines,
    };
    let output = OutputSpec {
        bars: keep_bars,
        ..job.output.clone()
    };
    let params = ProcessParams {
        prepare: PrepareParams {
            make_valid: false,
            ..PrepareParams::default()
        },
        score: Some(ScoreParams::default()),
        keep_bars,
        ..ProcessParams::default()
    };
    let run = Job {
        name: format!("score {}", job.label),
        provenance: format!(
            "score --polygons {} --skeletons {} --join {:?}",
            job.polygons.source, job.skeletons.source, job.join
        ),
        input: &job.polygons,
        output: &output,
        params,
        on_error: OnError::Reject,
        given: Some(&given),
        other_inputs: vec![("the skeletons source", job.skeletons.source.clone())],
        plan: crate::config::plan_of(&output, Some(&job.polygons), &[]),
    };
    run_job(&run, &RunOptions::default())
}

pub use crate::score::join::Unjoined;

/// Logs what was left out of the join; with nothing joined at all, the
/// error saying why.
fn report(unjoined: &Unjoined, source: &str, any_joined: bool) -> Result<(), RunError> {
    if !any_joined {
        return Err(RunError::Io(crate::io::IoError::Read {
            source_name: source.to_string(),
            reason: unjoined.nothing_joined("`--skeleton-key`/`--polygon-key`"),
        }));
    }
    let why = unjoined.reasons();
    if !why.is_empty() {
        tracing::warn!(
            null_key = unjoined.null_key,
            unknown_key = unjoined.unknown_key.0,
            not_lines = unjoined.not_lines,
            outside = unjoined.outside,
            "skeleton rows joined to no polygon and left out: {}",
            why.join(", ")
        );
    }
    Ok(())
}

/// The skeleton lines of `job`, by the FID of the polygon they are joined
/// to, and the rows that joined none.
fn join(job: &ScoreJob) -> Result<(HashMap<u64, MultiLineString<f64>>, Unjoined), RunError> {
    let mut pr = Reader::open(&job.polygons).map_err(for_score)?;
    let mut sr = Reader::open(&job.skeletons).map_err(for_score)?;
    if crate::io::reader::same_crs(pr.info(), sr.info()) == Some(false) {
        return Err(RunError::Io(crate::io::IoError::Gdal {
            context: format!(
                "the skeletons `{}` (CRS {}) and the polygons `{}` (CRS {})",
                job.skeletons.source,
                sr.info().crs_name,
                job.polygons.source,
                pr.info().crs_name
            ),
            reason: "are in different CRSs, so no skeleton would meet its polygon; reproject one of them to the other's CRS first (e.g. with ogr2ogr -t_srs), or give both `--reproject EPSG:<code>`".into(),
        }));
    }
    let polygons = read_all(&mut pr)?;
    let skeletons = read_all(&mut sr)?;
    let mut unjoined = Unjoined::default();
    let assigned = match &job.join {
        Join::Key {
            polygon_field,
            skeleton_field,
        } => join_by_key(
            (&pr, &sr),
            (&polygons, &skeletons),
            polygon_field,
            skeleton_field,
            &mut unjoined,
        )?,
        Join::Location => join_by_location(&polygons, &skeletons, &mut unjoined),
    };
    let lines = polygons
        .iter()
        .zip(assigned)
        .filter_map(|(f, lines)| Some((f.fid?, MultiLineString(lines))))
        .collect();
    Ok((lines, unjoined))
}

/// A reader's error with `score`'s own words: a geographic CRS is
/// reprojected with `--reproject`.
fn for_score(e: crate::io::IoError) -> RunError {
    match e {
        crate::io::IoError::Geographic { layer, crs, .. } => {
            RunError::Io(crate::io::IoError::Geographic {
                layer,
                crs,
                fix: "give `--reproject EPSG:<code>` (e.g. the layers' UTM zone)",
            })
        }
        e => RunError::Io(e),
    }
}

fn join_by_key(
    (pr, sr): (&Reader, &Reader),
    (polygons, skeletons): (&[Feature], &[Feature]),
    polygon_field: &Option<String>,
    skeleton_field: &str,
    unjoined: &mut Unjoined,
) -> Result<Vec<Vec<LineString<f64>>>, RunError> {
    let pf = polygon_field
        .as_deref()
        .map(|n| field_index(pr, n, "polygon"))
        .transpose()?;
    let sf = field_index(sr, skeleton_field, "skeleton")?;
    let keys: Vec<Option<String>> = polygons.iter().map(|f| key_text(f, pf)).collect();
    Ok(join::by_key(
        &keys,
        skeletons
            .iter()
            .map(|s| (key_text(s, Some(sf)), join::lines_of(s.geometry.as_ref()))),
        unjoined,
    ))
}

fn join_by_location(
    polygons: &[Feature],
    skeletons: &[Feature],
    unjoined: &mut Unjoined,
) -> Vec<Vec<LineString<f64>>> {
    let geoms: Vec<_> = polygons.iter().map(|f| f.geometry.as_ref()).collect();
    join::by_location(
        &geoms,
        skeletons
            .iter()
            .map(|s| join::lines_of(s.geometry.as_ref())),
        unjoined,
    )
}
