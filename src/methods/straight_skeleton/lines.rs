//! The original edges, indexed for the split-candidate search.
//!
//! A reflex vertex's band (a stretch of its ray) takes its split candidates
//! from the edges whose boxes meet a box around that stretch
//! ([`LineIndex::near`]). On a rim of needles the box of a long band holds
//! hundreds to thousands of live edges, and nearly all of them fail the
//! candidate test of [`super::events::split_candidates`]: more than half move
//! away from the vertex as fast as it comes (a fast vertex outruns every line
//! whose normal points within about 90° of its direction), and most of the
//! others are reached only after the band's last time. That test asks of a
//! line with unit normal `n` through `a` that `A = (start − a) · n` lie in
//! `[t0 − tol, t0 + (1 − n · vel) · (t_max − t0 + tol)]` — a condition on
//! the line's direction and its distance from the vertex's start, not on
//! its place along the ray.
//!
//! So the edges are also kept in [`CLASSES`] trees by the direction of
//! their normals, each in its own frame (`u` along the class's middle
//! normal, `v` across it). [`LineIndex::near_ray`] skips a class whose
//! normals all outrun the vertex, and in the others skips a node whose
//! edges all have `A` out of that interval for every normal of the class
//! (a bound from the node's box), before the box test of [`LineIndex::near`].
//! A class's frame is turned to the middle of its edges' normals and its
//! width is the angle they span, so the classes of a pixel staircase (four
//! directions) have no width and their bounds are tight. `near_ray` returns
//! every edge `near` returns that can pass the candidate test — the same
//! candidates, so the same skeleton. The bounds are widened by the
//! tolerance, so rounding cannot drop a candidate. When a band's box holds
//! few edges ([`FEW_NEAR`]) the one tree's answer is taken as it is; that
//! count is made only until a vertex's band holds many, since its next
//! band's box holds that band's (the count cost as much as the search by
//! direction itself: without it StSk takes 0.84× the time on the rough
//! polygon at 200 000 vertices, 0.88× at 100 000).
//!
//! On the rough polygon of `scripts/make_rough_polygon.py` the edges tried
//! fall from 40.5 M to 11.1 M at 100 000 vertices and from 161 M to 22.8 M
//! at 200 000, and the straight skeleton takes 0.6–0.75× the time; smooth
//! polygons have few edges near their bands and are searched as before.

use super::segment_box;
use super::wavefront::{Line, LineId};
use crate::geometry::packed::{boxes_meet, Bbox, PackedTree};
use crate::geometry::vector::{cross, dot, hypot};
use geo::Coord;
use std::cell::OnceCell;
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// Direction classes of the edges' normals (each `2π / CLASSES` wide).
const CLASSES: usize = 32;

/// Up to this many edges near a band are taken from the one tree: the
/// search by direction visits every class's tree, which costs more than
/// it saves when few edges are near (the 6 660 GSHHG lakes took 10 % longer
/// with a quarter of this, and the rough polygon at 200 000 vertices 20 %
/// longer with four times it).
const FEW_NEAR: usize = 256;

/// Radians added to the angle a class's normals span: far more than the
/// rounding of `atan2`, `cos` and `sin` (about 1e-16).
const ANGLE_SLACK: f64 = 1e-9;

/// The part of a reflex vertex's ray one band searches: the vertex starts
/// at `start` at time `t0` with velocity `vel` and the band ends at time
/// `t_max`.
#[derive(Debug, Clone, Copy)]
pub struct Band {
    /// The vertex's position at `t0`.
    pub start: Coord<f64>,
    /// The vertex's creation time.
    pub t0: f64,
    /// The vertex's velocity.
    pub vel: Coord<f64>,
    /// The latest time a candidate of the band may have.
    pub t_max: f64,
}

