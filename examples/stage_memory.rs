//! Peak heap of each stage of one method on every polygon of a layer — the
//! prepared polygon, the raw skeleton (its peak, and what the graph keeps),
//! pruning and extension, then scoring — with pruning's per raw-skeleton
//! node and scoring's per boundary vertex: the figures behind the memory
//! budget's predictions (`skeleton.max_memory_mb`).
//!
//! ```text
//! cargo run --release --example stage_memory -- target/bench/rough-input-1000000.gpkg rough [MA|VD|CDT|DVD]
//! ```

use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::extend::{prune_and_extend, ExtendParams};
use skeletonise::graph::prune::PruneParams;
use skeletonise::methods::{MethodContext, MethodId, Registry, SkeletonParams};
use skeletonise::score::BarRays;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// The system allocator, counting the bytes live and their peak.
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let now = LIVE.fetch_add(l.size(), Relaxed) + l.size();
        PEAK.fetch_max(now, Relaxed);
        System.alloc(l)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        LIVE.fetch_sub(l.size(), Relaxed);
        System.dealloc(p, l)
    }
}

#[global_allocator]
static A: Counting = Counting;

/// Runs `f`; the peak heap it added above what was live before.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.load(Relaxed);
    PEAK.store(base, Relaxed);
    let t = f();
    (t, PEAK.load(Relaxed) - base)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: stage_memory <source> <layer> [METHOD]");
        std::process::exit(2);
    }
    let id: MethodId = args
        .get(3)
        .map_or("MA", String::as_str)
        .parse()
        .unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(2)
        });
    let feats = skeletonise::io::read_layer_polygons(&args[1], &args[2]).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let method = Registry::builtin()
        .build(id, &SkeletonParams::default())
        .unwrap_or_else(|| {
            eprintln!("method {id} is not registered");
            std::process::exit(1)
        });
    println!("vertices\tinput_MB\tskeleton_MB\traw_MB\tnodes\tfinished_nodes\tprune_s\tprune_MB\tprune_B_per_node\tscore_MB\tscore_B_per_vertex");
    for (_, g) in &feats {
        for p in skeletonise::process::polygon_parts(Some(g)).unwrap_or_default() {
            let (pp, input) = peak_of(|| PreparedPolygon::new(&p));
            let Ok(pp) = pp else {
                continue;
            };
            let live = LIVE.load(Relaxed);
            let (raw, skeleton) = peak_of(|| method.skeletonise(&pp, &MethodContext::default()));
            let Ok(raw) = raw else {
                continue;
            };
            let kept = LIVE.load(Relaxed) - live;
            let t = std::time::Instant::now();
            let (fin, prune) = peak_of(|| {
                prune_and_extend(
                    &raw,
                    &pp,
                    Some(&PruneParams::default()),
                    Some(&ExtendParams::default()),
                )
            });
            let prune_s = t.elapsed().as_secs_f64();
            eprintln!("legs raw {} finished {}", raw.leg_count(), fin.leg_count());
            let (_, score) = peak_of(|| {
                let rays = BarRays::new(&pp);
                rays.cast(&pp, &fin)
            });
            let (v, n) = (pp.vertex_count(), raw.nodes().len());
            println!(
                "{v}\t{:.1}\t{:.1}\t{:.1}\t{n}\t{}\t{prune_s:.2}\t{:.1}\t{:.0}\t{:.1}\t{:.0}",
                input as f64 / 1e6,
                skeleton as f64 / 1e6,
                kept as f64 / 1e6,
                fin.nodes().len(),
                prune as f64 / 1e6,
                prune as f64 / n.max(1) as f64,
                score as f64 / 1e6,
                score as f64 / v.max(1) as f64
            );
        }
    }
}
