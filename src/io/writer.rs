//! Writer: the output GeoPackage (SPEC §9).
//!
//! Layers: `skeletons` (name configurable; one row per feature, or per part
//! with `explode`), optional `candidates` and `bars`, `rejected`, and the
//! attribute table `skeletonise_runs`. Everything is written to a temporary
//! file beside the output, in one transaction per batch, and renamed over the
//! output only when the run succeeds: a killed run never leaves a half-written
//! output.

use super::reader::{AttributeValue, FieldInfo, SourceInfo};
use super::IoError;
use gdal::spatial_ref::SpatialRef;
use gdal::vector::{
    Feature, FieldDefn, FieldValue, Geometry, LayerAccess, LayerOptions, OGRFieldType,
    OGRwkbGeometryType, ToGdal,
};
use gdal::{Dataset, DriverManager};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

fn default_layer() -> String {
    "skeletons".into()
}

/// The `output` section of a pipeline file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Path of the GeoPackage to write.
    pub path: String,
    /// Name of the skeleton layer.
    #[serde(default = "default_layer")]
    pub layer: String,
    /// Replace an existing output file.
    #[serde(default)]
    pub overwrite: bool,
    /// Also write every method's skeleton and scores (layer `candidates`).
    #[serde(default)]
    pub candidates: bool,
    /// Also write the scoring bars (layer `bars`).
    #[serde(default)]
    pub bars: bool,
    /// One row per polygon part instead of per feature.
    #[serde(default)]
    pub explode: bool,
    /// Also write the chosen skeleton segment by segment with the local width
    /// of the polygon (2 × disc radius) at both ends (layer `widths`): the
    /// medial axis transform, for deciding what is narrow enough to collapse.
    #[serde(default)]
    pub widths: bool,
}

/// The metric columns of `skeletons` and `candidates`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScoreColumns {
    /// N.
    pub bars: i64,
    /// n.
    pub hits: i64,
    /// n / N.
    pub coverage: f64,
    /// s.
    pub deviation: f64,
    /// S.
    pub deviation_parts: f64,
    /// SZ.
    pub distortion_sum: f64,
    /// Z.
    pub distortion: f64,
}

/// One row of the `skeletons` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct SkeletonRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Polygon part index (with `explode`).
    pub part: Option<usize>,
    /// Source attributes.
    pub attributes: Vec<AttributeValue>,
    /// The skeleton.
    pub geometry: geo::MultiLineString<f64>,
    /// Chosen method id.
    pub method: String,
    /// Scores of the chosen method, when scored.
    pub scores: Option<ScoreColumns>,
    /// Connected components of the skeleton.
    pub components: i64,
    /// Legs after pruning and extension.
    pub legs: i64,
    /// MakeValid changed the input.
    pub repaired: bool,
}

/// One row of the `candidates` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Polygon part index (with `explode`).
    pub part: Option<usize>,
    /// Method id.
    pub method: String,
    /// The skeleton, or `None` when the method failed.
    pub geometry: Option<geo::MultiLineString<f64>>,
    /// Scores, when scored.
    pub scores: Option<ScoreColumns>,
    /// Whether this candidate was chosen.
    pub chosen: bool,
    /// Components, raw legs, final legs.
    pub components: i64,
    /// Legs before pruning.
    pub legs_raw: i64,
    /// Legs after pruning and extension.
    pub legs: i64,
    /// Why the method failed.
    pub error: Option<String>,
}

/// One row of the `bars` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct BarRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Method id.
    pub method: String,
    /// From origin to hit (or to the origin alone for a miss).
    pub geometry: geo::LineString<f64>,
    /// d_L, d_P, Δd, z — `None` for a miss.
    pub d_left: Option<f64>,
    /// d_P.
    pub d_right: Option<f64>,
    /// Δd.
    pub delta_d: Option<f64>,
    /// z.
    pub z: Option<f64>,
    /// Part index.
    pub part: Option<i64>,
}