/// The edges of one direction class, in the class's frame.
#[derive(Debug, Default)]
struct Class {
    /// The middle of its edges' normals (`u` axis); `v` is across it.
    normal: Coord<f64>,
    /// The cosine and sine of the largest angle between an edge's normal
    /// and `normal` (widened for rounding): 0 when every edge of the class
    /// has one direction, as on a pixel staircase.
    cos_h: f64,
    sin_h: f64,
    /// Boxes of the edges in `(u, v)`.
    tree: PackedTree,
    /// Item `i` of `tree` is line `lines[i]`.
    lines: Vec<u32>,
}

impl Class {
    /// `p` in the class's frame.
    fn frame(&self, p: Coord<f64>) -> (f64, f64) {
        let n = self.normal;
        (n.x * p.x + n.y * p.y, n.x * p.y - n.y * p.x)
    }

    /// The fastest closing speed on a vertex moving along unit `dir` at
    /// `speed` of a line of the class (its normal furthest from the
    /// vertex's direction), widened for rounding.
    fn closing(&self, dir: Coord<f64>, speed: f64) -> f64 {
        let (cos_phi, sin_phi) = (dot(self.normal, dir), cross(self.normal, dir).abs());
        let worst = if cos_phi < -self.cos_h {
            -1.0
        } else {
            cos_phi * self.cos_h - sin_phi * self.sin_h
        };
        1.0 - speed * worst + 1e-9 * (1.0 + speed)
    }

    /// The box of `corners` in the class's frame, grown by `pad`.
    fn frame_box(&self, corners: &[Coord<f64>], pad: f64) -> Bbox {
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for &p in corners {
            let (u, v) = self.frame(p);
            b = [
                b[0].min(u - pad),
                b[1].min(v - pad),
                b[2].max(u + pad),
                b[3].max(v + pad),
            ];
        }
        b
    }
}

/// The original edges (line `i` is edge `i`), with removal.
#[derive(Debug, Default)]
pub struct LineIndex {
    /// Every edge's axis-aligned box.
    boxes: Vec<Bbox>,
    /// The tree over `boxes`.
    all: PackedTree,
    /// Each edge's position in `all` (`u32::MAX` once removed).
    all_pos: Vec<u32>,
    /// The edges by direction, built at the first [`LineIndex::near_ray`]
    /// (a polygon whose reflex vertices all end in their first bands never
    /// needs them).
    classes: OnceCell<Classes>,
}

/// The edges left in the wavefront by the direction of their normals.
#[derive(Debug)]
struct Classes {
    classes: Vec<Class>,
    /// Each edge's class and position in the class's tree (`u32::MAX` for
    /// an edge removed before the classes were built).
    pos: Vec<(u32, u32)>,
}

impl Classes {
    /// The classes of the edges of `lines` whose `all_pos` is not
    /// `u32::MAX` (not removed).
    fn new(lines: &[Line], all_pos: &[u32]) -> Self {
        let width = 2.0 * PI / CLASSES as f64;
        let angles: Vec<(usize, f64)> = lines
            .iter()
            .map(|l| {
                let theta = l.normal.y.atan2(l.normal.x);
                ((((theta + PI) / width) as usize).min(CLASSES - 1), theta)
            })
            .collect();
        let live = |i: usize| all_pos[i] != u32::MAX;
        let mut range = [(f64::INFINITY, f64::NEG_INFINITY); CLASSES];
        for (i, &(k, theta)) in angles.iter().enumerate() {
            if live(i) {
                range[k] = (range[k].0.min(theta), range[k].1.max(theta));
            }
        }
        let mut classes: Vec<Class> = range
            .iter()
            .map(|&(lo, hi)| {
                let (mid, half) = if lo <= hi {
                    (0.5 * (lo + hi), 0.5 * (hi - lo) + ANGLE_SLACK)
                } else {
                    (0.0, 0.0)
                };
                Class {
                    normal: Coord {
                        x: mid.cos(),
                        y: mid.sin(),
                    },
                    cos_h: half.cos(),
                    sin_h: half.sin(),
                    ..Class::default()
                }
            })
            .collect();
        let mut class_boxes: Vec<Vec<Bbox>> = vec![Vec::new(); CLASSES];
        let mut class_of = vec![(0, u32::MAX); lines.len()];
        for (i, (l, &(k, _))) in lines.iter().zip(&angles).enumerate() {
            if !live(i) {
                continue;
            }
            let c = &mut classes[k];
            let ((ua, va), (ub, vb)) = (c.frame(l.a), c.frame(l.b));
            class_of[i] = (k as u32, c.lines.len() as u32);
            c.lines.push(i as u32);
            class_boxes[k].push([ua.min(ub), va.min(vb), ua.max(ub), va.max(vb)]);
        }
        for (c, b) in classes.iter_mut().zip(&class_boxes) {
            c.tree = PackedTree::new(b);
        }
        let positions: Vec<Vec<u32>> = classes.iter().map(|c| c.tree.item_positions()).collect();
        let pos = class_of
            .into_iter()
            .map(|(k, i)| match i {
                u32::MAX => (k, i),
                i => (k, positions[k as usize][i as usize]),
            })
            .collect();
        Self { classes, pos }
    }
}

