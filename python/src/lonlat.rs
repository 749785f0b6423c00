//! Longitude and latitude of a call's coordinates without GDAL: the CRS as
//! a PROJ string (pyproj's `CRS.to_proj4()`), transformed by proj4rs — what
//! the `label` step needs for its `minzoom`, on any worker thread (no
//! Python, no GIL).

use skeletonise::process::step::LonLat;

/// The map from coordinates in the CRS `proj` (a PROJ string) to longitude
/// and latitude in degrees (WGS 84), or `None` when proj4rs does not know
/// the projection.
pub fn lonlat_of(proj: &str) -> Option<LonLat> {
    use proj4rs::proj::Proj;
    let from = Proj::from_user_string(proj).ok()?;
    let to = Proj::from_proj_string("+proj=longlat +datum=WGS84 +no_defs").ok()?;
    let map = std::panic::AssertUnwindSafe(move |c: geo::Coord<f64>| {
        let mut p = if from.is_latlong() {
            (c.x.to_radians(), c.y.to_radians(), 0.0)
        } else {
            (c.x, c.y, 0.0)
        };
        proj4rs::transform::transform(&from, &to, &mut p).ok()?;
        let (lon, lat) = (p.0.to_degrees(), p.1.to_degrees());
        (lon.is_finite() && lat.is_finite()).then_some(geo::Coord { x: lon, y: lat })
    });
    Some(LonLat::new(move |c| (map.0)(c)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utm_coordinates_have_the_latitude_gdal_gives() {
        // UTM 33N, 500 000 E, 6 650 000 N: `gdaltransform -s_srs EPSG:32633
        // -t_srs "+proj=longlat +datum=WGS84"` gives 15, 59.9873285392347.
        let f = lonlat_of("+proj=utm +zone=33 +datum=WGS84 +units=m +no_defs +type=crs").unwrap();
        let c = f
            .of(geo::Coord {
                x: 500_000.0,
                y: 6_650_000.0,
            })
            .unwrap();
        assert!((c.x - 15.0).abs() < 1e-9, "{c:?}");
        assert!((c.y - 59.987_328_539_234_7).abs() < 1e-9, "{c:?}");
        // EPSG:3035 (LAEA Europe) far from its centre: GDAL gives
        // -47.121487390281, 6.19259738663062.
        let laea = "+proj=laea +lat_0=52 +lon_0=10 +x_0=4321000 +y_0=3210000 +ellps=GRS80 +units=m +no_defs +type=crs";
        let c = lonlat_of(laea)
            .unwrap()
            .of(geo::Coord {
                x: -2_000_000.0,
                y: 500_000.0,
            })
            .unwrap();
        assert!((c.x + 47.121_487_390_281).abs() < 1e-8, "{c:?}");
        assert!((c.y - 6.192_597_386_630_62).abs() < 1e-8, "{c:?}");
        // Degrees in, degrees out.
        let g = lonlat_of("+proj=longlat +datum=WGS84 +no_defs +type=crs").unwrap();
        let c = g.of(geo::Coord { x: 10.0, y: 50.0 }).unwrap();
        assert!(
            (c.x - 10.0).abs() < 1e-12 && (c.y - 50.0).abs() < 1e-12,
            "{c:?}"
        );
        assert!(lonlat_of("+proj=nonsense").is_none());
    }
}
