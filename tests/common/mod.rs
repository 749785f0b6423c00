//! Helpers for end-to-end tests: run the real binary, make and read real
//! GeoPackage files.
#![allow(dead_code)]

pub mod browser;

use gdal::spatial_ref::SpatialRef;
use gdal::vector::{
    Feature, FieldDefn, Geometry, LayerAccess, LayerOptions, OGRFieldType, OGRwkbGeometryType,
};
use gdal::{Dataset, DriverManager};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The training data shipped beside the project.
pub const TRAIN: &str = "tests/data/gshhg-train.gpkg";
/// Every layer of the training data.
pub const LAYERS: [&str; 5] = [
    "islands_hebrides",
    "lakes_scotland",
    "river_st_lawrence",
    "river_danube",
    "river_lena",
];

/// The embedded demo data.
pub const DEMO: &str = "examples/data/demo.gpkg";

/// Runs `skeletonise` with `args` in the crate root.
pub fn skeletonise(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skeletonise"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

/// Exit code and stderr as text.
pub fn code_and_err(o: &Output) -> (i32, String) {
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

/// A fresh temporary directory.
pub fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// Writes a pipeline file into `dir` and returns its path.
pub fn pipeline(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A standard pipeline reading `source`/`layer` and writing `out`.
pub fn basic_pipeline(source: &str, layer: &str, out: &Path, extra_steps: &str) -> String {
    format!(
        "input:\n  source: {source}\n  layer: {layer}\nsteps:\n  - skeleton: {{ methods: [CDT] }}\n{extra_steps}output:\n  path: {}\n",
        out.display()
    )
}

/// Absolute path of a file in the crate root.
pub fn root(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(p)
        .display()
        .to_string()
}

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

/// FNV-1a, 64 bit: a stable fingerprint of a text.
pub fn fingerprint(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}