impl LineIndex {
    /// Indexes `lines` (each edge runs from its line's `a` to `b`).
    pub fn new(lines: &[Line]) -> Self {
        let boxes: Vec<Bbox> = lines.iter().map(|l| segment_box(l.a, l.b)).collect();
        let all = PackedTree::new(&boxes);
        Self {
            all_pos: all.item_positions(),
            all,
            boxes,
            classes: OnceCell::new(),
        }
    }

    /// Takes edge `l` out of every later search (once it has left the
    /// wavefront).
    pub fn remove(&mut self, l: LineId) {
        let pos = self.all_pos[l.index()];
        if pos == u32::MAX {
            return;
        }
        self.all.remove_at(pos as usize);
        self.all_pos[l.index()] = u32::MAX;
        if let Some(c) = self.classes.get_mut() {
            let (k, pos) = c.pos[l.index()];
            if pos != u32::MAX {
                c.classes[k as usize].tree.remove_at(pos as usize);
            }
        }
    }

    /// Appends to `out` every edge (not removed) whose box meets `env`.
    pub fn near(&self, env: &Bbox, out: &mut Vec<LineId>) {
        self.near_at_most(env, usize::MAX, out);
    }

    /// [`Self::near`] when it finds at most `cap` edges (`true`); else
    /// appends nothing and returns `false`.
    fn near_at_most(&self, env: &Bbox, cap: usize, out: &mut Vec<LineId>) -> bool {
        let before = out.len();
        let over = self.all.visit(
            |b| boxes_meet(b, env),
            |i| {
                if out.len() - before == cap {
                    return ControlFlow::Break(());
                }
                out.push(LineId::from_index(i as usize));
                ControlFlow::Continue(())
            },
        );
        if over.is_some() {
            out.truncate(before);
        }
        over.is_none()
    }

