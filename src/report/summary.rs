//! What the report says about the whole file: every method's statistics
//! over all features, and which features to show (by `where`, by FID, or
//! the ones on which the methods disagree most).

use crate::output::CandidateRow;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Which features get a section of their own (`output.report.features`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Selection {
    /// The N features with the largest disagreement between methods: the
    /// range of Z plus the range of coverage over the methods, a method that
    /// failed or missed every bar counting as Z = 1 and coverage 0.
    Top(usize),
    /// These source FIDs, in this order.
    Fids(Vec<u64>),
    /// The features whose row in the skeleton layer passes this OGR SQL
    /// filter, e.g. "kind = 'lake'" or "distortion > 0.01", in file order.
    Where(String),
}

impl Default for Selection {
    fn default() -> Self {
        Selection::Top(20)
    }
}

impl Selection {
    /// Checks the option: `(key, message)` of what is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        match self {
            Selection::Top(0) => Err((
                "top".into(),
                "top must be at least 1 (the number of features to show)".into(),
            )),
            Selection::Fids(f) if f.is_empty() => Err((
                "fids".into(),
                "give at least one source FID, e.g. `fids: [3, 7]`".into(),
            )),
            Selection::Where(w) if w.trim().is_empty() => Err((
                "where".into(),
                "give an OGR SQL filter, e.g. \"kind = 'lake'\"".into(),
            )),
            _ => Ok(()),
        }
    }

    /// How the features were chosen, in words.
    pub fn describe(&self) -> String {
        match self {
            Selection::Top(n) => format!(
                "at most {n}, those on which the methods disagree most first (disagreement = range of Z plus range of coverage over the methods; a failed method or one without hits counts as Z = 1, coverage 0)"
            ),
            Selection::Fids(f) => {
                let list: Vec<String> = f.iter().map(u64::to_string).collect();
                format!("the features with source FID {}", list.join(", "))
            }
            Selection::Where(w) => format!("the features whose skeleton row passes `{w}`"),
        }
    }
}

/// A feature (or with `explode`, a polygon part): source FID and part.
pub type Key = (Option<u64>, Option<usize>);

/// One method's statistics over every feature of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodSummary {
    /// The method.
    pub method: String,
    /// Features with a candidate of this method.
    pub features: usize,
    /// Features on which this method was chosen.
    pub won: usize,
    /// Features on which the method failed.
    pub failed: usize,
    /// Mean Z over the candidates with hits.
    pub mean_distortion: f64,
    /// Mean s over the candidates with hits.
    pub mean_deviation: f64,
    /// Mean S over the candidates with hits.
    pub mean_deviation_parts: f64,
    /// Mean coverage over the scored candidates.
    pub mean_coverage: f64,
    /// Mean legs after pruning over the candidates that succeeded.
    pub mean_legs: f64,
    /// Candidates with hits (the n of the means of Z, s and S).
    pub with_hits: usize,
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (n, sum) = v.fold((0usize, 0.0), |(n, s), x| (n + 1, s + x));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// Every method's statistics, methods in the order they first appear.
pub fn summarise(candidates: &[CandidateRow]) -> Vec<MethodSummary> {
    let mut order: Vec<&str> = Vec::new();
    for c in candidates {
        if !order.contains(&c.method.as_str()) {
            order.push(&c.method);
        }
    }
    order
        .into_iter()
        .map(|m| {
            let rows: Vec<&CandidateRow> = candidates.iter().filter(|c| c.method == m).collect();
            let ok: Vec<&CandidateRow> =
                rows.iter().copied().filter(|c| c.error.is_none()).collect();
            let scored: Vec<_> = ok.iter().filter_map(|c| c.scores).collect();
            let hit: Vec<_> = scored.iter().filter(|s| s.hits > 0).collect();
            MethodSummary {
                method: m.to_string(),
                features: rows.len(),
                won: rows.iter().filter(|c| c.chosen).count(),
                failed: rows.len() - ok.len(),
                mean_distortion: mean(hit.iter().map(|s| s.distortion)),
                mean_deviation: mean(hit.iter().map(|s| s.deviation)),
                mean_deviation_parts: mean(hit.iter().map(|s| s.deviation_parts)),
                mean_coverage: mean(scored.iter().map(|s| s.coverage)),
                mean_legs: mean(ok.iter().map(|c| c.legs as f64)),
                with_hits: hit.len(),
            }
        })
        .collect()
}

/// The candidates of every feature, by key, in key order.
pub fn by_feature(candidates: &[CandidateRow]) -> BTreeMap<Key, Vec<&CandidateRow>> {
    let mut m: BTreeMap<Key, Vec<&CandidateRow>> = BTreeMap::new();
    for c in candidates {
        m.entry((c.src_fid, c.polygon_part)).or_default().push(c);
    }
    m
}

