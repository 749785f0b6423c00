//! Reader: any OGR data source (file, folder, `PG:` connection, `/vsizip/…`)
//! → owned [`Feature`]s with `geo` geometries.
//!
//! Z and M are dropped, curves linearised, geometries reprojected when asked
//! and, with `make_valid`, repaired by GDAL's MakeValid (keeping only the
//! areal parts of the result). Features come in batches to a callback so the
//! GDAL dataset and layer stay on the reader's thread.

use super::IoError;
use gdal::cpl::CslStringList;
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use gdal::vector::{FieldValue, Geometry, LayerAccess};
use gdal::{Dataset, DatasetOptions, GdalOpenFlags};

pub use crate::config::{InputSpec, LayerRef};
use crate::feature::{Feature, Value};

/// A source field definition.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldInfo {
    /// Field name.
    pub name: String,
    /// OGR field type code.
    pub(crate) kind: u32,
    /// Declared width (0 = unknown).
    pub width: i32,
    /// Declared precision.
    pub precision: i32,
}

/// What the reader found out about the source before reading.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceInfo {
    /// The data source string.
    pub source: String,
    /// Name of the layer read.
    pub layer: String,
    /// Source fields, in order.
    pub fields: Vec<FieldInfo>,
    /// WKT of the CRS of the geometries handed out (after reprojection).
    pub srs_wkt: Option<String>,
    /// Human-readable name of that CRS.
    pub crs_name: String,
    /// Features in the layer without filters (`None`: the driver cannot tell).
    pub total: Option<u64>,
    /// Features that pass `where` and `bbox` (`None`: the driver cannot tell).
    pub selected: Option<u64>,
}

/// An open input layer.
pub struct Reader {
    dataset: Dataset,
    layer_index: usize,
    spec: InputSpec,
    info: SourceInfo,
    target: Option<SpatialRef>,
}

/// `AUTH:CODE` of a CRS, else its name.
fn crs_name(s: &SpatialRef) -> String {
    match (s.auth_name(), s.auth_code().ok()) {
        (Some(a), Some(c)) => format!("{a}:{c}"),
        _ => s.name().unwrap_or_else(|| "(unnamed)".into()),
    }
}

/// The CRS to reproject to, checked: projected, and a source CRS to start
/// from; without `reproject`, the source CRS must not be geographic.
fn target_srs(
    spec: &InputSpec,
    source_srs: Option<&SpatialRef>,
    layer_name: &str,
) -> Result<Option<SpatialRef>, IoError> {
    let Some(t) = &spec.reproject else {
        if let Some(s) = source_srs.filter(|s| s.is_geographic()) {
            return Err(IoError::Geographic {
                layer: layer_name.to_string(),
                crs: s.name().unwrap_or_else(|| "(unnamed)".into()),
                fix:
                    "add `input.reproject: EPSG:<code>` (e.g. the layer's UTM zone) to the pipeline",
            });
        }
        return Ok(None);
    };
    let bad = |reason: String| IoError::BadReproject {
        target: t.clone(),
        reason,
    };
    let srs = SpatialRef::from_definition(t).map_err(|e| bad(e.to_string()))?;
    if srs.is_geographic() {
        return Err(bad(
            "it is a geographic CRS; choose a projected one (metres), e.g. a UTM zone or EPSG:3035"
                .into(),
        ));
    }
    match source_srs {
        None => Err(bad(format!(
            "layer `{layer_name}` has no CRS to reproject from; assign one to the source first"
        ))),
        // Already there: no transformation, not even an identity one.
        Some(s) if *s == srs => Ok(None),
        Some(_) => Ok(Some(traditional(srs))),
    }
}

/// Whether two sources hand out geometries in the same CRS (`None` when
/// either has none).
pub fn same_crs(a: &SourceInfo, b: &SourceInfo) -> Option<bool> {
    let srs = |i: &SourceInfo| {
        i.srs_wkt
            .as_deref()
            .and_then(|w| SpatialRef::from_wkt(w).ok())
    };
    Some(srs(a)? == srs(b)?)
}

