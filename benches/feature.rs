//! The whole per-feature path (`process::process`: prepare, skeleton, prune,
//! extend, score, select) on one feature at a time: the fixed cost a small
//! polygon pays, which decides the speed of a layer of many small polygons and
//! of a Python call on one polygon.
//!
//! `cargo bench --bench feature`

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use geo::Geometry;
use skeletonise::config::load_steps_str;
use skeletonise::process::{process, ProcessParams};
use std::time::Duration;

const TRAIN: &str = "tests/data/gshhg-train.gpkg";

fn features(name: &str) -> Vec<Geometry<f64>> {
    skeletonise::io::read_layer_polygons(TRAIN, name)
        .expect("training data (run from the crate root)")
        .into_iter()
        .map(|(_, g)| g)
        .collect()
}

fn params(steps: &str) -> ProcessParams {
    load_steps_str(steps, "bench", &[])
        .expect("valid steps")
        .process_params()
}

fn per_feature(c: &mut Criterion) {
    let one = params(
        "steps:\n  - prepare: { make_valid: true }\n  - skeleton: { methods: [CDT] }\n  - prune: {}\n  - extend: {}\n",
    );
    let all = params(
        "steps:\n  - prepare: { make_valid: true }\n  - skeleton: {}\n  - prune: {}\n  - extend: {}\n  - score: {}\n  - select: {}\n",
    );
    let mut group = c.benchmark_group("feature");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(5));
    // The Danube: one river of 138 vertices; the first 50 Hebrides islands.
    let danube = features("river_danube");
    let islands: Vec<_> = features("islands_hebrides").into_iter().take(50).collect();
    for (layer, geoms) in [("river_danube", &danube), ("islands_hebrides_50", &islands)] {
        group.throughput(Throughput::Elements(geoms.len() as u64));
        for (steps, p) in [("CDT", &one), ("default", &all)] {
            group.bench_with_input(BenchmarkId::new(steps, layer), geoms, |b, geoms| {
                b.iter(|| {
                    for g in geoms {
                        black_box(process(Some(g), p));
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, per_feature);
criterion_main!(benches);
