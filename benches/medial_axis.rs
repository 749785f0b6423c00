//! Method MA on the training layers (serial over the polygons of a layer), the
//! arc discretisation cost on a shape dominated by parabolic arcs, and the
//! `label` step's labels (which make their own medial axis) of the training
//! lochs and islands.
//!
//! `cargo bench --bench medial_axis`; the side-by-side comparison with PostGIS
//! is `scripts/bench-ma.sh`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::methods::medial_axis::{ArcTolerance, MedialAxis};
use skeletonise::methods::MethodContext;
use skeletonise::methods::SkeletonMethod;
use std::time::Duration;

const TRAIN: &str = "tests/data/gshhg-train.gpkg";

fn layer(name: &str) -> Vec<PreparedPolygon> {
    skeletonise::io::read_layer_polygons(TRAIN, name)
        .expect("training data (run from the crate root)")
        .iter()
        .flat_map(|(_, g)| skeletonise::process::polygon_parts(Some(g)).unwrap_or_default())
        .filter_map(|p| PreparedPolygon::new(&p).ok())
        .collect()
}

fn layers(c: &mut Criterion) {
    let mut group = c.benchmark_group("ma_layer");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let method = MedialAxis::default();
    for name in [
        "river_danube",
        "river_st_lawrence",
        "river_lena",
        "islands_hebrides",
    ] {
        let polys = layer(name);
        let vertices: usize = polys.iter().map(|p| p.vertex_count()).sum();
        group.throughput(Throughput::Elements(vertices as u64));
        group.bench_with_input(BenchmarkId::from_parameter(name), &polys, |b, polys| {
            b.iter(|| {
                for p in polys {
                    black_box(method.skeletonise(p, &MethodContext::default()).unwrap());
                }
            })
        });
    }
    group.finish();
}

/// A comb: many reflex vertices, so most of the axis is parabolic arcs.
fn comb(teeth: usize) -> PreparedPolygon {
    let mut ring = vec![(0.0, 0.0)];
    for i in 0..teeth {
        let x = i as f64 * 3.0;
        ring.extend([
            (x + 1.0, 0.0),
            (x + 1.0, -10.0),
            (x + 2.0, -10.0),
            (x + 2.0, 0.0),
        ]);
    }
    let w = teeth as f64 * 3.0;
    ring.extend([(w, 0.0), (w, 5.0), (0.0, 5.0)]);
    PreparedPolygon::new(&geo::Polygon::new(geo::LineString::from(ring), vec![])).unwrap()
}

fn arcs(c: &mut Criterion) {
    let mut group = c.benchmark_group("ma_arc_tolerance");
    let p = comb(200);
    for (label, tol) in [
        ("relative_0.1", ArcTolerance::Relative(0.1)),
        ("relative_0.01", ArcTolerance::Relative(0.01)),
        ("relative_0.001", ArcTolerance::Relative(0.001)),
    ] {
        let method = MedialAxis::new(tol);
        group.bench_function(label, |b| {
            b.iter(|| black_box(method.skeletonise(&p, &MethodContext::default()).unwrap()))
        });
    }
    group.finish();
}

/// One label per polygon part, as `skeletonise.labels` makes them: the
/// medial axis, its pruning and extension, and the label line or point.
fn labels(c: &mut Criterion) {
    let mut group = c.benchmark_group("labels");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let params = skeletonise::label::LabelParams::default();
    for name in ["lakes_scotland", "islands_hebrides"] {
        let polys = layer(name);
        group.throughput(Throughput::Elements(polys.len() as u64));
        group.bench_with_input(BenchmarkId::from_parameter(name), &polys, |b, polys| {
            b.iter(|| {
                for p in polys {
                    black_box(params.label(p));
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, layers, arcs, labels);
criterion_main!(benches);
