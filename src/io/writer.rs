//! Writer: the output GeoPackage (SPEC §9).
//!
//! Layers: those of the run's [`Plan`] — `skeletons` (name configurable;
//! one row per feature, or per part with `explode`; with a `collapse` step
//! one per feature and value of `collapsed`), optional `candidates`, `bars`
//! and `widths`, the steps' own (`areas`, `connections`, a registered
//! step's), `rejected`, and the attribute table `skeletonise_runs` — each
//! created and filled from its description. Everything is written to a temporary
//! file beside the output, in one transaction per batch, and renamed over the
//! output only when the run succeeds: a killed run never leaves a half-written
//! output.

use super::guard::{Kind, Protected, Target};
use super::reader::{FieldInfo, SourceInfo};
use super::{signals, IoError};
use crate::feature::Value;
use crate::layer::Fields;
use crate::output::{Cell, ColumnType, GeometryKind, Layer, Plan, Rows, RunRecord, Shape};
use gdal::spatial_ref::SpatialRef;
use gdal::vector::{
    Feature, FieldDefn, FieldValue, Geometry, LayerAccess, LayerOptions, OGRFieldType,
    OGRwkbGeometryType, ToGdal,
};
use gdal::{Dataset, DriverManager};

pub use crate::config::OutputSpec;
use std::path::{Path, PathBuf};

/// An open output GeoPackage (a temporary file until [`Writer::finish`]).
pub struct Writer {
    ds: Option<Dataset>,
    tmp: PathBuf,
    path: PathBuf,
    spec: OutputSpec,
    /// The layers and columns to write.
    plan: Plan,
    source_fields: Vec<(String, FieldInfo)>,
    /// The fields of `input.neighbours` (the partitioned coverage's layer).
    neighbour_fields: Vec<(String, FieldInfo)>,
    /// Rows written in the open transaction (`None`: none open).
    in_transaction: Option<usize>,
}

/// Rows written between two commits. Commits on the writer thread overlap
/// the workers, and the last one, after the last batch, is a serial tail
/// as long as the rows since the one before. Measured on 100 000 generated
/// islands, all five methods, two threads (three pairs each, median wall
/// time): 65 536 rows per commit was 8 % slower than 4 096 (that pair
/// also had a change worth 0.3 % of instructions), 4 096 4 %
/// slower than 1 024, and 256 no faster than 1 024. The file is a
/// temporary one until the run has finished (a failed run leaves nothing).
const ROWS_PER_COMMIT: usize = 1_024;

/// Checks that `spec.path` can be written without harm ([`super::guard`]):
/// a `.gpkg` path, not an existing device, FIFO or directory, none of the
/// `protected` sources, no file in the way without `overwrite`, and a
/// directory the process may write to. Creates nothing that stays.
pub fn check_output(spec: &OutputSpec, protected: &[Protected<'_>]) -> Result<(), IoError> {
    output_target(spec, protected).check()
}

/// The output GeoPackage as a guarded target.
fn output_target<'a>(spec: &'a OutputSpec, protected: &'a [Protected<'a>]) -> Target<'a> {
    Target {
        path: Path::new(&spec.path),
        kind: Kind::GeoPackage,
        overwrite: spec.overwrite,
        protected,
    }
}

fn field(layer: &gdal::vector::Layer<'_>, name: &str, ty: u32) -> Result<(), IoError> {
    FieldDefn::new(name, ty)
        .and_then(|f| f.add_to_layer(layer))
        .map_err(|e| IoError::gdal(format!("creating field `{name}`"), e))
}

fn ogr_type(t: ColumnType) -> u32 {
    match t {
        ColumnType::Int32 => OGRFieldType::OFTInteger,
        ColumnType::Int64 => OGRFieldType::OFTInteger64,
        ColumnType::Real => OGRFieldType::OFTReal,
        ColumnType::Text => OGRFieldType::OFTString,
    }
}

fn ogr_geometry(g: GeometryKind) -> u32 {
    match g {
        GeometryKind::MultiLineString => OGRwkbGeometryType::wkbMultiLineString,
        GeometryKind::LineString => OGRwkbGeometryType::wkbLineString,
        GeometryKind::Polygon => OGRwkbGeometryType::wkbPolygon,
        GeometryKind::MultiPolygon => OGRwkbGeometryType::wkbMultiPolygon,
        GeometryKind::Point => OGRwkbGeometryType::wkbPoint,
        GeometryKind::Unknown => OGRwkbGeometryType::wkbUnknown,
        GeometryKind::None => OGRwkbGeometryType::wkbNone,
    }
}