/// One row of the `widths` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct WidthRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Method id.
    pub method: String,
    /// The segment.
    pub geometry: geo::Line<f64>,
    /// Width (2 r) at the start.
    pub width_start: f64,
    /// Width (2 r) at the end.
    pub width_end: f64,
}

/// One row of the `rejected` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct RejectedRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Why the feature was not processed.
    pub reason: String,
    /// The input geometry as WKB, when there was one.
    pub wkb: Option<Vec<u8>>,
}

/// The `skeletonise_runs` row.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Pipeline name.
    pub name: String,
    /// Start, UTC, RFC 3339.
    pub started_utc: String,
    /// End, UTC, RFC 3339.
    pub finished_utc: String,
    /// Tool version.
    pub tool_version: String,
    /// The pipeline text (with overrides).
    pub pipeline: String,
    /// Input source and layer.
    pub input: String,
    /// Features read.
    pub read: u64,
    /// Rows written to the skeleton layer.
    pub written: u64,
    /// Features rejected.
    pub rejected: u64,
    /// Features filtered by where/bbox/min_area.
    pub filtered: u64,
    /// Wall time.
    pub elapsed_s: f64,
    /// Worker threads.
    pub threads: i64,
}

/// Field names the tool adds to the skeleton layer.
pub const SKELETON_FIELDS: [&str; 13] = [
    "src_fid",
    "part",
    "method",
    "bars",
    "hits",
    "coverage",
    "deviation",
    "deviation_parts",
    "distortion_sum",
    "distortion",
    "components",
    "legs",
    "repaired",
];

/// An open output GeoPackage (a temporary file until [`Writer::finish`]).
pub struct Writer {
    ds: Option<Dataset>,
    tmp: PathBuf,
    path: PathBuf,
    spec: OutputSpec,
    source_fields: Vec<(String, FieldInfo)>,
}

/// Checks that `spec.path` can be written (parent exists, no file in the way
/// without `overwrite`) without creating anything.
pub fn check_output(spec: &OutputSpec) -> Result<(), IoError> {
    let path = Path::new(&spec.path);
    if path.exists() && !spec.overwrite {
        return Err(IoError::OutputExists {
            path: spec.path.clone(),
        });
    }
    if path.is_dir() {
        return Err(IoError::Output {
            path: spec.path.clone(),
            reason: "it is a directory; give a file name ending in .gpkg".into(),
        });
    }
    let parent = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !parent.is_dir() {
        return Err(IoError::Output {
            path: spec.path.clone(),
            reason: format!(
                "directory `{}` does not exist; create it first",
                parent.display()
            ),
        });
    }
    Ok(())
}

fn field(layer: &gdal::vector::Layer<'_>, name: &str, ty: u32) -> Result<(), IoError> {
    FieldDefn::new(name, ty)
        .and_then(|f| f.add_to_layer(layer))
        .map_err(|e| IoError::gdal(format!("creating field `{name}`"), e))
}

fn set(f: &mut Feature<'_>, name: &str, v: Option<FieldValue>) -> Result<(), IoError> {
    let idx = f
        .field_index(name)
        .map_err(|e| IoError::gdal(format!("field `{name}`"), e))?;
    match v {
        Some(v) => f.set_field(idx, &v),
        None => f.set_field_null(idx),
    }
    .map_err(|e| IoError::gdal(format!("setting field `{name}`"), e))
}

/// A 32-bit integer field value (counts, flags, part indices).
fn small(v: i64) -> Option<FieldValue> {
    i32::try_from(v).ok().map(FieldValue::IntegerValue)
}

fn int(v: i64) -> Option<FieldValue> {
    Some(FieldValue::Integer64Value(v))
}

fn real(v: f64) -> Option<FieldValue> {
    v.is_finite().then_some(FieldValue::RealValue(v))
}

