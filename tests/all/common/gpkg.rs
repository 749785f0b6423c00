//! GeoPackage helpers for tests (GDAL): make input layers, read output layers.

use gdal::spatial_ref::SpatialRef;
use gdal::vector::{
    Feature, FieldDefn, Geometry, LayerAccess, LayerOptions, OGRFieldType, OGRwkbGeometryType,
};
use gdal::{Dataset, DriverManager};
use std::path::Path;

/// Creates a GeoPackage layer `layer` in `srs` holding the given WKT
/// geometries (`None` = NULL geometry) with an integer field `id`.
pub fn make_layer(path: &Path, layer: &str, epsg: u32, wkts: &[Option<&str>]) {
    let drv = DriverManager::get_driver_by_name("GPKG").unwrap();
    let mut ds = if path.exists() {
        Dataset::open_ex(
            path,
            gdal::DatasetOptions {
                open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE
                    | gdal::GdalOpenFlags::GDAL_OF_VECTOR,
                ..Default::default()
            },
        )
        .unwrap()
    } else {
        drv.create_vector_only(path).unwrap()
    };
    let srs = SpatialRef::from_epsg(epsg).unwrap();
    // One transaction for the whole layer: a GeoPackage commits (and syncs)
    // every feature written outside one, seconds for thousands of features.
    let mut ds = ds.start_transaction().unwrap();
    let l = ds
        .create_layer(LayerOptions {
            name: layer,
            srs: Some(&srs),
            ty: OGRwkbGeometryType::wkbUnknown,
            options: None,
        })
        .unwrap();
    FieldDefn::new("id", OGRFieldType::OFTInteger)
        .unwrap()
        .add_to_layer(&l)
        .unwrap();
    for (i, w) in wkts.iter().enumerate() {
        let mut f = Feature::new(l.defn()).unwrap();
        if let Some(w) = w {
            f.set_geometry(Geometry::from_wkt(w).unwrap()).unwrap();
        }
        f.set_field_integer(0, i as i32).unwrap();
        f.create(&l).unwrap();
    }
    ds.commit().unwrap();
}

/// Opens an output GeoPackage.
pub fn open(path: &Path) -> Dataset {
    Dataset::open(path).expect("output opens")
}

/// Number of features in a layer.
pub fn count(ds: &Dataset, layer: &str) -> u64 {
    ds.layer_by_name(layer).unwrap().feature_count()
}

/// One string field of every feature of a layer.
pub fn strings(ds: &Dataset, layer: &str, field: &str) -> Vec<Option<String>> {
    let mut l = ds.layer_by_name(layer).unwrap();
    let idx = l.defn().field_index(field).unwrap();
    l.features()
        .map(|f| f.field_as_string(idx).unwrap())
        .collect()
}

/// One integer field of every feature of a layer.
pub fn ints(ds: &Dataset, layer: &str, field: &str) -> Vec<Option<i64>> {
    let mut l = ds.layer_by_name(layer).unwrap();
    let idx = l.defn().field_index(field).unwrap();
    l.features()
        .map(|f| f.field_as_integer64(idx).unwrap())
        .collect()
}

/// One real field of every feature of a layer.
pub fn reals(ds: &Dataset, layer: &str, field: &str) -> Vec<Option<f64>> {
    let mut l = ds.layer_by_name(layer).unwrap();
    let idx = l.defn().field_index(field).unwrap();
    l.features()
        .map(|f| f.field_as_double(idx).unwrap())
        .collect()
}

/// WKT of every geometry of a layer.
pub fn wkts(ds: &Dataset, layer: &str) -> Vec<Option<String>> {
    let mut l = ds.layer_by_name(layer).unwrap();
    l.features()
        .map(|f| f.geometry().and_then(|g| g.wkt().ok()))
        .collect()
}

/// A canonical text of every layer of an output GeoPackage except the run
/// record (which holds times): per layer its name, field names and every
/// row — geometry as WKB in hex, values as GDAL gives them — so that two
/// runs compare equal exactly when their content is the same.
pub fn canonical(path: &Path) -> String {
    let ds = open(path);
    let mut out = String::new();
    let mut names: Vec<String> = ds.layers().map(|l| l.name()).collect();
    names.sort();
    for name in names.iter().filter(|n| *n != "skeletonise_runs") {
        let mut l = ds.layer_by_name(name).unwrap();
        let fields: Vec<String> = l.defn().fields().map(|f| f.name()).collect();
        out.push_str(&format!("## {name}: {}\n", fields.join(",")));
        for f in l.features() {
            let g = f
                .geometry()
                .and_then(|g| g.wkb().ok())
                .map(|w| w.iter().map(|b| format!("{b:02x}")).collect::<String>())
                .unwrap_or_default();
            let vals: Vec<String> = (0..fields.len())
                .map(|i| format!("{:?}", f.field(i).ok().flatten()))
                .collect();
            out.push_str(&format!("{g}|{}\n", vals.join("|")));
        }
    }
    out
}

/// The first column of the first row of `sql` (SQLite dialect) as text.
pub fn first_text(ds: &Dataset, sql: &str) -> Option<String> {
    let mut rs = ds
        .execute_sql(sql, None, gdal::vector::sql::Dialect::SQLITE)
        .unwrap()?;
    let f = rs.features().next()?;
    f.field_as_string(0).unwrap()
}
