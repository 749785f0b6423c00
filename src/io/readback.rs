//! Reading an output GeoPackage back — the run record, the candidates, the
//! skeleton rows and the bars — as the row types of [`crate::output`], so
//! that the report works on the same data the writer wrote.

use super::reader::value;
use super::IoError;
use crate::feature::Value;
use crate::output::{
    name, BarRow, CandidateRow, RunRecord, SkeletonRow, BARS, CANDIDATES, RUNS, SKELETONS,
};
use crate::score::Scores;
use gdal::vector::{Feature, LayerAccess};
use gdal::{Dataset, DatasetOptions, GdalOpenFlags};
use std::collections::HashMap;
use std::path::Path;

/// An output GeoPackage opened for reading.
pub struct OutputFile {
    ds: Dataset,
    path: String,
    run: Option<RunRecord>,
    skeleton_layer: String,
}

/// The column indices of one layer, by name.
struct Fields(HashMap<String, usize>);

impl Fields {
    fn of(layer: &gdal::vector::Layer<'_>) -> Self {
        Self(
            layer
                .defn()
                .fields()
                .enumerate()
                .map(|(i, f)| (f.name(), i))
                .collect(),
        )
    }

    fn int(&self, f: &Feature<'_>, name: &str) -> Option<i64> {
        let i = *self.0.get(name)?;
        f.field_as_integer64(i).ok().flatten()
    }

    fn real(&self, f: &Feature<'_>, name: &str) -> Option<f64> {
        let i = *self.0.get(name)?;
        f.field_as_double(i).ok().flatten()
    }

    fn text(&self, f: &Feature<'_>, name: &str) -> Option<String> {
        let i = *self.0.get(name)?;
        f.field_as_string(i).ok().flatten()
    }

    fn count(&self, f: &Feature<'_>, name: &str) -> usize {
        self.int(f, name)
            .and_then(|v| usize::try_from(v).ok())
            .unwrap_or(0)
    }

    fn fid(&self, f: &Feature<'_>) -> Option<u64> {
        self.int(f, name::SRC_FID)
            .and_then(|v| u64::try_from(v).ok())
    }

    fn polygon_part(&self, f: &Feature<'_>) -> Option<usize> {
        self.int(f, name::POLYGON_PART)
            .and_then(|v| usize::try_from(v).ok())
    }

    /// The paper's scores of a row; `None` when the run did not score.
    fn scores(&self, f: &Feature<'_>) -> Option<Scores> {
        let bars = usize::try_from(self.int(f, name::BARS)?).ok()?;
        let r = |n: &str| self.real(f, n).unwrap_or(f64::NAN);
        Some(Scores {
            bars,
            hits: self.count(f, name::HITS),
            coverage: self.real(f, name::COVERAGE).unwrap_or(0.0),
            deviation: r(name::DEVIATION),
            deviation_parts: r(name::DEVIATION_PARTS),
            distortion_sum: r(name::DISTORTION_SUM),
            distortion: r(name::DISTORTION),
        })
    }
}

fn lines(f: &Feature<'_>) -> Option<geo::MultiLineString<f64>> {
    // A NULL geometry (a candidate with no lines) reads as a geometry
    // without a handle: no lines, not a clone of nothing.
    // SAFETY: the handle is only compared with null, not dereferenced.
    let g = f
        .geometry()
        .filter(|g| !unsafe { g.c_geometry() }.is_null())?
        .clone();
    // M values (`output.measures`) are not part of the lines read back.
    // SAFETY: the handle is the clone's own, valid while `g` lives.
    unsafe { gdal_sys::OGR_G_SetMeasured(g.c_geometry(), 0) };
    match g.to_geo().ok()? {
        geo::Geometry::MultiLineString(m) => Some(m),
        geo::Geometry::LineString(l) => Some(geo::MultiLineString(vec![l])),
        _ => None,
    }
}

/// A `collapse` run writes a feature's skeleton in two rows (collapsed
/// lines and the centreline through the kept areas), one after the other:
/// one row again with all its lines, as a run without collapse writes it.
fn whole_skeletons(rows: Vec<SkeletonRow>) -> Vec<SkeletonRow> {
    let mut out: Vec<SkeletonRow> = Vec::with_capacity(rows.len());
    for r in rows {
        match out.last_mut() {
            Some(prev)
                if prev.collapsed.is_some()
                    && r.collapsed.is_some()
                    && prev.src_fid == r.src_fid
                    && prev.polygon_part == r.polygon_part =>
            {
                prev.geometry.0.extend(r.geometry.0);
                prev.collapsed = None;
            }
            _ => out.push(r),
        }
    }
    out
}