/// The feature count of a layer (as filtered), `None` when the driver cannot
/// tell (it returns −1).
fn count(layer: &gdal::vector::Layer<'_>) -> Option<u64> {
    // SAFETY: the handle is valid for the lifetime of `layer`.
    let n = unsafe { gdal_sys::OGR_L_GetFeatureCount(layer.c_layer(), 1) };
    u64::try_from(n).ok()
}

fn traditional(mut s: SpatialRef) -> SpatialRef {
    s.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    s
}

impl Reader {
    /// Opens the source and layer and checks filters and CRS; reads nothing.
    pub fn open(spec: &InputSpec) -> Result<Self, IoError> {
        super::gdal_errors::install();
        super::gdal_errors::clear();
        let dataset = Dataset::open_ex(
            &spec.source,
            DatasetOptions {
                open_flags: GdalOpenFlags::GDAL_OF_VECTOR | GdalOpenFlags::GDAL_OF_READONLY,
                ..Default::default()
            },
        )
        .map_err(|e| IoError::Open {
            source_name: spec.source.clone(),
            reason: e.to_string(),
        })?;
        let layer_index = Self::layer_index(&dataset, spec)?;
        let mut layer = dataset
            .layer(layer_index)
            .map_err(|e| IoError::gdal("opening the layer", e))?;
        let layer_name = layer.name();
        let total = count(&layer);
        let fields = layer
            .defn()
            .fields()
            .map(|f| FieldInfo {
                name: f.name(),
                kind: f.field_type(),
                width: f.width(),
                precision: f.precision(),
            })
            .collect();
        // A GeoPackage without a CRS reports an "Undefined geographic /
        // Cartesian SRS": that is no CRS.
        let source_srs = layer
            .spatial_ref()
            .filter(|s| !s.name().is_some_and(|n| n.starts_with("Undefined")));
        let target = target_srs(spec, source_srs.as_ref(), &layer_name)?;
        let out_srs = target.as_ref().or(source_srs.as_ref());
        let srs_wkt = out_srs.and_then(|s| s.to_wkt().ok());
        let crs_name = out_srs.map_or_else(|| "(no CRS)".into(), crs_name);
        Self::apply_filters(&mut layer, spec)?;
        let selected = count(&layer);
        // Some drivers (GeoPackage) accept a bad filter and only report it
        // when it is used: counting used it.
        if let (Some(w), [first, ..]) = (&spec.where_, &super::gdal_errors::take_failures()[..]) {
            return Err(IoError::BadWhere {
                filter: w.clone(),
                reason: first.clone(),
            });
        }
        let info = SourceInfo {
            source: spec.source.clone(),
            layer: layer_name,
            fields,
            srs_wkt,
            crs_name,
            total,
            selected,
        };
        Ok(Self {
            dataset,
            layer_index,
            spec: spec.clone(),
            info,
            target,
        })
    }

    /// The index of the layer `spec` asks for.
    fn layer_index(dataset: &Dataset, spec: &InputSpec) -> Result<usize, IoError> {
        let names: Vec<String> = dataset.layers().map(|l| l.name()).collect();
        let no_layer = |layer: String| IoError::NoLayer {
            source_name: spec.source.clone(),
            layer,
            available: if names.is_empty() {
                "(none)".into()
            } else {
                names.join(", ")
            },
        };
        match &spec.layer {
            None if names.is_empty() => Err(no_layer("#0".into())),
            None => Ok(0),
            Some(LayerRef::Index(i)) if *i < names.len() => Ok(*i),
            Some(LayerRef::Name(n)) => names
                .iter()
                .position(|x| x == n)
                .ok_or_else(|| no_layer(format!("`{n}`"))),
            Some(other) => Err(no_layer(other.to_string())),
        }
    }

    /// Reads the first selected feature and drops it: a filter or a source
    /// that fails only when read fails here (`validate`).
    pub fn probe(&mut self) -> Result<(), IoError> {
        let mut layer = self
            .dataset
            .layer(self.layer_index)
            .map_err(|e| IoError::gdal("opening the layer", e))?;
        Self::apply_filters(&mut layer, &self.spec)?;
        super::gdal_errors::clear();
        let _ = layer.features().next();
        self.check_read()
    }