    /// Appends to `out` the edges of [`Self::near`] that can be split
    /// candidates of `band` (see the module's doc), with `tol` the
    /// candidate test's tolerance. The others can pass no candidate test,
    /// so the candidates found among `out` are those found among `near`'s.
    /// `lines` are the edges' lines, those the index was made of.
    ///
    /// Returns whether `env` held more than [`FEW_NEAR`] edges, so that the
    /// search went by direction. With `dense` (a box within `env` held that
    /// many: the vertex's band before) it goes by direction without
    /// counting them first.
    pub fn near_ray(
        &self,
        lines: &[Line],
        env: &Bbox,
        band: &Band,
        tol: f64,
        dense: bool,
        out: &mut Vec<LineId>,
    ) -> bool {
        let speed = hypot(band.vel);
        if speed.is_nan() || speed <= 0.0 {
            self.near(env, out);
            return false;
        }
        // Few edges near: the one tree's answer costs less than a search
        // of every class.
        if !dense && self.near_at_most(env, FEW_NEAR, out) {
            return false;
        }
        let classes = &self
            .classes
            .get_or_init(|| Classes::new(lines, &self.all_pos))
            .classes;
        let dir = band.vel / speed;
        let corners = [(0, 1), (2, 1), (0, 3), (2, 3)].map(|(i, j)| Coord {
            x: env[i],
            y: env[j],
        });
        // Distances from the start within `pad` are rounding.
        let pad = 4.0 * tol;
        let lo = band.t0 - tol - pad;
        let span = band.t_max - band.t0 + tol;
        for c in classes {
            if c.tree.len() == 0 {
                continue;
            }
            let closing = c.closing(dir, speed);
            if closing <= 1e-12 {
                continue;
            }
            let hi = band.t0 + closing * span + pad;
            let (us, vs) = c.frame(band.start);
            let (cos_h, sin_h) = (c.cos_h, c.sin_h);
            let frame_env = c.frame_box(&corners, pad);
            c.tree.visit(
                |b| {
                    if !boxes_meet(b, &frame_env) {
                        return false;
                    }
                    // `A` of an edge through a point of the box, for any
                    // normal within `half` of the class's: `du cos ε + dv sin ε`.
                    let (du_lo, du_hi) = (us - b[2], us - b[0]);
                    let dv = (vs - b[1]).abs().max((vs - b[3]).abs());
                    let a_min = du_lo.min(du_lo * cos_h) - dv * sin_h;
                    let a_max = du_hi.max(du_hi * cos_h) + dv * sin_h;
                    a_max >= lo && a_min <= hi
                },
                |i| {
                    let l = c.lines[i as usize] as usize;
                    if boxes_meet(&self.boxes[l], env) {
                        out.push(LineId::from_index(l));
                    }
                    ControlFlow::<()>::Continue(())
                },
            );
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::straight_skeleton::events::split_candidates;
    use crate::methods::straight_skeleton::wavefront::Wavefront;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// `n` vertices around the origin, counter-clockwise, vertex `i` at
    /// radius `r(i)`.
    fn jagged(n: usize, r: impl Fn(usize) -> f64) -> Vec<Coord<f64>> {
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * 2.0 * PI;
                c(r(i) * t.cos(), r(i) * t.sin())
            })
            .collect()
    }

    /// The wavefront of the ring through `pts`, one line per edge, and the
    /// index of its edges.
    fn ring_wavefront(pts: &[Coord<f64>]) -> (Wavefront, LineIndex) {
        let n = pts.len();
        let mut w = Wavefront::default();
        for i in 0..n {
            w.lines.push(Line::new(pts[i], pts[(i + 1) % n]));
            w.pieces.push(Vec::new());
        }
        let index = LineIndex::new(&w.lines);
        (w, index)
    }

    /// Edges in every direction around a fast vertex: the edges of
    /// `near_ray` are a subset of `near`'s, and both give the same split
    /// candidates.
    #[test]
    fn the_ray_search_finds_the_same_candidates_among_fewer_edges() {
        // A ring of short edges: a jagged circle of radius 100.
        let n = 720;
        let pts = jagged(n, |i| 100.0 + if i % 2 == 0 { 0.0 } else { 7.0 });
        let (mut w, index) = ring_wavefront(&pts);
        let mut fewer = 0;
        for (k, speed) in [(0usize, 1.5), (5, 40.0), (77, 3.0), (301, 400.0)] {
            for angle in [0.3, 1.9, 3.5, 5.0] {
                let vel = c(speed * f64::cos(angle), speed * f64::sin(angle));
                let left = LineId::from_index((k + n - 1) % n);
                let right = LineId::from_index(k);
                let v = w.add_vertex(pts[k] * 0.5, 0.25, left, right, None);
                w.v_mut(v).vel = Some(vel);
                let band = Band {
                    start: pts[k] * 0.5,
                    t0: 0.25,
                    vel,
                    t_max: 0.25 + 150.0 / speed,
                };
                let env = [-120.0, -120.0, 120.0, 120.0];
                let (mut all, mut ray) = (Vec::new(), Vec::new());
                index.near(&env, &mut all);
                assert!(index.near_ray(&w.lines, &env, &band, 1e-7, false, &mut ray));
                assert!(ray.iter().all(|l| all.contains(l)));
                let of = |lines: &[LineId]| {
                    split_candidates(&w, v, lines.iter().copied(), band.t_max, 1e-7, None)
                };
                let expected = of(&all);
                assert!(!expected.is_empty());
                assert_eq!(of(&ray), expected);
                fewer += usize::from(ray.len() < all.len() / 2);
            }
        }
        // A fast vertex outruns the lines behind it at least.
        assert!(fewer >= 8, "{fewer}");
    }

