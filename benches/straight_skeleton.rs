//! Criterion benchmark of the straight skeleton (StSk) on training polygons.

use criterion::{criterion_group, criterion_main, Criterion};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::methods::straight_skeleton::StraightSkeleton;
use skeletonise::methods::MethodContext;
use skeletonise::methods::SkeletonMethod;

fn layer(name: &str) -> Vec<PreparedPolygon> {
    skeletonise::io::read_layer_polygons("tests/data/gshhg-train.gpkg", name)
        .unwrap_or_default()
        .into_iter()
        .flat_map(|(_, g)| match g {
            geo::Geometry::Polygon(p) => vec![p],
            geo::Geometry::MultiPolygon(m) => m.0,
            _ => Vec::new(),
        })
        .filter_map(|p| PreparedPolygon::new(&p).ok())
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("stsk");
    g.sample_size(10);
    for name in ["river_st_lawrence", "river_lena", "islands_hebrides"] {
        let polys = layer(name);
        g.bench_function(name, |b| {
            b.iter(|| {
                polys
                    .iter()
                    .filter(|p| {
                        StraightSkeleton
                            .skeletonise(p, &MethodContext::default())
                            .is_ok()
                    })
                    .count()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
