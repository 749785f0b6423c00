//! Method selection (SPEC §7).

use super::Scores;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The metric by which candidates are compared (smaller is better).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SelectBy {
    /// Z, mean distortion (eq. 10).
    #[default]
    Distortion,
    /// s (eq. 2).
    Deviation,
    /// S (eq. 4).
    DeviationParts,
    /// SZ (eq. 9).
    DistortionSum,
}

impl SelectBy {
    /// The metric's value in `s`.
    pub fn value(self, s: &Scores) -> f64 {
        match self {
            SelectBy::Distortion => s.distortion,
            SelectBy::Deviation => s.deviation,
            SelectBy::DeviationParts => s.deviation_parts,
            SelectBy::DistortionSum => s.distortion_sum,
        }
    }
}

fn default_min_coverage() -> f64 {
    0.9
}

/// Options of the `select` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelectParams {
    /// Metric to minimise.
    #[serde(default)]
    pub by: SelectBy,
    /// Candidates below this coverage are considered only if none reaches it.
    #[serde(default = "default_min_coverage")]
    pub min_coverage: f64,
}

impl Default for SelectParams {
    fn default() -> Self {
        Self {
            by: SelectBy::default(),
            min_coverage: default_min_coverage(),
        }
    }
}

/// Index of the chosen candidate among `candidates` (in `methods` order;
/// `None` entries are methods that failed). Ties go to the earlier one.
pub fn select(candidates: &[Option<Scores>], params: &SelectParams) -> Option<usize> {
    let ok = |s: &Scores| s.coverage >= params.min_coverage;
    let mut best: Option<(usize, f64)> = None;
    for (i, s) in candidates.iter().enumerate() {
        let Some(s) = s else { continue };
        if !ok(s) {
            continue;
        }
        let v = params.by.value(s);
        let v = if v.is_nan() { f64::INFINITY } else { v };
        if best.is_none_or(|(_, bv)| v < bv) {
            best = Some((i, v));
        }
    }
    if let Some((i, _)) = best {
        return Some(i);
    }
    // None reaches min_coverage: the highest coverage wins.
    let mut best: Option<(usize, f64)> = None;
    for (i, s) in candidates.iter().enumerate() {
        let Some(s) = s else { continue };
        if best.is_none_or(|(_, bc)| s.coverage > bc) {
            best = Some((i, s.coverage));
        }
    }
    best.map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(coverage: f64, distortion: f64) -> Option<Scores> {
        Some(Scores {
            coverage,
            distortion,
            ..Scores::default()
        })
    }

    #[test]
    fn picks_lowest_distortion_among_covered() {
        let p = SelectParams::default();
        assert_eq!(
            select(&[s(0.95, 0.2), s(0.5, 0.0), s(0.99, 0.1)], &p),
            Some(2)
        );
        assert_eq!(select(&[s(0.95, 0.1), s(0.99, 0.1)], &p), Some(0));
        assert_eq!(select(&[None, s(0.3, 0.1), s(0.6, 0.5)], &p), Some(2));
        assert_eq!(select(&[None, None], &p), None);
    }
}
