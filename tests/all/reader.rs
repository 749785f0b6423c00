//! The reader on the real training data.

use crate::common::TRAIN;
use skeletonise::io::{read_layer_polygons, InputSpec, IoError, LayerRef, Reader};

#[test]
fn reads_every_training_layer_with_its_fields() {
    for (layer, n) in [
        ("islands_hebrides", 1192),
        ("lakes_scotland", 18),
        ("river_st_lawrence", 1),
        ("river_danube", 1),
        ("river_lena", 3),
    ] {
        let feats = read_layer_polygons(TRAIN, layer).unwrap();
        assert_eq!(feats.len(), n, "{layer}");
        assert!(feats.iter().all(|(_, g)| matches!(
            g,
            geo::Geometry::Polygon(_) | geo::Geometry::MultiPolygon(_)
        )));
    }
    let r = Reader::open(&InputSpec {
        source: TRAIN.into(),
        layer: Some(LayerRef::Name("lakes_scotland".into())),
        where_: Some("area_m2 > 1e7".into()),
        bbox: None,
        reproject: None,
        merge_adjacent: false,
        merge_by: None,
        connect: None,
        neighbours: None,
    })
    .unwrap();
    let names: Vec<_> = r.info().fields.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        ["kind", "area_m2", "perimeter_m", "vertices", "holes"]
    );
    assert_eq!(r.info().total, Some(18));
    assert!(r.info().selected.is_some_and(|n| n < 18));
    assert_eq!(r.info().crs_name, "EPSG:32630");
}

#[test]
fn missing_layer_lists_the_available_ones() {
    let e = read_layer_polygons(TRAIN, "rivers").unwrap_err();
    assert!(matches!(e, IoError::NoLayer { .. }));
    assert!(e.to_string().contains("river_lena"), "{e}");
}

/// With `make_valid`, a polygon without holes that the crate's own check
/// finds valid is not handed to GEOS (`checked`, not `repaired`); anything
/// that check rejects, and every polygon with holes or parts, goes through
/// GEOS's IsValid and MakeValid as before: the same geometries either way.
#[test]
fn make_valid_checks_simple_polygons_itself_and_repairs_the_rest_with_geos() {
    let dir = crate::common::tmp();
    let path = dir.path().join("shapes.geojson");
    let feature = |name: &str, wkt: &str| {
        let g = gdal::vector::Geometry::from_wkt(wkt)
            .unwrap()
            .json()
            .unwrap();
        format!(r#"{{"type":"Feature","properties":{{"name":"{name}"}},"geometry":{g}}}"#)
    };
    let shapes = [
        ("square", "POLYGON ((0 0,10 0,10 10,0 10,0 0))"),
        ("bow-tie", "POLYGON ((0 0,10 10,10 0,0 10,0 0))"),
        (
            "spike",
            "POLYGON ((0 0,10 0,10 10,5 10,5 20,5 10,0 10,0 0))",
        ),
        ("self-touch", "POLYGON ((0 0,10 0,10 10,5 0,0 10,0 0))"),
        (
            "repeated points",
            "POLYGON ((0 0,10 0,10 0,10 10,0 10,0 0))",
        ),
        (
            "with a hole",
            "POLYGON ((0 0,10 0,10 10,0 10,0 0),(2 2,2 4,4 4,4 2,2 2))",
        ),
        (
            "two parts",
            "MULTIPOLYGON (((0 0,1 0,1 1,0 0)),((5 5,6 5,6 6,5 5)))",
        ),
    ];
    let features: Vec<String> = shapes.iter().map(|(n, w)| feature(n, w)).collect();
    std::fs::write(
        &path,
        format!(
            r#"{{"type":"FeatureCollection","crs":{{"type":"name","properties":{{"name":"urn:ogc:def:crs:EPSG::32633"}}}},"features":[{}]}}"#,
            features.join(",")
        ),
    )
    .unwrap();
    let mut r = Reader::open(&InputSpec::layer(path.to_str().unwrap(), "shapes")).unwrap();
    let mut got = Vec::new();
    r.read::<IoError>(100, true, |batch| {
        got.extend(batch);
        Ok(())
    })
    .unwrap();
    let flags: Vec<(bool, bool)> = got.iter().map(|f| (f.checked, f.repaired)).collect();
    assert_eq!(
        flags,
        [
            (true, false),  // valid: checked here
            (false, true),  // crossing: GEOS repairs it
            (false, true),  // spike: likewise
            (false, true),  // a ring touching itself: likewise
            (true, false),  // a repeated vertex is no problem
            (false, false), // holes: GEOS checks (valid)
            (false, false), // parts: GEOS checks (valid)
        ]
    );
    // The repaired bow-tie is GEOS's: two triangles.
    assert!(
        matches!(&got[1].geometry, Some(geo::Geometry::MultiPolygon(m)) if m.0.len() == 2),
        "{:?}",
        got[1].geometry
    );
}
