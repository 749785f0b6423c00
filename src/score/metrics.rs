//! The paper's metrics over a skeleton's bars: eqs. 1–4 and 8–10.

use super::{Bar, Scores};
use std::collections::BTreeMap;

/// Standard deviation of eqs. 2–3 from Σ Δd² over `n` hits: √(Σ Δd² / (n − 1)),
/// |Δd| for a single hit, NaN for none.
fn deviation(sum_sq: f64, n: usize) -> f64 {
    match n {
        0 => f64::NAN,
        1 => sum_sq.sqrt(),
        _ => (sum_sq / (n - 1) as f64).sqrt(),
    }
}

/// The metrics of a set of bars (N = `bars.len()`; misses count in N only).
///
/// Parts for eqs. 3–4 are the distinct [`super::BarHit::part`] values.
pub fn metrics(bars: &[Bar]) -> Scores {
    let big_n = bars.len();
    let mut n = 0usize;
    let mut sum_sq = 0.0;
    let mut sz = 0.0;
    // part → (Σ Δd², hits); ordered so the sum of eq. 4 is deterministic.
    let mut parts: BTreeMap<usize, (f64, usize)> = BTreeMap::new();
    for h in bars.iter().filter_map(|b| b.hit.as_ref()) {
        let dd = h.delta_d();
        n += 1;
        sum_sq += dd * dd;
        sz += h.z();
        let e = parts.entry(h.part).or_insert((0.0, 0));
        e.0 += dd * dd;
        e.1 += 1;
    }
    let coverage = if big_n == 0 {
        0.0
    } else {
        n as f64 / big_n as f64
    };
    if n == 0 {
        return Scores {
            bars: big_n,
            hits: 0,
            coverage,
            deviation: f64::NAN,
            deviation_parts: f64::NAN,
            distortion_sum: f64::NAN,
            distortion: f64::NAN,
        };
    }
    let s_parts_sq: f64 = parts
        .values()
        .map(|&(sq, k)| deviation(sq, k).powi(2))
        .sum();
    Scores {
        bars: big_n,
        hits: n,
        coverage,
        deviation: deviation(sum_sq, n),
        deviation_parts: s_parts_sq.sqrt(),
        distortion_sum: sz,
        distortion: sz / n as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::BarHit;
    use geo::Coord;

    fn bar(hit: Option<(f64, f64, usize)>) -> Bar {
        Bar {
            origin: Coord { x: 0.0, y: 0.0 },
            dir: Coord { x: 0.0, y: 1.0 },
            hit: hit.map(|(d_left, d_right, part)| BarHit {
                point: Coord { x: 0.0, y: 1.0 },
                d_left,
                d_right,
                part,
            }),
        }
    }

    #[test]
    fn hand_computed() {
        // Δd = 1, −2, 3 (parts 0, 0, 1); one miss.
        let b = [
            bar(Some((1.0, 2.0, 0))),
            bar(Some((3.0, 1.0, 0))),
            bar(Some((0.0, 3.0, 1))),
            bar(None),
        ];
        let s = metrics(&b);
        assert_eq!((s.bars, s.hits), (4, 3));
        assert_eq!(s.coverage, 0.75);
        // s = √((1 + 4 + 9) / 2) = √7.
        assert!((s.deviation - 7f64.sqrt()).abs() < 1e-12);
        // s_0 = √((1 + 4) / 1) = √5, s_1 = |3| (one hit): S = √(5 + 9).
        assert!((s.deviation_parts - 14f64.sqrt()).abs() < 1e-12);
        // z = 1/3, 2/4, 3/3.
        let sz = 1.0 / 3.0 + 0.5 + 1.0;
        assert!((s.distortion_sum - sz).abs() < 1e-12);
        assert!((s.distortion - sz / 3.0).abs() < 1e-12);
    }

    #[test]
    fn one_hit_and_no_hit() {
        let s = metrics(&[bar(Some((1.0, 4.0, 2)))]);
        assert_eq!((s.deviation, s.deviation_parts), (3.0, 3.0));
        assert!((s.distortion - 0.6).abs() < 1e-12);
        let s = metrics(&[bar(None), bar(None)]);
        assert_eq!((s.bars, s.hits, s.coverage), (2, 0, 0.0));
        assert!(s.deviation.is_nan() && s.distortion.is_nan() && s.distortion_sum.is_nan());
        let s = metrics(&[]);
        assert_eq!((s.bars, s.coverage), (0, 0.0));
    }

    #[test]
    fn no_hit_never_wins_selection() {
        use crate::score::select::{select, Entry, SelectBy, SelectParams};
        let entry = |scores| Entry {
            scores,
            components: 1,
        };
        let empty = entry(metrics(&[bar(None)]));
        let poor = entry(metrics(&[bar(Some((0.0, 5.0, 0))), bar(None)]));
        for by in [
            SelectBy::Distortion,
            SelectBy::Deviation,
            SelectBy::DeviationParts,
            SelectBy::DistortionSum,
        ] {
            let p = SelectParams {
                by,
                min_coverage: 0.0,
                ..SelectParams::default()
            };
            assert_eq!(select(&[Some(empty), Some(poor)], &p), Some(1), "{by:?}");
        }
    }
}
