//! The reader on the real training data.

mod common;
use common::TRAIN;
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