fn text(v: &str) -> Option<FieldValue> {
    Some(FieldValue::StringValue(v.to_string()))
}

fn fid(v: Option<u64>) -> Option<FieldValue> {
    v.map(|x| FieldValue::Integer64Value(x as i64))
}

fn add_score_fields(layer: &gdal::vector::Layer<'_>) -> Result<(), IoError> {
    field(layer, "bars", OGRFieldType::OFTInteger64)?;
    field(layer, "hits", OGRFieldType::OFTInteger64)?;
    for n in [
        "coverage",
        "deviation",
        "deviation_parts",
        "distortion_sum",
        "distortion",
    ] {
        field(layer, n, OGRFieldType::OFTReal)?;
    }
    Ok(())
}

fn set_scores(f: &mut Feature<'_>, s: Option<&ScoreColumns>) -> Result<(), IoError> {
    let s = s.copied();
    set(f, "bars", s.map(|s| FieldValue::Integer64Value(s.bars)))?;
    set(f, "hits", s.map(|s| FieldValue::Integer64Value(s.hits)))?;
    set(f, "coverage", s.and_then(|s| real(s.coverage)))?;
    set(f, "deviation", s.and_then(|s| real(s.deviation)))?;
    set(
        f,
        "deviation_parts",
        s.and_then(|s| real(s.deviation_parts)),
    )?;
    set(f, "distortion_sum", s.and_then(|s| real(s.distortion_sum)))?;
    set(f, "distortion", s.and_then(|s| real(s.distortion)))
}

fn to_gdal<G: ToGdal>(g: &G) -> Result<Geometry, IoError> {
    g.to_gdal()
        .map_err(|e| IoError::gdal("converting a geometry", e))
}

