//! `VD` and `DVD` (factor 4, the paper's density) on two real layers, one
//! thread, every polygon part of the layer per iteration.
//!
//! `cargo bench --bench voronoi`

use criterion::{criterion_group, criterion_main, Criterion};
use skeletonise::geometry::{densify::Density, PreparedPolygon};
use skeletonise::io::read_layer_polygons;
use skeletonise::methods::MethodContext;
use skeletonise::methods::{voronoi::Voronoi, SkeletonMethod};
use skeletonise::process::polygon_parts;
use std::hint::black_box;
use std::time::Duration;

const TRAIN: &str = "tests/data/gshhg-train.gpkg";

fn parts(layer: &str) -> Vec<PreparedPolygon> {
    read_layer_polygons(TRAIN, layer)
        .expect("the training data beside the work tree")
        .iter()
        .flat_map(|(_, g)| polygon_parts(Some(g)).unwrap_or_default())
        .filter_map(|p| PreparedPolygon::new(&p).ok())
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("voronoi");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for layer in ["river_lena", "islands_hebrides"] {
        let parts = parts(layer);
        for (name, m) in [
            ("VD", Voronoi::plain()),
            (
                "DVD-factor4",
                Voronoi::densified(Density::Factor(4), 2_000_000),
            ),
        ] {
            group.bench_function(format!("{name}/{layer}"), |b| {
                b.iter(|| {
                    for p in &parts {
                        black_box(
                            m.skeletonise(black_box(p), &MethodContext::default())
                                .unwrap(),
                        );
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
