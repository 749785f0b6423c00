use skeletonise::geometry::PreparedPolygon;
use skeletonise::methods::{build, MethodId, SkeletonParams};
use std::time::Instant;
fn main() {
    let n = 1_000_000usize;
    let pts: Vec<geo::Coord<f64>> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 1000.0 + 30.0 * (t * 50.0).sin() + 5.0 * (t * 3000.0).sin();
            geo::Coord {
                x: 5e6 + r * 3.0 * t.cos(),
                y: 6e6 + r * t.sin(),
            }
        })
        .collect();
    let p = geo::Polygon::new(geo::LineString(pts), vec![]);
    let t = Instant::now();
    let pp = PreparedPolygon::new(&p).unwrap();
    println!("prepare {:?}", t.elapsed());
    let t = Instant::now();
    println!(
        "valid {:?} {:?}",
        skeletonise::geometry::validity::problem(&pp),
        t.elapsed()
    );
    for m in [
        MethodId::Cdt,
        MethodId::Vd,
        MethodId::Ma,
        MethodId::StSk,
        MethodId::Dvd,
    ] {
        let t = Instant::now();
        let r = build(m, &SkeletonParams::default()).skeletonise(&pp);
        println!(
            "{m} {:?} {:?}",
            r.map(|g| g.edges().len()).map_err(|e| e.to_string()),
            t.elapsed()
        );
    }
}
