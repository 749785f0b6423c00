//! Label lines: the `label` step of `pipelines/lake-labels.yaml` on the
//! training lakes and islands gives every polygon part exactly one label —
//! a simple line inside its polygon, off the shore, turning gently and
//! centred (scored with `skeletonise score`), or a point at the centre of
//! the largest inscribed disc.
#![cfg(all(feature = "cli", feature = "gdal"))]

use crate::common::*;
use gdal::vector::LayerAccess;
use geo::{Contains, Coord, Geometry, LineString, Polygon};
use skeletonise::geometry::PreparedPolygon;
use std::collections::HashMap;
use std::path::Path;

const TRAIN: &str = "tests/data/gshhg-train.gpkg";
/// Two world lakes whose axes bend too sharply for a label (README in tests/data).
const BENDS: &str = "tests/data/gshhg-lakes-bends.gpkg";

fn geometry(w: &str) -> Geometry<f64> {
    wkt::TryFromWkt::try_from_wkt_str(w).unwrap()
}

/// The layer's polygons by FID (every part of a multipolygon).
fn polygons(data: &str, layer: &str) -> HashMap<i64, Vec<Polygon<f64>>> {
    let ds = open(Path::new(&root(data)));
    let mut l = ds.layer_by_name(layer).unwrap();
    l.features()
        .map(|f| {
            let parts = match geometry(&f.geometry().unwrap().wkt().unwrap()) {
                Geometry::Polygon(p) => vec![p],
                Geometry::MultiPolygon(m) => m.0,
                other => panic!("not a polygon: {other:?}"),
            };
            (f.fid().unwrap() as i64, parts)
        })
        .collect()
}

fn run(dir: &Path, data: &str, layer: &str) -> std::path::PathBuf {
    let out = dir.join(format!("{layer}.gpkg"));
    let o = skeletonise(&[
        "run",
        &root("pipelines/lake-labels.yaml"),
        "--set",
        &format!("input.source={}", root(data)),
        "--set",
        &format!("input.layer={layer}"),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    out
}

fn dist(a: Coord<f64>, b: Coord<f64>) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// The signed angle from `u` to `v` (radians).
fn turn(u: Coord<f64>, v: Coord<f64>) -> f64 {
    (u.x * v.y - u.y * v.x).atan2(u.x * v.x + u.y * v.y)
}

/// True when no two non-adjacent segments of `l` meet.
fn simple(l: &LineString<f64>) -> bool {
    use geo::Intersects;
    let segs: Vec<geo::Line<f64>> = l.lines().collect();
    for i in 0..segs.len() {
        for j in i + 2..segs.len() {
            if segs[i].intersects(&segs[j]) {
                return false;
            }
        }
    }
    true
}

/// The largest turn of `l` over a stretch starting at each vertex and
/// `2 d` long, d the vertex's distance to ∂P: the local width 2r where the
/// line is on the medial axis.
fn worst_turn(l: &LineString<f64>, p: &PreparedPolygon) -> f64 {
    let c = &l.0;
    let mut worst: f64 = 0.0;
    for i in 0..c.len().saturating_sub(2) {
        let d = p.boundary().nearest(c[i]).unwrap().2;
        let (mut along, mut total) = (0.0, 0.0);
        let mut j = i + 1;
        while j + 1 < c.len() && along < 2.0 * d {
            total += turn(c[j] - c[j - 1], c[j + 1] - c[j]);
            worst = worst.max(total.abs());
            along += dist(c[j], c[j + 1]);
            j += 1;
        }
    }
    worst.to_degrees()
}

/// The largest distance to ∂P over a grid of points inside `p` (a check of
/// the largest inscribed disc, independent of the medial axis).
fn grid_max_radius(poly: &Polygon<f64>, p: &PreparedPolygon) -> f64 {
    use geo::BoundingRect;
    let r = poly.bounding_rect().unwrap();
    let n = 120;
    let mut best: f64 = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            let c = Coord {
                x: r.min().x + r.width() * i as f64 / n as f64,
                y: r.min().y + r.height() * j as f64 / n as f64,
            };
            if poly.contains(&geo::Point(c)) {
                best = best.max(p.boundary().nearest(c).unwrap().2);
            }
        }
    }
    best
}