impl Writer {
    /// Creates the temporary GeoPackage and its layers. Fails, touching
    /// nothing, when the output exists without `overwrite` or cannot be written.
    pub fn create(spec: &OutputSpec, source: &SourceInfo) -> Result<Self, IoError> {
        check_output(spec)?;
        let path = PathBuf::from(&spec.path);
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_else(|| "out.gpkg".into());
        let tmp = path.with_file_name(format!(".{name}.{}.tmp.gpkg", std::process::id()));
        let out_err = |e: gdal::errors::GdalError| IoError::Output {
            path: spec.path.clone(),
            reason: e.to_string(),
        };
        let driver = DriverManager::get_driver_by_name("GPKG").map_err(out_err)?;
        let _ = std::fs::remove_file(&tmp);
        let mut ds = driver.create_vector_only(&tmp).map_err(out_err)?;
        let srs = source
            .srs_wkt
            .as_deref()
            .map(SpatialRef::from_wkt)
            .transpose()
            .map_err(|e| IoError::gdal("reading the CRS", e))?;
        // Source fields whose names clash with the tool's get a `src_` prefix.
        let source_fields: Vec<(String, FieldInfo)> = source
            .fields
            .iter()
            .map(|f| {
                let clash = SKELETON_FIELDS
                    .iter()
                    .any(|n| n.eq_ignore_ascii_case(&f.name));
                (
                    if clash {
                        format!("src_{}", f.name)
                    } else {
                        f.name.clone()
                    },
                    f.clone(),
                )
            })
            .collect();
        let mut w = Writer {
            ds: None,
            tmp,
            path,
            spec: spec.clone(),
            source_fields,
        };
        let r = (|| -> Result<(), IoError> {
            fn opts<'a>(name: &'a str, srs: Option<&'a SpatialRef>, ty: u32) -> LayerOptions<'a> {
                LayerOptions {
                    name,
                    srs,
                    ty,
                    options: None,
                }
            }
            let srs = srs.as_ref();
            {
                let l = ds
                    .create_layer(opts(
                        &spec.layer,
                        srs,
                        OGRwkbGeometryType::wkbMultiLineString,
                    ))
                    .map_err(|e| IoError::gdal(format!("creating layer `{}`", spec.layer), e))?;
                for (name, f) in &w.source_fields {
                    let d = FieldDefn::new(name, f.kind)
                        .map_err(|e| IoError::gdal("copying a field", e))?;
                    d.set_width(f.width);
                    d.set_precision(f.precision);
                    d.add_to_layer(&l)
                        .map_err(|e| IoError::gdal(format!("copying field `{name}`"), e))?;
                }
                field(&l, "src_fid", OGRFieldType::OFTInteger64)?;
                if spec.explode {
                    field(&l, "part", OGRFieldType::OFTInteger)?;
                }
                field(&l, "method", OGRFieldType::OFTString)?;
                add_score_fields(&l)?;
                field(&l, "components", OGRFieldType::OFTInteger)?;
                field(&l, "legs", OGRFieldType::OFTInteger)?;
                field(&l, "repaired", OGRFieldType::OFTInteger)?;
            }
            if spec.candidates {
                let l = ds
                    .create_layer(opts(
                        "candidates",
                        srs,
                        OGRwkbGeometryType::wkbMultiLineString,
                    ))
                    .map_err(|e| IoError::gdal("creating layer `candidates`", e))?;
                field(&l, "src_fid", OGRFieldType::OFTInteger64)?;
                field(&l, "part", OGRFieldType::OFTInteger)?;
                field(&l, "method", OGRFieldType::OFTString)?;
                field(&l, "chosen", OGRFieldType::OFTInteger)?;
                add_score_fields(&l)?;
                field(&l, "components", OGRFieldType::OFTInteger)?;
                field(&l, "legs_raw", OGRFieldType::OFTInteger)?;
                field(&l, "legs", OGRFieldType::OFTInteger)?;
                field(&l, "error", OGRFieldType::OFTString)?;
            }
            if spec.bars {
                let l = ds
                    .create_layer(opts("bars", srs, OGRwkbGeometryType::wkbLineString))
                    .map_err(|e| IoError::gdal("creating layer `bars`", e))?;
                field(&l, "src_fid", OGRFieldType::OFTInteger64)?;
                field(&l, "method", OGRFieldType::OFTString)?;
                for n in ["d_left", "d_right", "delta_d", "z"] {
                    field(&l, n, OGRFieldType::OFTReal)?;
                }
                field(&l, "part", OGRFieldType::OFTInteger64)?;
            }
            if spec.widths {
                let l = ds
                    .create_layer(opts("widths", srs, OGRwkbGeometryType::wkbLineString))
                    .map_err(|e| IoError::gdal("creating layer `widths`", e))?;
                field(&l, "src_fid", OGRFieldType::OFTInteger64)?;
                field(&l, "method", OGRFieldType::OFTString)?;
                for n in ["width_start", "width_end", "width"] {
                    field(&l, n, OGRFieldType::OFTReal)?;
                }
            }
            {
                let l = ds
                    .create_layer(opts("rejected", srs, OGRwkbGeometryType::wkbUnknown))
                    .map_err(|e| IoError::gdal("creating layer `rejected`", e))?;
                field(&l, "src_fid", OGRFieldType::OFTInteger64)?;
                field(&l, "reason", OGRFieldType::OFTString)?;
            }
            {
                let l = ds
                    .create_layer(LayerOptions {
                        name: "skeletonise_runs",
                        srs: None,
                        ty: OGRwkbGeometryType::wkbNone,
                        options: None,
                    })
                    .map_err(|e| IoError::gdal("creating table `skeletonise_runs`", e))?;
                for n in [
                    "name",
                    "started_utc",
                    "finished_utc",
                    "tool_version",
                    "pipeline",
                    "input",
                ] {
                    field(&l, n, OGRFieldType::OFTString)?;
                }
                for n in [
                    "features_read",
                    "features_written",
                    "features_rejected",
                    "features_filtered",
                    "threads",
                ] {
                    field(&l, n, OGRFieldType::OFTInteger64)?;
                }
                field(&l, "elapsed_s", OGRFieldType::OFTReal)?;
            }
            Ok(())
        })();
        w.ds = Some(ds);
        if let Err(e) = r {
            w.abort();
            return Err(e);
        }
        Ok(w)
    }