/// A tool column's value as GDAL writes it (`None` for NULL).
fn cell_value(c: Cell, ty: ColumnType) -> Option<FieldValue> {
    match (c, ty) {
        (Cell::Null, _) => None,
        (Cell::Int(v), ColumnType::Int32) => i32::try_from(v).ok().map(FieldValue::IntegerValue),
        (Cell::Int(v), _) => Some(FieldValue::Integer64Value(v)),
        (Cell::Real(v), _) => v.is_finite().then_some(FieldValue::RealValue(v)),
        (Cell::Text(s), _) => Some(FieldValue::StringValue(s)),
    }
}

/// A source attribute as GDAL writes it.
fn attribute_value(v: &Value) -> Option<FieldValue> {
    Some(match v {
        Value::Null => return None,
        Value::Integer(i) => FieldValue::IntegerValue(*i),
        Value::Integer64(i) => FieldValue::Integer64Value(*i),
        Value::Real(r) => FieldValue::RealValue(*r),
        Value::Text(s) => FieldValue::StringValue(s.clone()),
        Value::Date(d) => FieldValue::DateValue(*d),
        Value::DateTime(d) => FieldValue::DateTimeValue(*d),
        Value::IntegerList(l) => FieldValue::IntegerListValue(l.clone()),
        Value::Integer64List(l) => FieldValue::Integer64ListValue(l.clone()),
        Value::RealList(l) => FieldValue::RealListValue(l.clone()),
        Value::TextList(l) => FieldValue::StringListValue(l.clone()),
    })
}

fn set_field(f: &mut Feature<'_>, idx: usize, v: Option<FieldValue>) -> Result<(), IoError> {
    match v {
        Some(v) => f.set_field(idx, &v),
        None => f.set_field_null(idx),
    }
    .map_err(|e| IoError::gdal(format!("setting field {idx}"), e))
}

fn shape_to_gdal(s: Shape<'_>) -> Result<Geometry, IoError> {
    match s {
        Shape::Lines(l) => to_gdal(l),
        Shape::Line(l) => to_gdal(&l),
        Shape::Polygon(p) => to_gdal(p),
        Shape::MultiPolygon(p) => to_gdal(p),
        Shape::LinesM(lines, m) => lines_m(lines, m),
        Shape::Wkb(w) => {
            Geometry::from_wkb(w).map_err(|e| IoError::gdal("reading a WKB geometry", e))
        }
        Shape::Geometry(g) => to_gdal(g),
    }
}

/// Lines with an M value per vertex as a GDAL MULTILINESTRING M.
fn lines_m(lines: &geo::MultiLineString<f64>, m: &[Vec<f64>]) -> Result<Geometry, IoError> {
    let err = |e| IoError::gdal("making a measured line", e);
    let mut multi = Geometry::empty(OGRwkbGeometryType::wkbMultiLineStringM).map_err(err)?;
    for (l, ms) in lines.0.iter().zip(m) {
        let mut g = Geometry::empty(OGRwkbGeometryType::wkbLineStringM).map_err(err)?;
        for (c, &w) in l.0.iter().zip(ms) {
            g.add_point_m((c.x, c.y, w));
        }
        multi.add_geometry(g).map_err(err)?;
    }
    Ok(multi)
}

fn to_gdal<G: ToGdal>(g: &G) -> Result<Geometry, IoError> {
    g.to_gdal()
        .map_err(|e| IoError::gdal("converting a geometry", e))
}

