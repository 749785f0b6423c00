//! Fuzzing the per-feature path: random polygons with holes — star shapes
//! with spikes, duplicate and collinear vertices, huge offsets and tiny
//! scales — through every method and every step in every mode. Whatever
//! comes in, the result is a skeleton, a rejection with a reason or a
//! filtered feature; never a panic, an empty chosen skeleton, a point
//! outside the polygon, two crossing pieces or a distortion outside [0, 1].
//!
//! `tests/data/fuzz-seeds.wkt` holds the seed corpus (one WKT polygon per
//! line), always run first. The number of random cases is
//! `PROPTEST_CASES` (default 48): `PROPTEST_CASES=200000 cargo test --release
//! --test all fuzz::` is the long run.

use geo::{Coord, Geometry, LineString, Polygon};
use proptest::prelude::*;
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::extend::{prune_and_extend, ExtendMode, ExtendParams};
use skeletonise::graph::planar::crossings;
use skeletonise::graph::prune::{PruneMode, PruneParams, Structure};
use skeletonise::graph::SkeletonGraph;
use skeletonise::methods::{build, MethodContext, MethodId};
use skeletonise::process::{process, CandidateError, ProcessParams, Processed};

/// The steps in one of their modes.
fn params(prune: usize, extend: usize, shared: bool) -> ProcessParams {
    let mut p = ProcessParams::all_steps();
    p.keep_bars = true;
    p.keep_widths = true;
    p.prune = Some(PruneParams {
        mode: [
            PruneMode::Significance,
            PruneMode::Trunk,
            PruneMode::Length,
            PruneMode::None,
        ][prune % 4],
        structure: if shared {
            Structure::Shared
        } else {
            Structure::Independent
        },
        min_length: 1.0,
        ..PruneParams::default()
    });
    p.extend = Some(ExtendParams {
        mode: [
            ExtendMode::Centred,
            ExtendMode::Ray,
            ExtendMode::Nearest,
            ExtendMode::None,
        ][extend % 4],
    });
    p
}

/// Checks one outcome; `Err` with what is wrong.
fn check(geom: &Geometry<f64>, p: &ProcessParams) -> Result<(), String> {
    let r = std::panic::catch_unwind(|| process(Some(geom), p))
        .map_err(|_| "process panicked".to_string())?;
    match r {
        Processed::Filtered => Ok(()),
        Processed::Rejected(reason) if reason.contains("internal error") => Err(reason),
        Processed::Rejected(reason) if !reason.trim().is_empty() => Ok(()),
        Processed::Rejected(_) => Err("rejected without a reason".into()),
        Processed::Done(o) => {
            let (_, chosen) = o.chosen();
            if chosen.geometry.0.is_empty() {
                return Err("an empty skeleton was chosen".into());
            }
            let Geometry::Polygon(poly) = geom else {
                return Ok(());
            };
            let pp = PreparedPolygon::new(poly).map_err(|e| e.to_string())?;
            check_graphs(&pp, p)?;
            let tol = 1e-6 * pp.extent();
            for c in &o.candidates {
                let s = match &c.result {
                    Err(e @ CandidateError::Internal { .. }) => return Err(e.to_string()),
                    Err(_) => continue,
                    Ok(s) => s,
                };
                for l in &s.geometry.0 {
                    for &q in &l.0 {
                        if !pp.boundary().contains_with_tolerance(q, tol) {
                            return Err(format!("{}: point {q:?} outside the polygon", c.method));
                        }
                    }
                }
                let lines = SkeletonGraph::from_lines(&s.geometry);
                lines
                    .check_invariants()
                    .map_err(|e| format!("{}'s lines: {e}", c.method))?;
                if crossings(&lines) > 0 {
                    return Err(format!("{}: pieces cross", c.method));
                }
                if let Some(sc) = s.scores {
                    if sc.hits > 0 && !(0.0..=1.0 + 1e-9).contains(&sc.distortion) {
                        return Err(format!("{}: distortion {}", c.method, sc.distortion));
                    }
                }
            }
            Ok(())
        }
    }
}

/// Every built-in method's raw skeleton of `pp`, and that skeleton pruned
/// and extended as `p` asks, keep the graph's invariants.
fn check_graphs(pp: &PreparedPolygon, p: &ProcessParams) -> Result<(), String> {
    for id in MethodId::builtin() {
        let method = build(id, &p.skeleton);
        let raw = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            method.skeletonise(pp, &MethodContext::default())
        }))
        .map_err(|_| format!("{id} panicked"))?;
        let Ok(raw) = raw else { continue };
        raw.check_invariants()
            .map_err(|e| format!("{id}'s raw skeleton: {e}"))?;
        let g = prune_and_extend(&raw, pp, p.prune.as_ref(), p.extend.as_ref());
        g.check_invariants()
            .map_err(|e| format!("{id}'s pruned and extended skeleton: {e}"))?;
    }
    Ok(())
}

/// A star polygon around `centre` with radii `radii` (a spike where a
/// radius is far above its neighbours), vertices repeated where `dup`.
fn star(centre: Coord<f64>, radii: &[f64], dup: &[bool], scale: f64) -> LineString<f64> {
    let n = radii.len();
    let mut v = Vec::with_capacity(2 * n + 1);
    for (i, &r) in radii.iter().enumerate() {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        let p = Coord {
            x: centre.x + scale * r * a.cos(),
            y: centre.y + scale * r * a.sin(),
        };
        v.push(p);
        if dup.get(i).copied().unwrap_or(false) {
            v.push(p);
        }
    }
    v.push(v[0]);
    LineString(v)
}