    /// The failures GDAL reported while reading, as an error.
    fn check_read(&self) -> Result<(), IoError> {
        let failures = super::gdal_errors::take_failures();
        if failures.is_empty() {
            return Ok(());
        }
        Err(match &self.spec.where_ {
            Some(w) => IoError::BadWhere {
                filter: w.clone(),
                reason: failures.join("; "),
            },
            None => IoError::Read {
                source_name: self.spec.source.clone(),
                reason: failures.join("; "),
            },
        })
    }

    fn apply_filters(layer: &mut gdal::vector::Layer<'_>, spec: &InputSpec) -> Result<(), IoError> {
        if let Some(w) = &spec.where_ {
            super::set_filter(layer, w).map_err(|reason| IoError::BadWhere {
                filter: w.clone(),
                reason,
            })?;
        }
        if let Some([x0, y0, x1, y1]) = spec.bbox {
            layer.set_spatial_filter_rect(x0, y0, x1, y1);
        }
        Ok(())
    }

    /// What the source holds.
    pub fn info(&self) -> &SourceInfo {
        &self.info
    }

    /// Reads every selected feature, handing them to `on_batch` in batches of
    /// at most `batch` features, in source order.
    pub fn read<E: From<IoError>>(
        &mut self,
        batch: usize,
        make_valid: bool,
        mut on_batch: impl FnMut(Vec<Feature>) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut layer = self
            .dataset
            .layer(self.layer_index)
            .map_err(|e| IoError::gdal("opening the layer", e))?;
        Self::apply_filters(&mut layer, &self.spec)?;
        let transform = self.transform(&layer)?;
        let mut buf = Vec::with_capacity(batch);
        super::gdal_errors::clear();
        for f in layer.features() {
            // Failures while fetching the feature are the source's.
            self.check_read()?;
            buf.push(self.feature(&f, transform.as_ref(), make_valid));
            if buf.len() >= batch {
                on_batch(std::mem::take(&mut buf))?;
            }
        }
        // A source that fails part way (a broken file, a dropped
        // connection) ends the feature loop early: that is an error, not the
        // end of the data.
        self.check_read()?;
        if !buf.is_empty() {
            on_batch(buf)?;
        }
        Ok(())
    }

    /// Reads the features with the given FIDs, in that order, whatever the
    /// filters; an FID the layer does not hold is left out.
    pub fn read_fids(&self, fids: &[u64], make_valid: bool) -> Result<Vec<Feature>, IoError> {
        let layer = self
            .dataset
            .layer(self.layer_index)
            .map_err(|e| IoError::gdal("opening the layer", e))?;
        let transform = self.transform(&layer)?;
        Ok(fids
            .iter()
            .filter_map(|&fid| layer.feature(fid))
            .map(|f| self.feature(&f, transform.as_ref(), make_valid))
            .collect())
    }

    /// The transformation to the target CRS, when reprojecting.
    fn transform(
        &self,
        layer: &gdal::vector::Layer<'_>,
    ) -> Result<Option<CoordTransform>, IoError> {
        match (&self.target, layer.spatial_ref()) {
            (Some(t), Some(s)) => Ok(Some(
                CoordTransform::new(&traditional(s), t)
                    .map_err(|e| IoError::gdal("creating the coordinate transformation", e))?,
            )),
            _ => Ok(None),
        }
    }

    /// One GDAL feature as an owned [`Feature`].
    fn feature(
        &self,
        f: &gdal::vector::Feature<'_>,
        transform: Option<&CoordTransform>,
        make_valid: bool,
    ) -> Feature {
        let attributes = (0..self.info.fields.len())
            .map(|i| value(f.field(i).ok().flatten()))
            .collect();
        let mut feat = Feature::new(f.fid(), attributes);
        // gdal hands out a wrapper around a null handle for NULL geometries.
        // SAFETY: the handle is only compared with null.
        let geometry = f
            .geometry()
            .filter(|g| unsafe { !g.c_geometry().is_null() });
        if let Some(g) = geometry {
            match convert(g, transform, make_valid) {
                Ok(c) => {
                    feat.geometry = c.geometry;
                    feat.source_wkb = c.wkb;
                    feat.repaired = c.repaired;
                    feat.checked = c.checked;
                }
                Err(e) => feat.geometry_error = Some(e),
            }
            // What GDAL reported while converting (a reprojection or a
            // repair that failed) is this feature's reason, not the run's.
            super::gdal_errors::clear();
        }
        feat
    }
}