impl Writer {
    /// Creates the temporary GeoPackage and the layers of `plan`. Fails,
    /// touching nothing, when the output is refused by [`check_output`]
    /// (`protected`: the data sources the run reads). `neighbours`: what
    /// `input.neighbours` holds, when the run partitions.
    pub fn create(
        plan: &Plan,
        spec: &OutputSpec,
        source: &SourceInfo,
        neighbours: Option<&SourceInfo>,
        protected: &[Protected<'_>],
    ) -> Result<Self, IoError> {
        let target = output_target(spec, protected);
        target.check()?;
        let path = PathBuf::from(&spec.path);
        signals::remove_stale(&path);
        let tmp = target.temporary(std::process::id())?;
        let out_err = |e: gdal::errors::GdalError| IoError::Output {
            path: spec.path.clone(),
            reason: e.to_string(),
        };
        let driver = DriverManager::get_driver_by_name("GPKG").map_err(out_err)?;
        signals::register(&tmp);
        let mut ds = driver.create_vector_only(&tmp).map_err(out_err)?;
        let srs = source
            .srs_wkt
            .as_deref()
            .map(SpatialRef::from_wkt)
            .transpose()
            .map_err(|e| IoError::gdal("reading the CRS", e))?;
        let mut w = Writer {
            ds: None,
            tmp,
            path,
            spec: spec.clone(),
            plan: plan.clone(),
            source_fields: source_fields(source, &plan.reserved_names()),
            neighbour_fields: neighbours
                .map(|n| source_fields(n, &plan.reserved_neighbour_names()))
                .unwrap_or_default(),
            in_transaction: None,
        };
        let r = plan
            .layers()
            .into_iter()
            .try_for_each(|l| w.create_layer(&mut ds, l, srs.as_ref()));
        w.ds = Some(ds);
        if let Err(e) = r {
            w.abort();
            return Err(e);
        }
        Ok(w)
    }

    /// Creates `layer` (under the plan's name for it).
    fn create_layer(
        &self,
        ds: &mut Dataset,
        layer: &dyn Layer,
        srs: Option<&SpatialRef>,
    ) -> Result<(), IoError> {
        let name = self.plan.name_of(layer);
        // `output.measures: width`: the skeleton layer's lines carry M.
        let ty = if self.plan.measured(layer) {
            OGRwkbGeometryType::wkbMultiLineStringM
        } else {
            ogr_geometry(layer.geometry())
        };
        // The spatial index is made now, while the layer is empty, so every
        // batch's rows enter it as they are written (on the writer thread,
        // alongside the workers) rather than all at once when the file is
        // closed (GDAL's deferred index: a serial tail after the last batch,
        // 0.8 s for 100 000 skeletons).
        let spatial = layer.geometry() != GeometryKind::None;
        let l = ds
            .create_layer(LayerOptions {
                name,
                srs: if spatial { srs } else { None },
                ty,
                options: spatial.then_some(&["SPATIAL_INDEX=NO"][..]),
            })
            .map_err(|e| IoError::gdal(format!("creating layer `{name}`"), e))?;
        for (fname, f) in self.fields_of(layer) {
            let d =
                FieldDefn::new(fname, f.kind).map_err(|e| IoError::gdal("copying a field", e))?;
            d.set_width(f.width);
            d.set_precision(f.precision);
            d.add_to_layer(&l)
                .map_err(|e| IoError::gdal(format!("copying field `{fname}`"), e))?;
        }
        for (_, cname, ty) in self.plan.columns(layer) {
            field(&l, cname, ogr_type(ty))?;
        }
        if spatial {
            let column = l
                .defn()
                .geom_fields()
                .next()
                .map_or_else(|| "geom".to_string(), |g| g.name());
            let quote = |s: &str| s.replace('\'', "''");
            let sql = format!(
                "SELECT CreateSpatialIndex('{}', '{}')",
                quote(name),
                quote(&column)
            );
            ds.execute_sql(&sql, None, gdal::vector::sql::Dialect::DEFAULT)
                .map_err(|e| IoError::gdal(format!("indexing layer `{name}`"), e))?;
        }
        Ok(())
    }

    /// The source fields `layer` carries first.
    fn fields_of(&self, layer: &dyn Layer) -> &[(String, FieldInfo)] {
        match layer.fields() {
            None => &[],
            Some(Fields::Input) => &self.source_fields,
            Some(Fields::Neighbours) => &self.neighbour_fields,
        }
    }

    /// Writes the rows of `layer` in `rows`.
    fn write_rows(&self, ds: &Dataset, layer: &dyn Layer, rows: &Rows) -> Result<(), IoError> {
        let n = layer.count(rows);
        if n == 0 {
            return Ok(());
        }
        let name = self.plan.name_of(layer);
        let l = ds
            .layer_by_name(name)
            .map_err(|e| IoError::gdal(format!("opening layer `{name}`"), e))?;
        let n_source = self.fields_of(layer).len();
        let columns = self.plan.columns(layer);
        for i in 0..n {
            let mut f =
                Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
            if let Some(s) = layer.shape(rows, i) {
                f.set_geometry(shape_to_gdal(s)?)
                    .map_err(|e| IoError::gdal("setting a geometry", e))?;
            }
            for (k, v) in layer.attributes(rows, i).iter().enumerate().take(n_source) {
                set_field(&mut f, k, attribute_value(v))?;
            }
            for (k, &(c, _, ty)) in columns.iter().enumerate() {
                set_field(&mut f, n_source + k, cell_value(layer.cell(rows, i, c), ty))?;
            }
            f.create(&l)
                .map_err(|e| IoError::gdal(format!("writing a row of `{name}`"), e))?;
        }
        Ok(())
    }

    /// Writes one batch of rows, in the transaction open since the last
    /// commit (one commit every `ROWS_PER_COMMIT` rows and at the end).
    pub fn write_batch(&mut self, rows: &Rows) -> Result<(), IoError> {
        let ds = self.ds.take().expect("open until finish/abort");
        let r = (|| {
            let written = match self.in_transaction {
                Some(n) => n,
                None => {
                    transaction(&ds, "starting a transaction", |h| unsafe {
                        gdal_sys::GDALDatasetStartTransaction(h, 0)
                    })?;
                    0
                }
            };
            self.in_transaction = Some(written);
            for layer in self.plan.layers() {
                self.write_rows(&ds, layer, rows)?;
            }
            let written = written + rows.len();
            self.in_transaction = Some(written);
            if written >= ROWS_PER_COMMIT {
                self.commit(&ds)?;
            }
            Ok(())
        })();
        self.ds = Some(ds);
        r
    }

    /// Commits the open transaction, if any.
    fn commit(&mut self, ds: &Dataset) -> Result<(), IoError> {
        if self.in_transaction.take().is_some() {
            transaction(ds, "committing the rows written", |h| unsafe {
                gdal_sys::GDALDatasetCommitTransaction(h)
            })?;
        }
        Ok(())
    }

    /// Writes the run record, closes the file and renames it over the output.
    /// On any failure (a full disk at the last commit, a rename refused) the
    /// temporary file is removed and the previous output, if any, stays.
    pub fn finish(mut self, run: &RunRecord) -> Result<PathBuf, IoError> {
        let ds = self.ds.take().expect("open until finish/abort");
        let r = self.close(ds, run);
        if r.is_err() {
            signals::remove_with_companions(&self.tmp);
        }
        signals::unregister(&self.tmp);
        r
    }

    /// The last commit, the run record, closing and the rename.
    fn close(&mut self, ds: Dataset, run: &RunRecord) -> Result<PathBuf, IoError> {
        self.commit(&ds)?;
        let record = Rows {
            runs: vec![run.clone()],
            ..Rows::default()
        };
        for layer in self.plan.layers() {
            self.write_rows(&ds, layer, &record)?;
        }
        // Closing flushes the file before it is renamed into place.
        close_dataset(ds).map_err(|reason| IoError::Output {
            path: self.spec.path.clone(),
            reason: super::with_full_disk_hint(format!(
                "closing the finished file failed: {reason}"
            )),
        })?;
        if self.path.exists() && !self.spec.overwrite {
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

    /// Discards the temporary file (and what SQLite kept beside it).
    pub fn abort(&mut self) {
        drop(self.ds.take());
        signals::remove_with_companions(&self.tmp);
        signals::unregister(&self.tmp);
    }
}

/// The source's fields as the output names them: those whose names clash
/// with `reserved` (the tool's columns of the layers that carry them, see
/// [`Plan::reserved_names`]) get a `src_` prefix — in every layer alike —
/// repeated until the name is free (`src_fid` beside a source field
/// `src_src_fid`, as in a previous run's output, becomes `src_src_src_fid`).
/// SQLite compares column names without case.
fn source_fields(source: &SourceInfo, reserved: &[&str]) -> Vec<(String, FieldInfo)> {
    let names: Vec<&str> = source.fields.iter().map(|f| f.name.as_str()).collect();
    crate::output::source_names(&names, reserved)
        .into_iter()
        .zip(source.fields.iter().cloned())
        .collect()
}

/// Closes a dataset, with GDAL's reason when closing fails (the last
/// write of a file on a full disk fails here).
fn close_dataset(ds: Dataset) -> Result<(), String> {
    super::gdal_errors::clear();
    ds.close().map_err(|e| e.to_string())?;
    match super::gdal_errors::take_failures().first() {
        Some(m) => Err(m.clone()),
        None => Ok(()),
    }
}

/// Starts or commits a transaction on `ds` by `call` (a GDAL dataset
/// transaction function), with GDAL's reason when it fails.
fn transaction(
    ds: &Dataset,
    context: &str,
    call: impl FnOnce(gdal_sys::GDALDatasetH) -> gdal_sys::OGRErr::Type,
) -> Result<(), IoError> {
    match call(ds.c_dataset()) {
        gdal_sys::OGRErr::OGRERR_NONE => Ok(()),
        code => Err(IoError::gdal(context, format!("OGR error {code}"))),
    }
}

impl Drop for Writer {
    fn drop(&mut self) {
        if self.ds.is_some() {
            self.abort();
        }
    }
}