    fn ds(&mut self) -> &mut Dataset {
        self.ds.as_mut().expect("open until finish/abort")
    }

    /// Writes one batch of rows in one transaction.
    pub fn write_batch(
        &mut self,
        skeletons: &[SkeletonRow],
        candidates: &[CandidateRow],
        bars: &[BarRow],
        widths: &[WidthRow],
        rejected: &[RejectedRow],
    ) -> Result<(), IoError> {
        let layer_name = self.spec.layer.clone();
        let explode = self.spec.explode;
        let source_fields = self.source_fields.clone();
        let txn = self
            .ds()
            .start_transaction()
            .map_err(|e| IoError::gdal("starting a transaction", e))?;
        {
            let l = txn
                .layer_by_name(&layer_name)
                .map_err(|e| IoError::gdal("opening the skeleton layer", e))?;
            for r in skeletons {
                let mut f =
                    Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
                f.set_geometry(to_gdal(&r.geometry)?)
                    .map_err(|e| IoError::gdal("setting a geometry", e))?;
                for ((name, _), v) in source_fields.iter().zip(&r.attributes) {
                    set(&mut f, name, v.0.clone())?;
                }
                set(&mut f, "src_fid", fid(r.src_fid))?;
                if explode {
                    set(&mut f, "part", r.part.and_then(|p| small(p as i64)))?;
                }
                set(&mut f, "method", text(&r.method))?;
                set_scores(&mut f, r.scores.as_ref())?;
                set(&mut f, "components", small(r.components))?;
                set(&mut f, "legs", small(r.legs))?;
                set(&mut f, "repaired", small(r.repaired as i64))?;
                f.create(&l)
                    .map_err(|e| IoError::gdal("writing a skeleton", e))?;
            }
        }
        if !candidates.is_empty() {
            let l = txn
                .layer_by_name("candidates")
                .map_err(|e| IoError::gdal("opening `candidates`", e))?;
            for r in candidates {
                let mut f =
                    Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
                if let Some(g) = &r.geometry {
                    f.set_geometry(to_gdal(g)?)
                        .map_err(|e| IoError::gdal("setting a geometry", e))?;
                }
                set(&mut f, "src_fid", fid(r.src_fid))?;
                set(&mut f, "part", r.part.and_then(|p| small(p as i64)))?;
                set(&mut f, "method", text(&r.method))?;
                set(&mut f, "chosen", small(r.chosen as i64))?;
                set_scores(&mut f, r.scores.as_ref())?;
                set(&mut f, "components", small(r.components))?;
                set(&mut f, "legs_raw", small(r.legs_raw))?;
                set(&mut f, "legs", small(r.legs))?;
                set(&mut f, "error", r.error.as_deref().and_then(text))?;
                f.create(&l)
                    .map_err(|e| IoError::gdal("writing a candidate", e))?;
            }
        }
        if !bars.is_empty() {
            let l = txn
                .layer_by_name("bars")
                .map_err(|e| IoError::gdal("opening `bars`", e))?;
            for r in bars {
                let mut f =
                    Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
                f.set_geometry(to_gdal(&r.geometry)?)
                    .map_err(|e| IoError::gdal("setting a geometry", e))?;
                set(&mut f, "src_fid", fid(r.src_fid))?;
                set(&mut f, "method", text(&r.method))?;
                set(&mut f, "d_left", r.d_left.and_then(real))?;
                set(&mut f, "d_right", r.d_right.and_then(real))?;
                set(&mut f, "delta_d", r.delta_d.and_then(real))?;
                set(&mut f, "z", r.z.and_then(real))?;
                set(&mut f, "part", r.part.and_then(int))?;
                f.create(&l)
                    .map_err(|e| IoError::gdal("writing a bar", e))?;
            }
        }
        if !widths.is_empty() {
            let l = txn
                .layer_by_name("widths")
                .map_err(|e| IoError::gdal("opening `widths`", e))?;
            for r in widths {
                let mut f =
                    Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
                f.set_geometry(to_gdal(&geo::LineString(vec![
                    r.geometry.start,
                    r.geometry.end,
                ]))?)
                .map_err(|e| IoError::gdal("setting a geometry", e))?;
                set(&mut f, "src_fid", fid(r.src_fid))?;
                set(&mut f, "method", text(&r.method))?;
                set(&mut f, "width_start", real(r.width_start))?;
                set(&mut f, "width_end", real(r.width_end))?;
                set(&mut f, "width", real((r.width_start + r.width_end) / 2.0))?;
                f.create(&l)
                    .map_err(|e| IoError::gdal("writing a width", e))?;
            }
        }
        if !rejected.is_empty() {
            let l = txn
                .layer_by_name("rejected")
                .map_err(|e| IoError::gdal("opening `rejected`", e))?;
            for r in rejected {
                let mut f =
                    Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
                if let Some(g) = r.wkb.as_deref().and_then(|w| Geometry::from_wkb(w).ok()) {
                    f.set_geometry(g)
                        .map_err(|e| IoError::gdal("setting a geometry", e))?;
                }
                set(&mut f, "src_fid", fid(r.src_fid))?;
                set(&mut f, "reason", text(&r.reason))?;
                f.create(&l)
                    .map_err(|e| IoError::gdal("writing a rejected feature", e))?;
            }
        }
        txn.commit()
            .map_err(|e| IoError::gdal("committing a batch", e))
    }

