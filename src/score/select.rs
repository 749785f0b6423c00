//! Method selection (SPEC §7, refined by the issue on the default output's
//! quality).
//!
//! Among the candidates with hits (a skeleton without hits has nothing to
//! measure, an empty one is never a candidate):
//!
//! 1. **Eligible**: coverage ≥ min(`min_coverage`, C_max − `coverage_slack`),
//!    where C_max is the best coverage of any candidate. When some reach
//!    `min_coverage` these are the eligible ones; when none does, every
//!    candidate within `coverage_slack` of the best coverage is — a few
//!    points of coverage (usually from spurs into bays) never outweigh a
//!    several-fold worse distortion.
//! 2. **Whole**: of the eligible ones, those in the fewest connected pieces
//!    (`components`). A Voronoi skeleton (VD, DVD) drops the edges that
//!    cross ∂P, so where the boundary's vertices are farther apart than the
//!    corridor is wide it falls into pieces and loses the arms between them;
//!    the metric only sees the bars those arms would have hit, a few percent
//!    of coverage, and a broken candidate with a lower distortion would win
//!    over a whole one. A polygon's parts and holes never make a whole
//!    skeleton broken, so the fewest pieces of any candidate is the number a
//!    whole one has.
//! 3. **Best**: the smallest `by` among the whole eligible ones, where values
//!    within `tie` of the smallest count as equal (`by: distortion` only:
//!    the medial axis approximates its parabolic arcs within
//!    `arc_tolerance`, so where StSk or DVD coincide with it their exact
//!    segments score ~10⁻¹² against MA's ~10⁻⁹–10⁻⁴, a difference no map
//!    shows); among equals the method listed first in `methods` wins.
//!
//! With `prune.structure: shared` (the default) every candidate has the same
//! legs reaching ∂P at the same places, so coverage differs little and the
//! metric decides.

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

fn default_coverage_slack() -> f64 {
    0.25
}

fn default_tie() -> f64 {
    1e-4
}

/// Options of the `select` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SelectParams {
    /// Metric to minimise.
    #[serde(default)]
    pub by: SelectBy,
    /// Candidates reaching this coverage are eligible.
    #[serde(default = "default_min_coverage")]
    pub min_coverage: f64,
    /// When none reaches `min_coverage`, those within this much of the best
    /// coverage are eligible.
    #[serde(default = "default_coverage_slack")]
    pub coverage_slack: f64,
    /// Distortions closer than this to the smallest count as equal (the
    /// earlier method wins).
    #[serde(default = "default_tie")]
    pub tie: f64,
}

impl Default for SelectParams {
    fn default() -> Self {
        Self {
            by: SelectBy::default(),
            min_coverage: default_min_coverage(),
            coverage_slack: default_coverage_slack(),
            tie: default_tie(),
        }
    }
}

impl SelectParams {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let fraction = |v: f64| (0.0..=1.0).contains(&v);
        if !fraction(self.min_coverage) {
            return Err((
                "min_coverage".into(),
                "min_coverage is a fraction between 0 and 1".into(),
            ));
        }
        if !fraction(self.coverage_slack) {
            return Err((
                "coverage_slack".into(),
                "coverage_slack is a fraction between 0 and 1".into(),
            ));
        }
        if !(self.tie >= 0.0 && self.tie <= 1.0) {
            return Err(("tie".into(), "tie is a distortion between 0 and 1".into()));
        }
        Ok(())
    }
}

/// What [`select`] compares of one candidate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Entry {
    /// The candidate's scores.
    pub scores: Scores,
    /// Connected pieces of its skeleton (summed over polygon parts).
    pub components: usize,
}