/// A field value as the per-feature path carries it.
pub(super) fn value(v: Option<FieldValue>) -> Value {
    match v {
        None => Value::Null,
        Some(FieldValue::IntegerValue(i)) => Value::Integer(i),
        Some(FieldValue::Integer64Value(i)) => Value::Integer64(i),
        Some(FieldValue::RealValue(r)) => Value::Real(r),
        Some(FieldValue::StringValue(s)) => Value::Text(s),
        Some(FieldValue::DateValue(d)) => Value::Date(d),
        Some(FieldValue::DateTimeValue(d)) => Value::DateTime(d),
        Some(FieldValue::IntegerListValue(l)) => Value::IntegerList(l),
        Some(FieldValue::Integer64ListValue(l)) => Value::Integer64List(l),
        Some(FieldValue::RealListValue(l)) => Value::RealList(l),
        Some(FieldValue::StringListValue(l)) => Value::TextList(l),
    }
}

/// A source geometry as the per-feature path takes it.
struct Converted {
    geometry: Option<geo::Geometry<f64>>,
    /// The 2D source WKB, for the `rejected` layer.
    wkb: Option<Vec<u8>>,
    /// MakeValid changed it.
    repaired: bool,
    /// Found valid by the crate's own check ([`checked_polygon`]).
    checked: bool,
}

/// 2D, linear, reprojected, optionally repaired `geo` geometry (plus the 2D
/// source WKB for the `rejected` layer).
fn convert(
    g: &Geometry,
    transform: Option<&CoordTransform>,
    make_valid: bool,
) -> Result<Converted, String> {
    let mut g = g.clone();
    if g.is_empty() {
        let wkb = g.wkb().ok();
        return Ok(Converted {
            geometry: Some(geo::Geometry::GeometryCollection(Default::default())),
            wkb,
            repaired: false,
            checked: false,
        });
    }
    g.flatten_to_2d();
    // SAFETY: the handle is valid for the lifetime of `g`.
    let nonlinear = unsafe {
        gdal_sys::OGR_GT_IsNonLinear(gdal_sys::OGR_G_GetGeometryType(g.c_geometry())) != 0
    };
    if nonlinear {
        g = linearise(&g)?;
    }
    if let Some(ct) = transform {
        g.transform_inplace(ct)
            .map_err(|e| format!("reprojection failed: {e}"))?;
    }
    let wkb = g.wkb().ok();
    if make_valid {
        if let Some(polygon) = checked_polygon(&g) {
            return Ok(Converted {
                geometry: Some(geo::Geometry::Polygon(polygon)),
                wkb,
                repaired: false,
                checked: true,
            });
        }
    }
    let mut repaired = false;
    if make_valid && !g.is_valid() {
        let fixed = g
            .make_valid(&CslStringList::new())
            .map_err(|e| format!("make_valid could not repair the geometry: {e}"))?;
        g = areal_parts(fixed)?;
        repaired = true;
    }
    let geo = g
        .to_geo()
        .map_err(|e| format!("unsupported geometry: {e}"))?;
    Ok(Converted {
        geometry: Some(geo),
        wkb,
        repaired,
        checked: false,
    })
}

/// `g` as a `geo` polygon when it is a polygon without holes that the
/// crate's own validity check (the one `prepare` makes) finds valid: for
/// such a polygon that check decides what GEOS's IsValid would (finite
/// coordinates, a closed ring of at least three distinct points, no
/// crossing, overlap, self-touch or spike; the checks GEOS adds concern
/// holes and parts), in a fraction of its time and on every core — GEOS's
/// took 5 of the 25 s of a million-vertex polygon, on one thread. Anything
/// else (`None`) goes through GEOS's IsValid and MakeValid as before.
fn checked_polygon(g: &Geometry) -> Option<geo::Polygon<f64>> {
    use gdal_sys::OGRwkbGeometryType as T;
    if gdal::vector::geometry_type_flatten(g.geometry_type()) != T::wkbPolygon
        || g.geometry_count() != 1
    {
        return None;
    }
    let geo::Geometry::Polygon(p) = g.to_geo().ok()? else {
        return None;
    };
    let ring = &p.exterior().0;
    // geo closes an open ring; GEOS calls it invalid (MakeValid closes it).
    let (first, last) = (g.get_geometry(0).get_point(0), {
        let r = g.get_geometry(0);
        r.get_point(r.point_count().checked_sub(1)? as i32)
    });
    let mut distinct = ring.clone();
    distinct.dedup();
    if first != last
        || distinct.len() < 4
        || !p.interiors().is_empty()
        || ring.iter().any(|c| !c.x.is_finite() || !c.y.is_finite())
    {
        return None;
    }
    let prepared = crate::geometry::PreparedPolygon::new(&p).ok()?;
    crate::geometry::validity::problem(&prepared)
        .is_none()
        .then_some(p)
}

