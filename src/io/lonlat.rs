//! Longitude and latitude of a run's coordinates, for the steps that need
//! to know where on Earth a feature lies (a label's minimum web-map zoom).
//! GDAL's transformations are not to be shared between threads: each
//! worker thread makes its own from the CRS's WKT, once.

use crate::process::step::LonLat;
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use std::cell::RefCell;

thread_local! {
    /// This thread's transformation and the WKT it was made for.
    static TO_LONLAT: RefCell<Option<(String, Option<CoordTransform>)>> = const { RefCell::new(None) };
}

/// The map from coordinates in the CRS `wkt` to longitude and latitude
/// (WGS 84), or `None` when GDAL cannot make the transformation.
pub fn lonlat_of(wkt: &str) -> Option<LonLat> {
    // Fails here, once, rather than on every feature.
    transformation(wkt)?;
    let wkt = wkt.to_string();
    Some(LonLat::new(move |c| {
        TO_LONLAT.with(|t| {
            let mut t = t.borrow_mut();
            if t.as_ref().is_none_or(|(w, _)| *w != wkt) {
                *t = Some((wkt.clone(), transformation(&wkt)));
            }
            let tr = t.as_ref()?.1.as_ref()?;
            let (mut x, mut y, mut z) = ([c.x], [c.y], [0.0]);
            tr.transform_coords(&mut x, &mut y, &mut z).ok()?;
            (x[0].is_finite() && y[0].is_finite()).then_some(geo::Coord { x: x[0], y: y[0] })
        })
    }))
}

fn transformation(wkt: &str) -> Option<CoordTransform> {
    let mut from = SpatialRef::from_wkt(wkt).ok()?;
    from.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let mut to = SpatialRef::from_epsg(4326).ok()?;
    to.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    CoordTransform::new(&from, &to).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utm_coordinates_come_back_as_degrees() {
        let utm30 = SpatialRef::from_epsg(32630).unwrap().to_wkt().unwrap();
        let f = lonlat_of(&utm30).unwrap();
        // The central meridian of zone 30 (3° W) at the equator.
        let c = f
            .of(geo::Coord {
                x: 500_000.0,
                y: 0.0,
            })
            .unwrap();
        assert!((c.x + 3.0).abs() < 1e-9 && c.y.abs() < 1e-9, "{c:?}");
        // From another thread, with its own transformation.
        let g = f.clone();
        let d = std::thread::spawn(move || {
            g.of(geo::Coord {
                x: 500_000.0,
                y: 6_300_000.0,
            })
        })
        .join()
        .unwrap()
        .unwrap();
        assert!((d.y - 56.8).abs() < 0.1, "{d:?}");
        assert!(lonlat_of("not a CRS").is_none());
    }
}
