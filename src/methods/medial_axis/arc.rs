//! Polyline approximation of a parabolic Voronoi edge.
//!
//! The edge between a point site `p` and a segment site `ab` is part of the
//! parabola of points equidistant from `p` and the line through `ab`. In the
//! frame with origin `a`, x-axis along `ab` and y-axis towards `p`, with `p` at
//! `(px, py)`, `py > 0`, it is the graph of
//!
//! ```text
//! f(x) = ((x − px)² + py²) / (2 py)
//! ```
//!
//! and `f(x)` is also the disc radius there. A chord over `[x₀, x₁]` deviates
//! from the arc by at most the largest vertical gap, `(x₁ − x₀)² f'' / 8 =
//! (x₁ − x₀)² / (8 py)` (a quadratic's chord gap peaks at the midpoint), and
//! the Hausdorff distance between chord and arc is at most that gap. Pieces are
//! halved until this bound is within the tolerance, evaluated at the smallest
//! radius on the piece, so the bound holds for every piece by construction.

/// A sample of the arc: grid-frame position and disc radius (grid units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Sample {
    pub x: f64,
    pub y: f64,
    pub r: f64,
}

/// Most halvings of one piece: far beyond what any tolerance ≥ the floor needs,
/// a guard against non-finite input only.
const MAX_DEPTH: usize = 64;

/// The parabola of points equidistant from a point and a line, in the frame of
/// the line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Parabola {
    origin: [f64; 2],
    u: [f64; 2],
    n: [f64; 2],
    px: f64,
    py: f64,
}

impl Parabola {
    /// The parabola with focus `p` and directrix the line through `a` and `b`;
    /// `None` when `p` lies on that line (no curved edge there).
    pub fn new(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<Self> {
        let d = [b[0] - a[0], b[1] - a[1]];
        let l = d[0].hypot(d[1]);
        if !l.is_finite() || l == 0.0 {
            return None;
        }
        let u = [d[0] / l, d[1] / l];
        let mut n = [-u[1], u[0]];
        let w = [p[0] - a[0], p[1] - a[1]];
        let px = w[0] * u[0] + w[1] * u[1];
        let mut py = w[0] * n[0] + w[1] * n[1];
        if py < 0.0 {
            n = [-n[0], -n[1]];
            py = -py;
        }
        (py > 0.0).then_some(Self {
            origin: a,
            u,
            n,
            px,
            py,
        })
    }

    /// Abscissa of a point in the line's frame.
    pub fn abscissa(&self, q: [f64; 2]) -> f64 {
        (q[0] - self.origin[0]) * self.u[0] + (q[1] - self.origin[1]) * self.u[1]
    }

    /// Height of the parabola (= disc radius) at abscissa `x`.
    pub fn height(&self, x: f64) -> f64 {
        ((x - self.px) * (x - self.px) + self.py * self.py) / (2.0 * self.py)
    }

    /// The point of the parabola at abscissa `x`.
    pub fn point(&self, x: f64) -> Sample {
        let y = self.height(x);
        Sample {
            x: self.origin[0] + x * self.u[0] + y * self.n[0],
            y: self.origin[1] + x * self.u[1] + y * self.n[1],
            r: y,
        }
    }

    /// Smallest height over `[x0, x1]` (either order).
    pub fn min_height(&self, x0: f64, x1: f64) -> f64 {
        self.height(self.px.clamp(x0.min(x1), x0.max(x1)))
    }

    /// Largest distance between the chord over `[x0, x1]` and the arc.
    pub fn chord_gap(&self, x0: f64, x1: f64) -> f64 {
        (x1 - x0) * (x1 - x0) / (8.0 * self.py)
    }

    /// The interior samples of the arc from abscissa `x0` to `x1` (ends
    /// excluded) such that every chord is within `tolerance(r_min)` of the
    /// arc, `r_min` being the smallest radius over that chord's span.
    pub fn samples(&self, x0: f64, x1: f64, tolerance: impl Fn(f64) -> f64) -> Vec<Sample> {
        let mut out = Vec::new();
        if !(x0.is_finite() && x1.is_finite()) || x0 == x1 {
            return out;
        }
        let mut stack = vec![x1];
        let mut cur = x0;
        while let Some(&next) = stack.last() {
            let fits = self.chord_gap(cur, next) <= tolerance(self.min_height(cur, next));
            if fits || stack.len() >= MAX_DEPTH {
                stack.pop();
                if !stack.is_empty() {
                    out.push(self.point(next));
                }
                cur = next;
            } else {
                stack.push(0.5 * (cur + next));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance from `q` to the parabola, by dense search then refinement.
    fn distance_to_parabola(par: &Parabola, q: [f64; 2], lo: f64, hi: f64) -> f64 {
        let d = |x: f64| {
            let s = par.point(x);
            (s.x - q[0]).hypot(s.y - q[1])
        };
        let (mut a, mut b) = (lo - (hi - lo), hi + (hi - lo));
        for _ in 0..200 {
            let m1 = a + (b - a) / 3.0;
            let m2 = b - (b - a) / 3.0;
            if d(m1) < d(m2) {
                b = m2;
            } else {
                a = m1;
            }
        }
        d(0.5 * (a + b))
    }

    #[test]
    fn samples_lie_on_the_parabola_and_chords_within_tolerance() {
        let p = [3.0, 2.0];
        let par = Parabola::new(p, [0.0, 0.0], [10.0, 0.0]).unwrap();
        for eps in [0.1, 0.01, 0.001] {
            let tol = |r: f64| eps * r;
            let (x0, x1) = (-4.0, 9.5);
            let mut pts = vec![par.point(x0)];
            pts.extend(par.samples(x0, x1, tol));
            pts.push(par.point(x1));
            for s in &pts {
                // Equidistant from the focus and the directrix y = 0.
                assert!(((s.x - p[0]).hypot(s.y - p[1]) - s.y).abs() < 1e-12);
                assert!((s.r - s.y).abs() < 1e-12);
            }
            let mut worst_ratio: f64 = 0.0;
            for w in pts.windows(2) {
                let rmin = par.min_height(
                    par.abscissa([w[0].x, w[0].y]),
                    par.abscissa([w[1].x, w[1].y]),
                );
                for k in 0..=50 {
                    let t = k as f64 / 50.0;
                    let q = [
                        w[0].x + t * (w[1].x - w[0].x),
                        w[0].y + t * (w[1].y - w[0].y),
                    ];
                    let dist = distance_to_parabola(&par, q, w[0].x, w[1].x);
                    assert!(dist <= eps * rmin * (1.0 + 1e-9), "{dist} > {}", eps * rmin);
                    worst_ratio = worst_ratio.max(dist / (eps * rmin));
                }
            }
            // Not needlessly fine: some chord uses at least a quarter of its budget.
            assert!(worst_ratio > 0.2, "ratio {worst_ratio}");
        }
    }

    #[test]
    fn point_on_the_line_has_no_parabola() {
        assert!(Parabola::new([5.0, 0.0], [0.0, 0.0], [1.0, 0.0]).is_none());
        assert!(Parabola::new([5.0, 1.0], [0.0, 0.0], [0.0, 0.0]).is_none());
    }

    #[test]
    fn relative_tolerance_needs_few_pieces_over_a_huge_range() {
        let par = Parabola::new([0.0, 1.0], [-1e9, 0.0], [1e9, 0.0]).unwrap();
        let n = par.samples(0.0, 1e6, |r| 0.01 * r).len();
        assert!(n < 200, "{n} samples");
    }
}