/// Index of the chosen candidate among `candidates` (in `methods` order;
/// `None` entries are methods that failed or gave an empty skeleton), per
/// the rule in the module documentation. Candidates without hits are chosen
/// only when no candidate has one (then the first of them).
pub fn select(candidates: &[Option<Entry>], params: &SelectParams) -> Option<usize> {
    let scored: Vec<(usize, &Entry, f64)> = candidates
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let e = e.as_ref()?;
            let v = params.by.value(&e.scores);
            (e.scores.hits > 0 && !v.is_nan()).then_some((i, e, v))
        })
        .collect();
    if scored.is_empty() {
        return candidates.iter().position(Option::is_some);
    }
    let c_max = scored
        .iter()
        .map(|c| c.1.scores.coverage)
        .fold(0.0, f64::max);
    let floor = params.min_coverage.min(c_max - params.coverage_slack);
    let covered = scored.iter().filter(|c| c.1.scores.coverage >= floor);
    let fewest = covered.clone().map(|c| c.1.components).min();
    let eligible: Vec<&(usize, &Entry, f64)> =
        covered.filter(|c| Some(c.1.components) == fewest).collect();
    let best = eligible.iter().map(|c| c.2).fold(f64::INFINITY, f64::min);
    let tie = if params.by == SelectBy::Distortion {
        params.tie
    } else {
        0.0
    };
    eligible.iter().find(|c| c.2 <= best + tie).map(|c| c.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(coverage: f64, distortion: f64) -> Option<Entry> {
        Some(Entry {
            scores: Scores {
                bars: 100,
                hits: (coverage * 100.0) as usize,
                coverage,
                distortion,
                ..Scores::default()
            },
            components: 1,
        })
    }

    fn broken(coverage: f64, distortion: f64) -> Option<Entry> {
        s(coverage, distortion).map(|e| Entry { components: 2, ..e })
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

    #[test]
    fn a_few_points_of_coverage_never_outweigh_a_worse_distortion() {
        let p = SelectParams::default();
        // Nobody reaches 0.9: MA at 0.80 with Z 0.001 against a spur-laden
        // CDT at 0.86 with Z 0.05 — MA is within the slack and wins.
        assert_eq!(select(&[s(0.80, 0.001), s(0.86, 0.05)], &p), Some(0));
        // Far below the best coverage (0.5 against 0.86): not eligible.
        assert_eq!(select(&[s(0.50, 0.001), s(0.86, 0.05)], &p), Some(1));
        // Above min_coverage: the metric alone decides.
        assert_eq!(select(&[s(0.91, 0.002), s(0.99, 0.05)], &p), Some(0));
    }

    #[test]
    fn distortions_within_the_tie_go_to_the_earlier_method() {
        let p = SelectParams::default();
        // MA's polyline arcs (Z 5e-5) against StSk's exact segments (1e-12).
        assert_eq!(select(&[s(0.95, 5e-5), s(0.95, 1e-12)], &p), Some(0));
        assert_eq!(select(&[s(0.95, 5e-4), s(0.95, 1e-12)], &p), Some(1));
        let exact = SelectParams { tie: 0.0, ..p };
        assert_eq!(select(&[s(0.95, 5e-5), s(0.95, 1e-12)], &exact), Some(1));
    }

    #[test]
    fn a_skeleton_without_hits_only_wins_alone() {
        let p = SelectParams::default();
        let none = Some(Entry {
            scores: Scores {
                bars: 4,
                distortion: f64::NAN,
                ..Scores::default()
            },
            components: 1,
        });
        assert_eq!(select(&[none, s(0.2, 0.3)], &p), Some(1));
        assert_eq!(select(&[None, none], &p), Some(1));
    }

    #[test]
    fn a_broken_candidate_never_wins_over_a_whole_one() {
        let p = SelectParams::default();
        // The states quarter: DVD in two pieces (coverage 0.713, Z 0.0250)
        // against MA whole (0.722, 0.0266).
        assert_eq!(
            select(&[s(0.722, 0.0266), broken(0.713, 0.0250)], &p),
            Some(0)
        );
        assert_eq!(
            select(&[broken(0.713, 0.0250), s(0.722, 0.0266)], &p),
            Some(1)
        );
        // All in two pieces (a polygon of two parts): the metric decides.
        assert_eq!(
            select(&[broken(0.722, 0.0266), broken(0.713, 0.0250)], &p),
            Some(1)
        );
        // A whole candidate the coverage rule excludes does not make the
        // covered ones ineligible.
        assert_eq!(select(&[s(0.3, 0.001), broken(0.9, 0.05)], &p), Some(1));
    }
}