impl OutputFile {
    /// Opens a GeoPackage written by `skeletonise run` or `score`.
    pub fn open(path: &Path) -> Result<Self, IoError> {
        let shown = path.display().to_string();
        let ds = Dataset::open_ex(
            path,
            DatasetOptions {
                open_flags: GdalOpenFlags::GDAL_OF_VECTOR | GdalOpenFlags::GDAL_OF_READONLY,
                ..Default::default()
            },
        )
        .map_err(|e| IoError::NotAnOutput {
            path: shown.clone(),
            reason: if path.exists() {
                e.to_string()
            } else {
                "the file does not exist".into()
            },
        })?;
        let mut file = Self {
            ds,
            path: shown,
            run: None,
            skeleton_layer: SKELETONS.name.to_string(),
        };
        file.run = file.read_run()?;
        if let Some(l) = file.run.as_ref().map(|r| r.skeleton_layer.clone()) {
            if !l.is_empty() {
                file.skeleton_layer = l;
            }
        }
        if !file.has_layer(&file.skeleton_layer) {
            return Err(IoError::NotAnOutput {
                path: file.path.clone(),
                reason: format!(
                    "it has no skeleton layer `{}` (its layers: {})",
                    file.skeleton_layer,
                    file.layer_names().join(", ")
                ),
            });
        }
        Ok(file)
    }

    fn layer_names(&self) -> Vec<String> {
        self.ds.layers().map(|l| l.name()).collect()
    }

    /// Whether the file has the layer `name`.
    pub fn has_layer(&self, name: &str) -> bool {
        self.layer_names().iter().any(|n| n == name)
    }

    /// The file's path.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The record of the run that wrote the file (the last one).
    pub fn run(&self) -> Option<&RunRecord> {
        self.run.as_ref()
    }

    /// The name of the skeleton layer.
    pub fn skeleton_layer(&self) -> &str {
        &self.skeleton_layer
    }

    /// The short name of the skeletons' CRS unit (`m` for metres), or `""`.
    pub fn units(&self) -> String {
        let srs = self
            .ds
            .layer_by_name(&self.skeleton_layer)
            .ok()
            .and_then(|l| l.spatial_ref());
        match srs.and_then(|s| s.linear_units_name()).as_deref() {
            Some("metre" | "meter" | "Meter" | "Metre") => "m".into(),
            Some(other) => other.to_string(),
            None => String::new(),
        }
    }

