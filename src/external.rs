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
use crate::geometry::PreparedPolygon;
use crate::io::guard::Protected;
use crate::io::reader::Reader;
use crate::pipeline::{run_job, Given, Job, RunError, RunOptions, RunSummary};
use crate::process::{polygon_parts, PrepareParams, ProcessParams};
use crate::score::ScoreParams;
use geo::{BoundingRect, LineString, MultiLineString};
use rstar::{primitives::GeomWithData, primitives::Rectangle, RTree, AABB};
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

use crate::connect::lines_of;

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
    unjoined.report(
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

/// Skeleton rows that were joined to no polygon, by why.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Unjoined {
    /// Rows whose key is NULL.
    pub null_key: usize,
    /// Rows whose key no polygon has, with the first such key.
    pub unknown_key: (usize, Option<String>),
    /// Rows without a geometry, or whose geometry has no line (points,
    /// polygons).
    pub not_lines: usize,
    /// Lines (joined by location) that lie in no polygon.
    pub outside: usize,
}

impl Unjoined {
    /// Logs what was left out; with nothing joined at all, the error
    /// saying why.
    fn report(&self, source: &str, any_joined: bool) -> Result<(), RunError> {
        let mut why = Vec::new();
        if self.null_key > 0 {
            why.push(format!("{} with a NULL key", self.null_key));
        }
        if let (n, Some(k)) = &self.unknown_key {
            why.push(format!("{n} with a key no polygon has (e.g. `{k}`)"));
        }
        if self.not_lines > 0 {
            why.push(format!(
                "{} without a line geometry (points, polygons or NULL)",
                self.not_lines
            ));
        }
        if self.outside > 0 {
            why.push(format!("{} lines inside no polygon", self.outside));
        }
        if !any_joined {
            return Err(RunError::Io(crate::io::IoError::Read {
                source_name: source.to_string(),
                reason: format!(
                    "no skeleton line could be joined to a polygon ({}); check `--skeleton-key`/`--polygon-key` (or, joining by location, that the lines lie in the polygons) and that both layers are the ones meant",
                    if why.is_empty() { "the layer has no rows".to_string() } else { why.join(", ") }
                ),
            }));
        }
        if !why.is_empty() {
            tracing::warn!(
                null_key = self.null_key,
                unknown_key = self.unknown_key.0,
                not_lines = self.not_lines,
                outside = self.outside,
                "skeleton rows joined to no polygon and left out: {}",
                why.join(", ")
            );
        }
        Ok(())
    }
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
    let mut assigned = vec![Vec::new(); polygons.len()];
    let pf = polygon_field
        .as_deref()
        .map(|n| field_index(pr, n, "polygon"))
        .transpose()?;
    let sf = field_index(sr, skeleton_field, "skeleton")?;
    let by_key: HashMap<String, usize> = polygons
        .iter()
        .enumerate()
        .filter_map(|(i, f)| key_text(f, pf).map(|k| (k, i)))
        .collect();
    for s in skeletons {
        let ls = feature_lines(s);
        if ls.is_empty() {
            unjoined.not_lines += 1;
            continue;
        }
        let Some(k) = key_text(s, Some(sf)) else {
            unjoined.null_key += 1;
            continue;
        };
        match by_key.get(&k) {
            Some(&i) => assigned[i].extend(ls),
            None => {
                unjoined.unknown_key.0 += 1;
                unjoined.unknown_key.1.get_or_insert(k);
            }
        }
    }
    Ok(assigned)
}

/// The lines of a skeleton feature (none when it has no line geometry).
fn feature_lines(s: &Feature) -> Vec<LineString<f64>> {
    let mut ls = Vec::new();
    if let Some(g) = &s.geometry {
        lines_of(g, &mut ls);
    }
    ls
}

fn join_by_location(
    polygons: &[Feature],
    skeletons: &[Feature],
    unjoined: &mut Unjoined,
) -> Vec<Vec<LineString<f64>>> {
    let mut assigned = vec![Vec::new(); polygons.len()];
    let prepared: Vec<Vec<PreparedPolygon>> = polygons
        .iter()
        .map(|f| {
            polygon_parts(f.geometry.as_ref())
                .map(|ps| {
                    ps.iter()
                        .filter_map(|p| PreparedPolygon::new(p).ok())
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let boxes: Vec<GeomWithData<Rectangle<[f64; 2]>, usize>> = polygons
        .iter()
        .enumerate()
        .filter_map(|(i, f)| {
            let r = f.geometry.as_ref()?.bounding_rect()?;
            Some(GeomWithData::new(
                Rectangle::from_corners([r.min().x, r.min().y], [r.max().x, r.max().y]),
                i,
            ))
        })
        .collect();
    let tree = RTree::bulk_load(boxes);
    for s in skeletons {
        let ls = feature_lines(s);
        if ls.is_empty() {
            unjoined.not_lines += 1;
        }
        for l in ls {
            let Some(w) = l.0.windows(2).find(|w| w[0] != w[1]) else {
                continue;
            };
            let m = (w[0] + w[1]) * 0.5;
            let hit = tree
                .locate_in_envelope_intersecting(&AABB::from_point([m.x, m.y]))
                .map(|c| c.data)
                .filter(|&i| {
                    prepared[i]
                        .iter()
                        .any(|p| p.boundary().contains_with_tolerance(m, 1e-9 * p.extent()))
                })
                .min();
            match hit {
                Some(i) => assigned[i].push(l),
                None => unjoined.outside += 1,
            }
        }
    }
    assigned
}