fn linearise(g: &Geometry) -> Result<Geometry, String> {
    // SAFETY: OGR_G_GetLinearGeometry returns a new geometry we own; it is
    // exported to WKB and destroyed here.
    unsafe {
        let h = gdal_sys::OGR_G_GetLinearGeometry(g.c_geometry(), 0.0, std::ptr::null_mut());
        if h.is_null() {
            return Err("the curved geometry could not be linearised".into());
        }
        let size = gdal_sys::OGR_G_WkbSize(h) as usize;
        let mut buf = vec![0u8; size];
        let rv =
            gdal_sys::OGR_G_ExportToWkb(h, gdal_sys::OGRwkbByteOrder::wkbNDR, buf.as_mut_ptr());
        gdal_sys::OGR_G_DestroyGeometry(h);
        if rv != gdal_sys::OGRErr::OGRERR_NONE {
            return Err("the linearised geometry could not be exported".into());
        }
        Geometry::from_wkb(&buf).map_err(|e| e.to_string())
    }
}

/// Keeps the polygons of a MakeValid result (which may mix in the lines and
/// points that collapsed spikes become).
fn areal_parts(g: Geometry) -> Result<Geometry, String> {
    use gdal_sys::OGRwkbGeometryType as T;
    let ty = gdal::vector::geometry_type_flatten(g.geometry_type());
    if ty == T::wkbPolygon || ty == T::wkbMultiPolygon {
        return Ok(g);
    }
    let mut mp = Geometry::empty(T::wkbMultiPolygon).map_err(|e| e.to_string())?;
    collect_polygons(&g, &mut mp)?;
    if mp.geometry_count() == 0 {
        return Err("make_valid left no area (the polygon collapses to lines or points)".into());
    }
    Ok(mp)
}

fn collect_polygons(g: &Geometry, out: &mut Geometry) -> Result<(), String> {
    use gdal_sys::OGRwkbGeometryType as T;
    let ty = gdal::vector::geometry_type_flatten(g.geometry_type());
    if ty == T::wkbPolygon {
        out.add_geometry(g.clone()).map_err(|e| e.to_string())?;
    } else if ty == T::wkbMultiPolygon || ty == T::wkbGeometryCollection {
        for i in 0..g.geometry_count() {
            let sub = g.get_geometry(i);
            collect_polygons(&sub, out)?;
        }
    }
    Ok(())
}

/// The data source string as it opens from any working directory: an
/// existing local path made absolute; anything else (`PG:…`, `/vsizip/…`,
/// URLs) as given.
pub fn absolute_source(source: &str) -> String {
    let path = std::path::Path::new(source);
    match path.is_relative().then(|| path.canonicalize()) {
        Some(Ok(abs)) => abs.display().to_string(),
        _ => source.to_string(),
    }
}

/// A source FID and its geometry.
pub type FidGeometry = (Option<u64>, geo::Geometry<f64>);

/// Reads every feature of one layer of a file as `(fid, geometry)`, skipping
/// NULL geometries: for benchmarks, examples and tests.
pub fn read_layer_polygons(source: &str, layer: &str) -> Result<Vec<FidGeometry>, IoError> {
    let mut r = Reader::open(&InputSpec::layer(source, layer))?;
    let mut out = Vec::new();
    r.read::<IoError>(1024, false, |batch| {
        out.extend(
            batch
                .into_iter()
                .filter_map(|f| f.geometry.map(|g| (f.fid, g))),
        );
        Ok(())
    })?;
    Ok(out)
}