    /// Writes the run record, closes the file and renames it over the output.
    pub fn finish(mut self, run: &RunRecord) -> Result<PathBuf, IoError> {
        {
            let ds = self.ds();
            let l = ds
                .layer_by_name("skeletonise_runs")
                .map_err(|e| IoError::gdal("opening `skeletonise_runs`", e))?;
            let mut f =
                Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
            set(&mut f, "name", text(&run.name))?;
            set(&mut f, "started_utc", text(&run.started_utc))?;
            set(&mut f, "finished_utc", text(&run.finished_utc))?;
            set(&mut f, "tool_version", text(&run.tool_version))?;
            set(&mut f, "pipeline", text(&run.pipeline))?;
            set(&mut f, "input", text(&run.input))?;
            set(&mut f, "features_read", int(run.read as i64))?;
            set(&mut f, "features_written", int(run.written as i64))?;
            set(&mut f, "features_rejected", int(run.rejected as i64))?;
            set(&mut f, "features_filtered", int(run.filtered as i64))?;
            set(&mut f, "threads", int(run.threads))?;
            set(&mut f, "elapsed_s", real(run.elapsed_s))?;
            f.create(&l)
                .map_err(|e| IoError::gdal("writing the run record", e))?;
        }
        // Closing flushes the file before it is renamed into place.
        drop(self.ds.take());
        if self.path.exists() && !self.spec.overwrite {
            let _ = std::fs::remove_file(&self.tmp);
            return Err(IoError::OutputExists {
                path: self.spec.path.clone(),
            });
        }
        std::fs::rename(&self.tmp, &self.path).map_err(|e| IoError::Output {
            path: self.spec.path.clone(),
            reason: format!("renaming the finished file into place failed: {e}"),
        })?;
        Ok(self.path.clone())
    }

    /// Discards the temporary file.
    pub fn abort(&mut self) {
        drop(self.ds.take());
        let _ = std::fs::remove_file(&self.tmp);
    }
}

impl Drop for Writer {
    fn drop(&mut self) {
        if self.ds.is_some() {
            self.abort();
        }
    }
}