    /// A band known to be dense is searched by direction even when its box
    /// holds few edges (they were removed since), with the same candidates.
    #[test]
    fn a_band_known_dense_finds_the_same_candidates() {
        let n = 400;
        let pts = jagged(n, |i| 60.0 + if i % 2 == 0 { 0.0 } else { 4.0 });
        let (mut w, index) = ring_wavefront(&pts);
        let (left, right) = (LineId::from_index(n - 1), LineId::from_index(0));
        let vel = c(-30.0, 2.0);
        let v = w.add_vertex(pts[0] * 0.9, 0.1, left, right, None);
        w.v_mut(v).vel = Some(vel);
        let band = Band {
            start: pts[0] * 0.9,
            t0: 0.1,
            vel,
            t_max: 0.1 + 100.0 / hypot(vel),
        };
        // A box around a few edges, and one around all of them.
        for (env, many) in [
            ([50.0, -6.0, 70.0, 6.0], false),
            ([-70.0, -70.0, 70.0, 70.0], true),
        ] {
            let (mut all, mut counted, mut known) = (Vec::new(), Vec::new(), Vec::new());
            index.near(&env, &mut all);
            assert_eq!(all.len() > FEW_NEAR, many);
            assert_eq!(
                index.near_ray(&w.lines, &env, &band, 1e-7, false, &mut counted),
                many
            );
            assert!(index.near_ray(&w.lines, &env, &band, 1e-7, true, &mut known));
            assert!(known.iter().all(|l| all.contains(l)));
            let of = |lines: &[LineId]| {
                split_candidates(&w, v, lines.iter().copied(), band.t_max, 1e-7, None)
            };
            assert_eq!(of(&known), of(&all));
            assert_eq!(of(&counted), of(&all));
        }
    }

    #[test]
    fn a_removed_edge_is_found_by_neither_search() {
        let n = 600;
        let pts = jagged(n, |i| 50.0 + 3.0 * (i % 3) as f64);
        let lines: Vec<Line> = (0..n)
            .map(|i| Line::new(pts[i], pts[(i + 1) % n]))
            .collect();
        let mut index = LineIndex::new(&lines);
        let band = Band {
            start: c(0.0, 0.0),
            t0: 0.0,
            vel: c(0.0, -1.0),
            t_max: 100.0,
        };
        let env = [-60.0, -60.0, 60.0, 60.0];
        let search = |index: &LineIndex| {
            let (mut all, mut ray) = (Vec::new(), Vec::new());
            index.near(&env, &mut all);
            index.near_ray(&lines, &env, &band, 1e-9, false, &mut ray);
            (all, ray)
        };
        // Removed before the classes are built, and after.
        let (early, late) = (LineId::from_index(450), LineId::from_index(451));
        index.remove(early);
        let (all, ray) = search(&index);
        assert!(all.len() > FEW_NEAR && ray.contains(&late));
        index.remove(late);
        index.remove(late);
        let (all, ray) = search(&index);
        assert_eq!(all.len(), n - 2);
        for l in [early, late] {
            assert!(!all.contains(&l) && !ray.contains(&l));
        }
        // A vertex moving south at unit speed from the centre reaches the
        // southern edges, and outruns none.
        assert!(ray.contains(&LineId::from_index(449)) && ray.len() < all.len());
    }
}
