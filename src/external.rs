//! Scoring skeletons made by other tools (GRASS `v.voronoi -s`, PostGIS
//! `ST_ApproximateMedialAxis`, `pygeoops.centerline`, …) with the same
//! metrics: `skeletonise score --polygons SRC --skeletons SRC -o OUT.gpkg`.
//!
//! Skeleton features are joined to polygons either by key (a skeleton field
//! whose value equals the polygon's FID or a polygon field) or by location
//! (the polygon that contains a skeleton feature's first segment midpoint).
//! Every polygon gets one row in the output's skeleton layer with the merged
//! linework and its scores; polygons without a skeleton are listed in
//! `rejected`.

use crate::geometry::PreparedPolygon;
use crate::io::reader::{InputFeature, InputSpec, Reader};
use crate::io::writer::{BarRow, OutputSpec, RejectedRow, RunRecord, SkeletonRow, Writer};
use crate::pipeline::{columns, RunError, RunSummary};
use crate::process::polygon_parts;
use crate::score::{metrics, score_skeleton};
use geo::{BoundingRect, Coord, Geometry, LineString, MultiLineString};
use rayon::prelude::*;
use rstar::{primitives::GeomWithData, primitives::Rectangle, RTree, AABB};
use std::collections::HashMap;
use std::time::Instant;

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

fn lines_of(g: &Geometry<f64>, out: &mut Vec<LineString<f64>>) {
    match g {
        Geometry::LineString(l) => out.push(l.clone()),
        Geometry::MultiLineString(m) => out.extend(m.0.iter().cloned()),
        Geometry::Line(l) => out.push(LineString(vec![l.start, l.end])),
        Geometry::GeometryCollection(c) => c.iter().for_each(|g| lines_of(g, out)),
        _ => {}
    }
}