fn polygon_strategy() -> impl Strategy<Value = Polygon<f64>> {
    (
        prop::collection::vec(0.3f64..1.0, 3..48),
        prop::collection::vec(any::<bool>(), 48),
        prop::collection::vec(
            (
                0.0f64..1.0,
                0.0f64..1.0,
                prop::collection::vec(0.5f64..1.0, 3..9),
            ),
            0..4,
        ),
        prop_oneof![Just(1.0), Just(1e-3), Just(1e3)],
        prop_oneof![Just(0.0), Just(1e7)],
        any::<bool>(),
    )
        .prop_map(|(mut radii, dup, holes, scale, offset, spike)| {
            if spike {
                let k = radii.len() / 2;
                radii[k] = 3.0;
            }
            let dup: Vec<bool> = dup.iter().map(|&d| d && radii.len() % 5 == 0).collect();
            let c = Coord {
                x: offset,
                y: offset,
            };
            let exterior = star(c, &radii, &dup, scale * 100.0);
            let min_r = radii.iter().copied().fold(f64::INFINITY, f64::min);
            // Holes inside the disc every exterior vertex lies outside of,
            // on distinct rings of angles so that they never overlap.
            let k = holes.len().max(1) as f64;
            let interiors = holes
                .iter()
                .enumerate()
                .map(|(i, (fa, fr, hr))| {
                    let a = std::f64::consts::TAU * (i as f64 + 0.5 * fa) / k;
                    let room = 0.25 * min_r * (std::f64::consts::PI / k).sin().min(1.0);
                    let d = (0.3 + 0.3 * fr) * min_r;
                    let hc = Coord {
                        x: c.x + scale * 100.0 * d * a.cos(),
                        y: c.y + scale * 100.0 * d * a.sin(),
                    };
                    star(hc, hr, &[], scale * 100.0 * room * 0.9)
                })
                .collect();
            Polygon::new(exterior, interiors)
        })
}

#[test]
fn the_seed_corpus_goes_through_every_mode() {
    let text = std::fs::read_to_string(crate::common::root("tests/data/fuzz-seeds.wkt")).unwrap();
    let mut n = 0;
    for line in text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
    {
        let g: Geometry<f64> = wkt::TryFromWkt::try_from_wkt_str(line)
            .unwrap_or_else(|e| panic!("seed `{line}`: {e}"));
        for (prune, extend, shared) in [
            (0, 0, true),
            (1, 0, true),
            (0, 1, false),
            (2, 2, true),
            (3, 3, false),
        ] {
            if let Err(e) = check(&g, &params(prune, extend, shared)) {
                panic!("seed `{line}` (prune {prune}, extend {extend}, shared {shared}): {e}");
            }
        }
        n += 1;
    }
    assert!(n >= 10, "{n} seeds");
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(48),
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_polygons_with_holes_never_break_a_step(
        p in polygon_strategy(),
        prune in 0usize..4,
        extend in 0usize..4,
        shared in any::<bool>(),
    ) {
        let g = Geometry::Polygon(p);
        if let Err(e) = check(&g, &params(prune, extend, shared)) {
            prop_assert!(false, "{e}: {:?}", g);
        }
    }
}

/// The `collapse` step on one polygon at `fraction` of its extent: no panic,
/// kept areas inside the polygon and no larger than it, lines inside it.
fn check_collapse(poly: &Polygon<f64>, fraction: f64) -> Result<(), String> {
    use geo::Area;
    let pp = PreparedPolygon::new(poly).map_err(|e| e.to_string())?;
    let mut p = ProcessParams::all_steps();
    p.collapse = Some(skeletonise::collapse::CollapseParams::new(
        fraction * pp.extent(),
    ));
    let g = Geometry::Polygon(poly.clone());
    let r = std::panic::catch_unwind(|| process(Some(&g), &p))
        .map_err(|_| "process panicked".to_string())?;
    let Processed::Done(o) = r else {
        return Ok(());
    };
    let tol = 1e-6 * pp.extent();
    let parts = o.collapse.ok_or("no collapse")?;
    let area: f64 = parts
        .iter()
        .flat_map(|c| &c.areas)
        .map(|a| a.polygon.unsigned_area())
        .sum();
    if area > poly.unsigned_area() * (1.0 + 1e-6) {
        return Err(format!(
            "areas {area} exceed the polygon {}",
            poly.unsigned_area()
        ));
    }
    for c in &parts {
        let points = c
            .areas
            .iter()
            .flat_map(|a| a.polygon.exterior().0.iter())
            .chain(c.collapsed.iter().chain(&c.kept).flat_map(|l| l.0.iter()));
        for &q in points {
            if !pp.boundary().contains_with_tolerance(q, tol) {
                return Err(format!("point {q:?} outside the polygon"));
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(48),
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_polygons_with_holes_collapse_without_breaking(
        p in polygon_strategy(),
        fraction in prop::sample::select(vec![0.01, 0.05, 0.2, 0.6]),
    ) {
        if let Err(e) = check_collapse(&p, fraction) {
            prop_assert!(false, "{e} (width {fraction} × extent): {:?}", p);
        }
    }
}