fn check_layer(data: &str, layer: &str, max_z: f64) -> (usize, usize) {
    let dir = tmp();
    let out = run(dir.path(), data, layer);
    let polys = polygons(data, layer);
    let ds = open(&out);
    let fids = ints(&ds, "labels", "src_fid");
    let parts = ints(&ds, "labels", "polygon_part");
    let kinds = strings(&ds, "labels", "kind");
    let widths = reals(&ds, "labels", "max_width");
    let geoms = wkts(&ds, "labels");
    let zooms = ints(&ds, "labels", "minzoom");
    let lengths = reals(&ds, "labels", "length");
    // Longitude and latitude of the layer's coordinates, by GDAL.
    let to_lonlat = {
        use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
        let mut from = ds.layer_by_name("labels").unwrap().spatial_ref().unwrap();
        from.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
        let mut to = SpatialRef::from_epsg(4326).unwrap();
        to.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
        CoordTransform::new(&from, &to).unwrap()
    };
    // The zoom from which a label is 64 pixels long (a point's disc wide)
    // on 256-pixel web-map tiles at its own latitude.
    let zoom_ok = |metres: f64, at: Coord<f64>, z: i64| {
        let (mut x, mut y, mut zz) = ([at.x], [at.y], [0.0]);
        to_lonlat.transform_coords(&mut x, &mut y, &mut zz).unwrap();
        let per_pixel = 156_543.033_928_041 * y[0].to_radians().cos();
        let px = |z: i64| metres / (per_pixel / 2f64.powi(z as i32));
        px(z) >= 64.0 && (z == 0 || px(z - 1) < 64.0)
    };
    let expected: usize = polys.values().map(Vec::len).sum();
    assert_eq!(fids.len(), expected, "{layer}: one label per polygon part");
    let mut seen = std::collections::HashSet::new();
    let (mut lines, mut points) = (0, 0);
    for k in 0..fids.len() {
        let (fid, part) = (fids[k].unwrap(), parts[k].unwrap() as usize);
        assert!(seen.insert((fid, part)), "{layer} {fid}/{part}: one row");
        let poly = &polys[&fid][part];
        let p = PreparedPolygon::new(poly).unwrap();
        match (kinds[k].as_deref(), geometry(geoms[k].as_deref().unwrap())) {
            (Some("line"), Geometry::LineString(l)) => {
                lines += 1;
                assert!(simple(&l), "{layer} {fid}: the line is simple");
                assert!(
                    poly.contains(&l),
                    "{layer} {fid}: the line lies inside its polygon"
                );
                let near =
                    l.0.iter()
                        .map(|&c| p.boundary().nearest(c).unwrap().2)
                        .fold(f64::INFINITY, f64::min);
                assert!(near > 0.0, "{layer} {fid}: off the shore");
                use geo::{Euclidean, InterpolateLine};
                let mid = Euclidean.point_at_ratio_from_start(&l, 0.5).unwrap().0;
                let z = zooms[k].expect("a line has a minzoom");
                assert!(
                    zoom_ok(lengths[k].unwrap(), mid, z),
                    "{layer} {fid}: minzoom {z}"
                );
                let t = worst_turn(&l, &p);
                assert!(
                    t <= 60.0,
                    "{layer} {fid}: turns {t:.1}° over one local width"
                );
            }
            (Some("point"), Geometry::Point(c)) => {
                points += 1;
                let r = p.boundary().nearest(c.0).unwrap().2;
                let w = widths[k].unwrap();
                assert!(
                    (2.0 * r - w).abs() <= 1e-6 * w.max(1.0),
                    "{layer} {fid}: max_width is the point's disc"
                );
                let z = zooms[k].expect("a point has a minzoom");
                assert!(zoom_ok(w, c.0, z), "{layer} {fid}: minzoom {z}");
                let grid = grid_max_radius(poly, &p);
                assert!(
                    r >= 0.99 * grid,
                    "{layer} {fid}: the largest disc ({r} against {grid} on a grid)"
                );
            }
            other => panic!("{layer} {fid}: {other:?}"),
        }
        // The run reuses the medial axis its `skeleton` step made; the
        // library call makes its own: the same label.
        let own = skeletonise::label::LabelParams::default().label(&p);
        let own = match own.map(|l| l.label) {
            Some(skeletonise::label::Label::Line(l)) => Geometry::LineString(l),
            Some(skeletonise::label::Label::Point(c)) => Geometry::Point(c.into()),
            None => panic!("{layer} {fid}: a label"),
        };
        let written = geometry(geoms[k].as_deref().unwrap());
        let (a, b): (Vec<Coord<f64>>, Vec<Coord<f64>>) = {
            use geo::CoordsIter;
            (own.coords_iter().collect(), written.coords_iter().collect())
        };
        assert!(
            a.len() == b.len() && a.iter().zip(&b).all(|(&a, &b)| dist(a, b) < 1e-6),
            "{layer} {fid}: the run's label is the library's"
        );
    }
    // Centred: the lines scored against their polygons.
    let lines_only = dir.path().join("lines.gpkg");
    let ok = std::process::Command::new("ogr2ogr")
        .args([
            "-f",
            "GPKG",
            lines_only.to_str().unwrap(),
            out.to_str().unwrap(),
            "labels",
            "-where",
            "kind = 'line'",
            "-nln",
            "lines",
        ])
        .status()
        .unwrap();
    assert!(ok.success());
    let scored = dir.path().join("scored.gpkg");
    let o = skeletonise(&[
        "score",
        "--polygons",
        &root(data),
        "--polygons-layer",
        layer,
        "--skeletons",
        lines_only.to_str().unwrap(),
        "--skeletons-layer",
        "lines",
        "--skeleton-key",
        "src_fid",
        "--label",
        "label",
        "-o",
        scored.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    let sds = open(&scored);
    let z: Vec<f64> = reals(&sds, "skeletons", "distortion")
        .into_iter()
        .flatten()
        .collect();
    assert_eq!(z.len(), lines, "{layer}: every line scored");
    let worst = z.iter().cloned().fold(0.0, f64::max);
    let mean = z.iter().sum::<f64>() / z.len().max(1) as f64;
    let over = z.iter().filter(|&&z| z > 0.01).count();
    eprintln!(
        "{layer}: {lines} lines, {points} points; Z mean {mean:.6}, worst {worst:.6}, {over} lines over 0.01"
    );
    assert!(
        worst <= max_z,
        "{layer}: Z ≤ {max_z} on every line (worst {worst})"
    );
    (lines, points)
}

#[test]
fn training_lakes_get_one_smooth_centred_label_each() {
    // The bound: Z ≤ 0.01 on every line.
    let (lines, _) = check_layer(TRAIN, "lakes_scotland", 0.01);
    assert!(lines >= 15, "the lochs are long and narrow: lines");
}

#[test]
fn training_islands_get_one_label_each_lines_or_points() {
    // The bound on the ragged islands too (it held for 7 of 9 lines
    // before the smoothed runs went back towards the axis and the ends that
    // bend away within their last width were cut: 0.0156 and 0.0169).
    let (lines, points) = check_layer(TRAIN, "islands_hebrides", 0.01);
    assert!(
        lines > 0 && points > 0,
        "elongated islands get lines, round ones points"
    );
}

#[test]
fn a_crescent_lake_cut_at_its_sharp_bend_keeps_its_arc() {
    // GSHHG lake 3436 in UTM 15N: the axis turns by about 70° where the
    // horn meets the round bay at its west end, sharper than the corridor
    // lets the line round off. The gentle run along the arc keeps 63 % of
    // the axis and is long enough for its own corridor, not for the bay's
    // width: a line, not a point in the bay.
    assert_eq!(check_layer(BENDS, "crescent_lake", 0.01), (1, 0));
}

#[test]
fn a_lake_whose_relaxed_line_is_cut_keeps_the_smoothed_one() {
    // GSHHG lake 2116 as in the world lakes (Equal Earth): after relaxing
    // towards the axis one bend is too sharp, and the gentle run of the
    // relaxed line is too short for a line; the line as smoothed is gentle
    // enough, and is kept. Smoothed, not relaxed towards the axis, it is
    // less centred than the training lines: Z 0.026 (the 0.01 is
    // for those; 0.020 before the axis's south end followed the medial
    // axis into the round bay's west corner instead of a straight chord to
    // its south shore, which changed where the smoothed line bends), held
    // here to 0.03.
    assert_eq!(check_layer(BENDS, "bent_lake", 0.03), (1, 0));
}

/// The `label` step gets the raw medial axis the `skeleton` step made
/// (kept only for such a step, and only when MA has its default
/// options: otherwise the step makes its own), and labels from it as
/// from its own.
#[test]
fn the_skeleton_steps_medial_axis_is_kept_for_the_label_step_only() {
    use geo::polygon;
    use skeletonise::methods::medial_axis::{ArcTolerance, MedialAxisOptions};
    use skeletonise::methods::MethodId;
    use skeletonise::process::{process, ProcessParams, Processed};
    let long = polygon![(x: 0., y: 0.), (x: 40., y: 0.), (x: 40., y: 4.), (x: 0., y: 4.)];
    let label = skeletonise::process::step::Extra {
        entry: skeletonise::label::ENTRY,
        options: serde_json::Value::Null,
        step: (skeletonise::label::ENTRY.build)(&serde_json::Value::Null).unwrap(),
        side: None,
    };
    let kept = |params: &ProcessParams| -> usize {
        let Processed::Done(o) = process(Some(&Geometry::Polygon(long.clone())), params) else {
            panic!("processed");
        };
        let ma = o
            .candidates
            .iter()
            .find(|c| c.method == MethodId::MA)
            .unwrap();
        ma.result.as_ref().unwrap().raw.len()
    };
    let mut params = ProcessParams::all_steps();
    assert_eq!(kept(&params), 0, "no step reads it: not kept");
    params.extra = vec![label];
    assert_eq!(kept(&params), 1, "kept for the label step");
    let Processed::Done(o) = process(Some(&Geometry::Polygon(long.clone())), &params) else {
        panic!("processed");
    };
    let own = skeletonise::label::LabelParams::default()
        .label(&skeletonise::geometry::PreparedPolygon::new(&long).unwrap())
        .unwrap();
    let Some((_, row)) = o.extra.first() else {
        panic!("a label row");
    };
    assert_eq!(
        row.geometry,
        Some(match own.label {
            skeletonise::label::Label::Line(l) => Geometry::LineString(l),
            skeletonise::label::Label::Point(c) => Geometry::Point(c.into()),
        }),
        "the label from the kept axis is the library's own"
    );
    params.skeleton.medial_axis = MedialAxisOptions {
        arc_tolerance: ArcTolerance::Relative(0.01),
    };
    assert_eq!(kept(&params), 0, "another MA: the step makes its own");
}

#[test]
fn exploded_labels_have_one_polygon_part_column_the_steps_own() {
    // The label step numbers the parts itself (`polygon_part`); with
    // `explode` the column the per-feature path adds to a layer of the
    // features is not added twice, and merged polygons add `members`.
    let d = crate::common::tmp();
    let out = d.path().join("exploded.gpkg");
    let o = skeletonise(&[
        "run",
        &root("pipelines/lake-labels.yaml"),
        "--set",
        "output.explode=true",
        "--set",
        "input.merge_adjacent=true",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    let ds = crate::common::open(&out);
    let l = ds.layer_by_name("labels").unwrap();
    let names: Vec<String> = l.defn().fields().map(|f| f.name()).collect();
    let count = |n: &str| names.iter().filter(|x| x.as_str() == n).count();
    assert_eq!(
        (count("polygon_part"), count("members")),
        (1, 1),
        "{names:?}"
    );
}