/// Z and coverage of a candidate as the disagreement counts them: a failed
/// candidate, or one without hits, is as bad as can be.
fn z_and_coverage(c: &CandidateRow) -> (f64, f64) {
    match (&c.error, c.scores) {
        (None, Some(s)) if s.hits > 0 && s.distortion.is_finite() => (s.distortion, s.coverage),
        _ => (1.0, 0.0),
    }
}

/// How much the methods disagree on one feature: the range of Z plus the
/// range of coverage over its candidates (0 for a single candidate).
pub fn disagreement(candidates: &[&CandidateRow]) -> f64 {
    let range = |v: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
        if hi >= lo {
            hi - lo
        } else {
            0.0
        }
    };
    let zc: Vec<(f64, f64)> = candidates.iter().map(|c| z_and_coverage(c)).collect();
    range(&mut zc.iter().map(|p| p.0)) + range(&mut zc.iter().map(|p| p.1))
}

/// Every feature with its disagreement, the largest first; among equals
/// the one whose chosen skeleton has the larger Z, then by key.
pub fn ranked(candidates: &[CandidateRow]) -> Vec<(Key, f64)> {
    let mut v: Vec<(Key, f64, f64)> = by_feature(candidates)
        .into_iter()
        .map(|(k, cs)| {
            let chosen_z = cs
                .iter()
                .find(|c| c.chosen)
                .map_or(1.0, |c| z_and_coverage(c).0);
            (k, disagreement(&cs), chosen_z)
        })
        .collect();
    v.sort_by(|a, b| {
        b.1.total_cmp(&a.1)
            .then(b.2.total_cmp(&a.2))
            .then(a.0.cmp(&b.0))
    });
    v.into_iter().map(|(k, d, _)| (k, d)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::Scores;

    fn cand(fid: u64, method: &str, z: Option<f64>, coverage: f64, chosen: bool) -> CandidateRow {
        CandidateRow {
            src_fid: Some(fid),
            polygon_part: None,
            method: method.into(),
            geometry: None,
            scores: z.map(|z| Scores {
                bars: 10,
                hits: 9,
                coverage,
                deviation: z * 100.0,
                deviation_parts: z * 200.0,
                distortion_sum: z * 9.0,
                distortion: z,
            }),
            chosen,
            components: 1,
            legs_raw: 4,
            legs: 2,
            error: z.is_none().then(|| "failed".to_string()),
        }
    }

    #[test]
    fn the_feature_where_methods_disagree_most_comes_first() {
        let c = vec![
            cand(1, "MA", Some(0.001), 0.9, true),
            cand(1, "CDT", Some(0.011), 0.9, false),
            cand(2, "MA", Some(0.001), 0.9, true),
            cand(2, "CDT", Some(0.101), 0.8, false),
            cand(3, "MA", Some(0.002), 0.9, true),
            cand(3, "CDT", None, 0.0, false),
        ];
        let r = ranked(&c);
        let keys: Vec<u64> = r.iter().map(|(k, _)| k.0.unwrap()).collect();
        // A failed method is the largest disagreement; then 0.1 + 0.1; then 0.01.
        assert_eq!(keys, [3, 2, 1]);
        assert!((r[1].1 - 0.2).abs() < 1e-12, "{r:?}");
        assert!((r[2].1 - 0.01).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn the_summary_counts_wins_and_failures_and_averages_only_what_was_measured() {
        let c = vec![
            cand(1, "MA", Some(0.001), 0.9, true),
            cand(1, "CDT", Some(0.011), 0.7, false),
            cand(2, "MA", Some(0.003), 1.0, false),
            cand(2, "CDT", None, 0.0, true),
        ];
        let s = summarise(&c);
        assert_eq!(
            s.iter().map(|m| m.method.as_str()).collect::<Vec<_>>(),
            ["MA", "CDT"]
        );
        assert_eq!((s[0].won, s[0].failed, s[0].with_hits), (1, 0, 2));
        assert!((s[0].mean_distortion - 0.002).abs() < 1e-12);
        assert!((s[0].mean_coverage - 0.95).abs() < 1e-12);
        assert_eq!((s[1].won, s[1].failed, s[1].with_hits), (1, 1, 1));
        assert!((s[1].mean_distortion - 0.011).abs() < 1e-12);
        assert!((s[1].mean_legs - 2.0).abs() < 1e-12);
    }

    #[test]
    fn an_empty_selection_is_refused_with_an_example() {
        assert!(Selection::Top(0).validate().is_err());
        let (key, msg) = Selection::Fids(vec![]).validate().unwrap_err();
        assert_eq!(key, "fids");
        assert!(msg.contains("fids: [3, 7]"), "{msg}");
        assert!(Selection::default().validate().is_ok());
    }
}