    /// Every row of layer `name` that passes `filter` (OGR SQL), in file
    /// order, made by `row`.
    fn rows<R>(
        &self,
        name: &str,
        filter: Option<&str>,
        mut row: impl FnMut(&Fields, &Feature<'_>) -> R,
    ) -> Result<Vec<R>, IoError> {
        let mut layer = self
            .ds
            .layer_by_name(name)
            .map_err(|e| IoError::gdal(format!("opening layer `{name}` of `{}`", self.path), e))?;
        if let Some(w) = filter {
            super::set_filter(&mut layer, w).map_err(|reason| IoError::BadFilter {
                path: self.path.clone(),
                layer: name.to_string(),
                filter: w.to_string(),
                reason,
            })?;
        }
        let fields = Fields::of(&layer);
        super::gdal_errors::clear();
        let rows = layer.features().map(|f| row(&fields, &f)).collect();
        // A filter that fails only on some rows (an integer overflow,
        // malformed JSON) ends the loop early with GDAL's report: an error,
        // not fewer rows.
        let failures = super::gdal_errors::take_failures();
        if failures.is_empty() {
            return Ok(rows);
        }
        let reason = failures.join("; ");
        Err(match filter {
            Some(w) => IoError::BadFilter {
                path: self.path.clone(),
                layer: name.to_string(),
                filter: w.to_string(),
                reason,
            },
            None => IoError::NotAnOutput {
                path: self.path.clone(),
                reason: format!("reading layer `{name}` failed: {reason}"),
            },
        })
    }

    fn read_run(&self) -> Result<Option<RunRecord>, IoError> {
        if !self.has_layer(RUNS.name) {
            return Ok(None);
        }
        let runs = self.rows(RUNS.name, None, |c, f| {
            let t = |n: &str| c.text(f, n).unwrap_or_default();
            let n = |n: &str| c.int(f, n).and_then(|v| u64::try_from(v).ok()).unwrap_or(0);
            RunRecord {
                name: t(name::run::NAME),
                started_utc: t(name::run::STARTED_UTC),
                finished_utc: t(name::run::FINISHED_UTC),
                tool_version: t(name::run::TOOL_VERSION),
                pipeline: t(name::run::PIPELINE),
                input: t(name::run::INPUT),
                input_source: t(name::run::INPUT_SOURCE),
                input_layer: t(name::run::INPUT_LAYER),
                input_reproject: c.text(f, name::run::INPUT_REPROJECT),
                skeleton_layer: t(name::run::SKELETON_LAYER),
                read: n(name::run::FEATURES_READ),
                written: n(name::run::FEATURES_WRITTEN),
                rejected: n(name::run::FEATURES_REJECTED),
                filtered: n(name::run::FEATURES_FILTERED),
                elapsed_s: c.real(f, name::run::ELAPSED_S).unwrap_or(f64::NAN),
                threads: c.count(f, name::run::THREADS),
                stage_seconds: t(name::run::STAGE_SECONDS),
                area_held: c.real(f, name::run::AREA_HELD),
            }
        })?;
        Ok(runs.into_iter().last())
    }

    /// The rows of `candidates` that pass `filter`, with their skeletons
    /// when `geometry`.
    pub fn candidates(
        &self,
        filter: Option<&str>,
        geometry: bool,
    ) -> Result<Vec<CandidateRow>, IoError> {
        self.rows(CANDIDATES.name, filter, |c, f| CandidateRow {
            src_fid: c.fid(f),
            polygon_part: c.polygon_part(f),
            method: c.text(f, name::METHOD).unwrap_or_default(),
            geometry: if geometry { lines(f) } else { None },
            scores: c.scores(f),
            chosen: c.int(f, name::CHOSEN) == Some(1),
            components: c.count(f, name::COMPONENTS),
            legs_raw: c.count(f, name::LEGS_RAW),
            legs: c.count(f, name::LEGS),
            error: c.text(f, name::ERROR),
        })
    }

    /// The source fields of the skeleton layer (its columns that are not the
    /// tool's), in order.
    pub fn source_fields(&self) -> Result<Vec<String>, IoError> {
        let layer = self
            .ds
            .layer_by_name(&self.skeleton_layer)
            .map_err(|e| IoError::gdal("opening the skeleton layer", e))?;
        let tool: Vec<&str> = SKELETONS.column_names().collect();
        Ok(layer
            .defn()
            .fields()
            .map(|f| f.name())
            .filter(|n| !tool.contains(&n.as_str()))
            .collect())
    }

    /// The rows of the skeleton layer that pass `filter` (OGR SQL on its
    /// columns), with the source fields as attributes and the skeletons when
    /// `geometry`.
    pub fn skeletons(
        &self,
        filter: Option<&str>,
        geometry: bool,
    ) -> Result<Vec<SkeletonRow>, IoError> {
        let source = self.source_fields()?;
        let rows = self.rows(&self.skeleton_layer, filter, |c, f| SkeletonRow {
            src_fid: c.fid(f),
            polygon_part: c.polygon_part(f),
            attributes: source
                .iter()
                .map(|n| {
                    c.0.get(n)
                        .map_or(Value::Null, |&i| value(f.field(i).ok().flatten()))
                })
                .collect(),
            geometry: geometry
                .then(|| lines(f))
                .flatten()
                .unwrap_or_else(|| geo::MultiLineString(Vec::new())),
            method: c.text(f, name::METHOD).unwrap_or_default(),
            scores: c.scores(f),
            components: c.count(f, name::COMPONENTS),
            legs: c.count(f, name::LEGS),
            repaired: c.int(f, name::REPAIRED) == Some(1),
            note: c.text(f, name::NOTE),
            collapsed: c.int(f, name::COLLAPSED).map(|v| v == 1),
            members: c.text(f, name::MEMBERS),
            measures: None,
        })?;
        Ok(whole_skeletons(rows))
    }

    /// The rows of `bars` that pass `filter`.
    pub fn bars(&self, filter: Option<&str>) -> Result<Vec<BarRow>, IoError> {
        self.rows(BARS.name, filter, |c, f| BarRow {
            src_fid: c.fid(f),
            method: c.text(f, name::METHOD).unwrap_or_default(),
            geometry: lines(f)
                .and_then(|m| m.0.into_iter().next())
                .unwrap_or_else(|| geo::LineString(Vec::new())),
            d_left: c.real(f, name::D_LEFT),
            d_right: c.real(f, name::D_RIGHT),
            delta_d: c.real(f, name::DELTA_D),
            z: c.real(f, name::Z),
            branch: c.int(f, name::BRANCH).and_then(|v| usize::try_from(v).ok()),
        })
    }
}
