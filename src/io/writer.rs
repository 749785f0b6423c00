//! Writer: the output GeoPackage (SPEC §9).
//!
//! Layers: `skeletons` (name configurable; one row per feature, or per part
//! with `explode`; with a `collapse` step one per feature and value of
//! `collapsed`), optional `candidates`, `bars` and `widths`, `areas` with a
//! `collapse` step, `rejected`,
//! and the attribute table `skeletonise_runs` — each created and filled from
//! its description in [`crate::output`]. Everything is written to a temporary
//! file beside the output, in one transaction per batch, and renamed over the
//! output only when the run succeeds: a killed run never leaves a half-written
//! output.

use super::guard::{Kind, Protected, Target};
use super::reader::{FieldInfo, SourceInfo};
use super::{signals, IoError};
use crate::feature::Value;
use crate::output::{
    Cell, Column, ColumnType, GeometryKind, LayerDef, Rows, RunRecord, Shape, When, AREAS, BARS,
    CANDIDATES, CONNECTIONS, REJECTED, RUNS, SKELETONS, WIDTHS,
};
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
    /// The pipeline collapses: the `areas` layer and the `collapsed` column.
    collapse: bool,
    /// `input.merge_adjacent`: the `members` column.
    merge: bool,
    source_fields: Vec<(String, FieldInfo)>,
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
        Shape::LinesM(lines, m) => lines_m(lines, m),
        Shape::Wkb(w) => {
            Geometry::from_wkb(w).map_err(|e| IoError::gdal("reading a WKB geometry", e))
        }
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
    /// Creates the temporary GeoPackage and its layers. Fails, touching
    /// nothing, when the output is refused by [`check_output`] (`protected`:
    /// the data sources the run reads). `collapse`: the pipeline has a
    /// `collapse` step (the `areas` layer, the `collapsed` column); `merge`:
    /// the input merges adjacent polygons (the `members` column); `connect`:
    /// the input has a line network (the `connections` layer).
    pub fn create(
        spec: &OutputSpec,
        source: &SourceInfo,
        protected: &[Protected<'_>],
        collapse: bool,
        merge: bool,
        connect: bool,
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
        // Source fields whose names clash with the tool's get a `src_` prefix.
        let source_fields: Vec<(String, FieldInfo)> = source
            .fields
            .iter()
            .map(|f| {
                let clash = SKELETONS
                    .column_names()
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
            collapse,
            merge,
            source_fields,
            in_transaction: None,
        };
        let r = (|| -> Result<(), IoError> {
            let srs = srs.as_ref();
            w.create_layer(&mut ds, &SKELETONS, &spec.layer, srs)?;
            if spec.candidates {
                w.create_layer(&mut ds, &CANDIDATES, CANDIDATES.name, srs)?;
            }
            if spec.bars {
                w.create_layer(&mut ds, &BARS, BARS.name, srs)?;
            }
            if spec.widths {
                w.create_layer(&mut ds, &WIDTHS, WIDTHS.name, srs)?;
            }
            if collapse {
                w.create_layer(&mut ds, &AREAS, AREAS.name, srs)?;
            }
            if connect {
                w.create_layer(&mut ds, &CONNECTIONS, CONNECTIONS.name, srs)?;
            }
            w.create_layer(&mut ds, &REJECTED, REJECTED.name, srs)?;
            w.create_layer(&mut ds, &RUNS, RUNS.name, None)?;
            Ok(())
        })();
        w.ds = Some(ds);
        if let Err(e) = r {
            w.abort();
            return Err(e);
        }
        Ok(w)
    }

    /// Creates the layer `name` described by `def`.
    fn create_layer<R>(
        &self,
        ds: &mut Dataset,
        def: &LayerDef<R>,
        name: &str,
        srs: Option<&SpatialRef>,
    ) -> Result<(), IoError> {
        // `output.measures: width`: the skeleton layer's lines carry M.
        let measured = name == self.spec.layer
            && def.geometry == GeometryKind::MultiLineString
            && self.spec.measures == crate::config::Measures::Width;
        let ty = if measured {
            OGRwkbGeometryType::wkbMultiLineStringM
        } else {
            ogr_geometry(def.geometry)
        };
        // The spatial index is made now, while the layer is empty, so every
        // batch's rows enter it as they are written (on the writer thread,
        // alongside the workers) rather than all at once when the file is
        // closed (GDAL's deferred index: a serial tail after the last batch,
        // 0.8 s for 100 000 skeletons).
        let spatial = def.geometry != GeometryKind::None;
        let l = ds
            .create_layer(LayerOptions {
                name,
                srs,
                ty,
                options: spatial.then_some(&["SPATIAL_INDEX=NO"][..]),
            })
            .map_err(|e| IoError::gdal(format!("creating layer `{name}`"), e))?;
        if def.attributes.is_some() {
            for (fname, f) in &self.source_fields {
                let d = FieldDefn::new(fname, f.kind)
                    .map_err(|e| IoError::gdal("copying a field", e))?;
                d.set_width(f.width);
                d.set_precision(f.precision);
                d.add_to_layer(&l)
                    .map_err(|e| IoError::gdal(format!("copying field `{fname}`"), e))?;
            }
        }
        for c in self.columns(def) {
            field(&l, c.name, ogr_type(c.ty))?;
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

    /// The columns of `def` this output has.
    fn columns<'d, R>(&self, def: &'d LayerDef<R>) -> impl Iterator<Item = &'d Column<R>> {
        let (explode, collapse, merge) = (self.spec.explode, self.collapse, self.merge);
        def.columns.iter().filter(move |c| match c.when {
            When::Always => true,
            When::Explode => explode,
            When::Collapse => collapse,
            When::Merge => merge,
        })
    }

    /// Writes `rows` to the layer `name` described by `def`.
    fn write_rows<R>(
        &self,
        ds: &Dataset,
        def: &LayerDef<R>,
        name: &str,
        rows: &[R],
    ) -> Result<(), IoError> {
        if rows.is_empty() {
            return Ok(());
        }
        let l = ds
            .layer_by_name(name)
            .map_err(|e| IoError::gdal(format!("opening layer `{name}`"), e))?;
        let n_source = if def.attributes.is_some() {
            self.source_fields.len()
        } else {
            0
        };
        let columns: Vec<&Column<R>> = self.columns(def).collect();
        for r in rows {
            let mut f =
                Feature::new(l.defn()).map_err(|e| IoError::gdal("creating a feature", e))?;
            if let Some(s) = (def.shape)(r) {
                f.set_geometry(shape_to_gdal(s)?)
                    .map_err(|e| IoError::gdal("setting a geometry", e))?;
            }
            if let Some(attrs) = def.attributes {
                for (i, v) in attrs(r).iter().enumerate().take(n_source) {
                    set_field(&mut f, i, attribute_value(v))?;
                }
            }
            for (k, c) in columns.iter().enumerate() {
                set_field(&mut f, n_source + k, cell_value((c.get)(r), c.ty))?;
            }
            f.create(&l)
                .map_err(|e| IoError::gdal(format!("writing a row of `{name}`"), e))?;
        }
        Ok(())
    }

    /// Writes one batch of rows, in the transaction open since the last
    /// commit (one commit every [`ROWS_PER_COMMIT`] rows and at the end).
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
            self.write_rows(&ds, &SKELETONS, &self.spec.layer, &rows.skeletons)?;
            self.write_rows(&ds, &CANDIDATES, CANDIDATES.name, &rows.candidates)?;
            self.write_rows(&ds, &BARS, BARS.name, &rows.bars)?;
            self.write_rows(&ds, &WIDTHS, WIDTHS.name, &rows.widths)?;
            self.write_rows(&ds, &AREAS, AREAS.name, &rows.areas)?;
            self.write_rows(&ds, &CONNECTIONS, CONNECTIONS.name, &rows.connections)?;
            self.write_rows(&ds, &REJECTED, REJECTED.name, &rows.rejected)?;
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
        self.write_rows(&ds, &RUNS, RUNS.name, std::slice::from_ref(run))?;
        // Closing flushes the file before it is renamed into place.
        close_dataset(ds).map_err(|reason| IoError::Output {
            path: self.spec.path.clone(),
            reason: format!("closing the finished file failed: {reason}"),
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
