//! The closed-form circle events (`pss_at_endpoint`: a polygon vertex and its
//! own edge; `pss_shared_vertex`: a vertex and two consecutive edges;
//! `pps_at_endpoint`: an edge, one of its vertices and another vertex;
//! `sss_chain`: three consecutive edges; the general `sss` in the frame at a
//! site's end point) against the general lazy/exact evaluation as published:
//! the diagrams of many polygons, built both ways, have the same vertices and
//! the same edges, and every closed form is exercised.

use super::lazy_circle_formation::{CLOSED_FORM_USES, ENDPOINT_FAST_PATH, GENERAL_SSS_EXACT};
use crate::builder::Builder;
use crate::diagram::Diagram;

/// A small deterministic generator (no dependency for the test).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 31) as f64
    }
}

/// A star-shaped ring of `n` vertices around the origin, radius `r` with
/// relative noise `noise`, on the integer grid.
fn ring(rng: &mut Lcg, n: usize, r: f64, noise: f64) -> Vec<[i32; 2]> {
    let mut pts: Vec<[i32; 2]> = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * (k as f64 + 0.3 * rng.unit()) / n as f64;
        let rr = r * (1.0 + noise * (rng.unit() - 0.5));
        let p = [(rr * a.cos()).round() as i32, (rr * a.sin()).round() as i32];
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    while pts.len() > 1 && pts.first() == pts.last() {
        let _ = pts.pop();
    }
    pts
}

/// A river-like band: two nearly parallel digitised banks.
fn band(rng: &mut Lcg, n: usize, len: f64, width: f64) -> Vec<[i32; 2]> {
    let bank = |rng: &mut Lcg, y: f64| -> Vec<[i32; 2]> {
        (0..n)
            .map(|k| {
                let x = len * k as f64 / (n - 1) as f64;
                let wobble = 0.05 * width * (rng.unit() - 0.5);
                [x.round() as i32, (y + wobble + 0.2 * width * (x / len * 7.0).sin()).round() as i32]
            })
            .collect()
    };
    let mut pts = bank(rng, 0.0);
    let mut top = bank(rng, width);
    top.reverse();
    pts.extend(top);
    pts.dedup();
    pts
}

fn diagram(pts: &[[i32; 2]], fast: bool) -> Diagram {
    ENDPOINT_FAST_PATH.with(|c| c.set(fast));
    let segs: Vec<[i32; 4]> = (0..pts.len())
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            [a[0], a[1], b[0], b[1]]
        })
        .collect();
    let d = Builder::<i32>::default()
        .with_segments(segs.iter())
        .and_then(|b| b.build())
        .expect("diagram");
    ENDPOINT_FAST_PATH.with(|c| c.set(true));
    d
}

/// The same diagram up to the numbering of its vertices: two circle events
/// whose keys are equal within rounding may be processed in either order,
/// which numbers their vertices the other way round. Every vertex of `a` is
/// matched to an unused vertex of `b` within 1e-9 relative, and the edges,
/// as (cell, start vertex, end vertex) under that matching, are the same.
fn same(a: &Diagram, b: &Diagram) -> Result<(), String> {
    if a.vertices().len() != b.vertices().len() || a.edges().len() != b.edges().len() {
        return Err(format!(
            "{} vertices / {} edges against {} / {}",
            a.vertices().len(),
            a.edges().len(),
            b.vertices().len(),
            b.edges().len()
        ));
    }
    let tol = |x: f64, y: f64| 1e-9 * (1.0 + x.abs().max(y.abs()));
    let mut by_x: Vec<usize> = (0..b.vertices().len()).collect();
    by_x.sort_by(|&i, &j| b.vertices()[i].x().total_cmp(&b.vertices()[j].x()));
    let mut used = vec![false; by_x.len()];
    let mut to_b = vec![0_usize; by_x.len()];
    for (i, u) in a.vertices().iter().enumerate() {
        let t = tol(u.x(), u.y());
        let from = by_x.partition_point(|&j| b.vertices()[j].x() < u.x() - t);
        let m = by_x[from..]
            .iter()
            .take_while(|&&j| b.vertices()[j].x() <= u.x() + t)
            .find(|&&j| !used[j] && (b.vertices()[j].y() - u.y()).abs() <= t)
            .ok_or_else(|| format!("vertex {i} ({}, {}) has no match", u.x(), u.y()))?;
        used[*m] = true;
        to_b[i] = *m;
    }
    let edges = |d: &Diagram, map: &dyn Fn(usize) -> usize| {
        let mut e: Vec<(usize, Option<usize>, Option<usize>)> = d
            .edges()
            .iter()
            .map(|e| {
                let end = e
                    .twin()
                    .ok()
                    .and_then(|t| d.edges()[t.0 as usize].vertex0());
                (
                    e.cell().map(|c| c.usize()).unwrap_or(usize::MAX),
                    e.vertex0().map(|v| map(v.usize())),
                    end.map(|v| map(v.usize())),
                )
            })
            .collect();
        e.sort_unstable();
        e
    };
    if edges(a, &|i| to_b[i]) != edges(b, &|i| i) {
        return Err("the edges differ".to_string());
    }
    Ok(())
}

#[test]
fn endpoint_circles_give_the_same_diagrams() {
    let mut rng = Lcg(0x5eed);
    let mut checked = 0;
    for case in 0..600 {
        let pts = match case % 6 {
            0 => ring(&mut rng, 8 + case % 40, 1.0e3, 0.5),
            1 => ring(&mut rng, 200, 3.0e7, 0.002),
            2 => band(&mut rng, 60, 2.0e6, 4.0e4),
            3 => band(&mut rng, 30, 5.0e3, 40.0),
            4 => far(band(&mut rng, 60, 2.0e6, 4.0e4)),
            _ => far(ring(&mut rng, 120, 1.0e5, 0.05)),
        };
        if pts.len() < 3 {
            continue;
        }
        let fast = diagram(&pts, true);
        let general = diagram(&pts, false);
        if let Err(e) = same(&fast, &general) {
            panic!("case {case} ({} points): {e}", pts.len());
        }
        checked += 1;
    }
    assert!(checked > 520);
    // Each closed form decided many events on its own (without the exact
    // evaluation), so the comparison above covers all five.
    let uses = CLOSED_FORM_USES.with(|c| c.get());
    assert!(uses.iter().all(|&n| n > 100), "closed-form uses {uses:?}");
}

/// Shapes far from the origin, as skeletonise's grid puts them (offset
/// 2^27): there the general sss formula's line offsets cancel most.
fn far(pts: Vec<[i32; 2]>) -> Vec<[i32; 2]> {
    pts.into_iter()
        .map(|[x, y]| [x + (1 << 27), y + (1 << 27)])
        .collect()
}

#[test]
fn local_frame_keeps_far_sss_events_out_of_the_exact_evaluation() {
    let mut rng = Lcg(0xba2d);
    let bands: Vec<Vec<[i32; 2]>> = (0..20).map(|_| far(band(&mut rng, 60, 2.0e6, 4.0e4))).collect();
    let exact = |fast: bool| {
        GENERAL_SSS_EXACT.with(|c| c.set(0));
        for pts in &bands {
            let _ = diagram(pts, fast);
        }
        GENERAL_SSS_EXACT.with(|c| c.get())
    };
    let (published, local) = (exact(false), exact(true));
    assert!(published > 100, "the general path as published: {published} exact evaluations");
    assert!(local * 4 < published, "local frame: {local} exact evaluations against {published}");
}