fn key_text(f: &InputFeature, field: Option<usize>) -> Option<String> {
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

fn read_all(r: &mut Reader) -> Result<Vec<InputFeature>, RunError> {
    let mut v = Vec::new();
    r.read::<RunError>(4096, false, |b| {
        v.extend(b);
        Ok(())
    })?;
    Ok(v)
}

/// Scores the skeletons of `job` and writes the output GeoPackage.
pub fn score_external(job: &ScoreJob, keep_bars: bool) -> Result<RunSummary, RunError> {
    let started = chrono::Utc::now();
    let clock = Instant::now();
    let mut pr = Reader::open(&job.polygons)?;
    let mut sr = Reader::open(&job.skeletons)?;
    let info = pr.info().clone();
    let mut writer = Writer::create(&job.output, &info)?;
    let polygons = read_all(&mut pr)?;
    let skeletons = read_all(&mut sr)?;
    // Lines per polygon index.
    let mut assigned: Vec<Vec<LineString<f64>>> = vec![Vec::new(); polygons.len()];
    match &job.join {
        Join::Key {
            polygon_field,
            skeleton_field,
        } => {
            let pf = polygon_field
                .as_deref()
                .map(|n| field_index(&pr, n, "polygon"))
                .transpose()?;
            let sf = field_index(&sr, skeleton_field, "skeleton")?;
            let by_key: HashMap<String, usize> = polygons
                .iter()
                .enumerate()
                .filter_map(|(i, f)| key_text(f, pf).map(|k| (k, i)))
                .collect();
            for s in &skeletons {
                if let (Some(k), Some(g)) = (key_text(s, Some(sf)), &s.geometry) {
                    if let Some(&i) = by_key.get(&k) {
                        lines_of(g, &mut assigned[i]);
                    }
                }
            }
        }
        Join::Location => {
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
            for s in &skeletons {
                let Some(g) = &s.geometry else { continue };
                let mut ls = Vec::new();
                lines_of(g, &mut ls);
                for l in ls {
                    let Some(w) = l.0.windows(2).find(|w| w[0] != w[1]) else {
                        continue;
                    };
                    let m = Coord {
                        x: (w[0].x + w[1].x) / 2.0,
                        y: (w[0].y + w[1].y) / 2.0,
                    };
                    let hit = tree
                        .locate_in_envelope_intersecting(&AABB::from_point([m.x, m.y]))
                        .map(|c| c.data)
                        .filter(|&i| {
                            prepared[i]
                                .iter()
                                .any(|p| p.boundary().contains_with_tolerance(m, 1e-9 * p.extent()))
                        })
                        .min();
                    if let Some(i) = hit {
                        assigned[i].push(l);
                    }
                }
            }
        }
    }
    let results: Vec<Result<(SkeletonRow, Vec<BarRow>), String>> = polygons
        .par_iter()
        .zip(assigned.into_par_iter())
        .map(|(f, lines)| {
            if let Some(e) = &f.geometry_error {
                return Err(e.clone());
            }
            let parts = polygon_parts(f.geometry.as_ref())?;
            if lines.is_empty() {
                return Err(format!(
                    "no skeleton joined to this polygon (join: {:?})",
                    job.join
                ));
            }
            let ml = MultiLineString(lines);
            let mut all = Vec::new();
            let mut offset = 0;
            for p in &parts {
                let pp = PreparedPolygon::new(p).map_err(|e| e.to_string())?;
                let (_, mut b) = score_skeleton(&pp, &ml);
                let max_part = b
                    .iter()
                    .filter_map(|b| b.hit.map(|h| h.part))
                    .max()
                    .map_or(0, |m| m + 1);
                for bar in &mut b {
                    if let Some(h) = &mut bar.hit {
                        h.part += offset;
                    }
                }
                offset += max_part;
                all.extend(b);
            }
            let s = metrics(&all);
            let bars = if keep_bars {
                all.iter()
                    .map(|b| BarRow {
                        src_fid: f.fid,
                        method: job.label.clone(),
                        geometry: LineString(vec![
                            b.origin,
                            b.hit.map(|h| h.point).unwrap_or(b.origin),
                        ]),
                        d_left: b.hit.map(|h| h.d_left),
                        d_right: b.hit.map(|h| h.d_right),
                        delta_d: b.hit.map(|h| h.delta_d()),
                        z: b.hit.map(|h| h.z()),
                        part: b.hit.map(|h| h.part as i64),
                    })
                    .collect()
            } else {
                Vec::new()
            };
            Ok((
                SkeletonRow {
                    src_fid: f.fid,
                    part: None,
                    attributes: f.attributes.clone(),
                    geometry: ml,
                    method: job.label.clone(),
                    scores: Some(columns(&s)),
                    components: 0,
                    legs: 0,
                    repaired: false,
                },
                bars,
            ))
        })
        .collect();
    let mut rows = Vec::new();
    let mut bars = Vec::new();
    let mut rejected = Vec::new();
    for (f, r) in polygons.iter().zip(results) {
        match r {
            Ok((row, b)) => {
                rows.push(row);
                bars.extend(b);
            }
            Err(reason) => rejected.push(RejectedRow {
                src_fid: f.fid,
                reason,
                wkb: f.source_wkb.clone(),
            }),
        }
    }
    writer.write_batch(&rows, &[], &bars, &[], &rejected)?;
    let elapsed_s = clock.elapsed().as_secs_f64();
    let record = RunRecord {
        name: format!("score {}", job.label),
        started_utc: started.to_rfc3339(),
        finished_utc: chrono::Utc::now().to_rfc3339(),
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        pipeline: format!(
            "score --polygons {} --skeletons {} --join {:?}",
            job.polygons.source, job.skeletons.source, job.join
        ),
        input: format!("{} (layer {})", info.source, info.layer),
        read: polygons.len() as u64,
        written: rows.len() as u64,
        rejected: rejected.len() as u64,
        filtered: info.total.saturating_sub(info.selected),
        elapsed_s,
        threads: rayon::current_num_threads() as i64,
    };
    let out = writer.finish(&record)?;
    Ok(RunSummary {
        read: polygons.len() as u64,
        written: rows.len() as u64,
        rows: rows.len() as u64,
        rejected: rejected.len() as u64,
        filtered: record.filtered,
        elapsed_s,
        output: out.display().to_string(),
        methods: vec![(job.label.clone(), rows.len() as u64)],
    })
}
