//! The `prepare` step: a feature's geometry as polygon parts, normalised
//! and checked, or what becomes of the feature instead (rejected with the
//! reason, or filtered by `min_area`).

use crate::geometry::parts::polygon_parts;
use crate::geometry::PreparedPolygon;
use geo::{Area, Geometry, Polygon};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Why a feature has no polygon parts to work on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NotPrepared {
    /// Skipped by `min_area` (counted as filtered, not rejected).
    Filtered,
    /// Rejected, with the reason.
    Rejected(String),
}

impl From<NotPrepared> for super::Processed {
    fn from(n: NotPrepared) -> Self {
        match n {
            NotPrepared::Filtered => Self::Filtered,
            NotPrepared::Rejected(r) => Self::Rejected(r),
        }
    }
}

/// Options of the `prepare` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PrepareParams {
    /// Repair invalid polygons (GDAL MakeValid) instead of rejecting them.
    pub make_valid: bool,
    /// Polygon parts smaller than this (CRS units²) are skipped; a feature all
    /// of whose parts are skipped is counted as filtered.
    pub min_area: f64,
    /// A feature with more boundary vertices than this is rejected with the
    /// reason, before any method runs (0: no limit).
    pub max_vertices: usize,
}

impl PrepareParams {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if self.min_area.is_nan() || self.min_area < 0.0 {
            return Err((
                "min_area".into(),
                "min_area must be ≥ 0 (CRS units²)".into(),
            ));
        }
        Ok(())
    }
}

impl Default for PrepareParams {
    fn default() -> Self {
        Self {
            make_valid: true,
            min_area: 0.0,
            max_vertices: 5_000_000,
        }
    }
}

/// The polygon parts of a feature's geometry, normalised and checked, or
/// what becomes of the feature instead (rejected, or filtered by
/// `min_area`).
pub fn prepare(
    geom: Option<&Geometry<f64>>,
    params: &PrepareParams,
) -> Result<Vec<PreparedPolygon>, NotPrepared> {
    prepare_checked(geom, params, false)
}

/// [`prepare`] of a geometry the reader already found valid by the same
/// check (`checked`: [`crate::feature::Feature::checked`]), which is then
/// not made again.
pub fn prepare_checked(
    geom: Option<&Geometry<f64>>,
    params: &PrepareParams,
    checked: bool,
) -> Result<Vec<PreparedPolygon>, NotPrepared> {
    let parts = polygon_parts(geom).map_err(NotPrepared::Rejected)?;
    let parts: Vec<Polygon<f64>> = parts
        .into_iter()
        .filter(|p| params.min_area <= 0.0 || p.unsigned_area() >= params.min_area)
        .collect();
    if parts.is_empty() {
        return Err(NotPrepared::Filtered);
    }
    let vertices: usize = parts
        .iter()
        .map(|p| p.exterior().0.len() + p.interiors().iter().map(|r| r.0.len()).sum::<usize>())
        .sum();
    if params.max_vertices > 0 && vertices > params.max_vertices {
        return Err(NotPrepared::Rejected(format!(
            "the polygon has {vertices} vertices, more than `prepare.max_vertices` = {}; raise it, or simplify the polygon first",
            params.max_vertices
        )));
    }
    let mut prepared = Vec::with_capacity(parts.len());
    for (i, p) in parts.iter().enumerate() {
        match PreparedPolygon::new(p) {
            Ok(pp) => prepared.push(pp),
            Err(e) => return Err(NotPrepared::Rejected(part_reason(i, parts.len(), &e))),
        }
    }
    if !checked {
        if let Some(reason) = invalidity(&prepared, params.make_valid) {
            return Err(NotPrepared::Rejected(reason));
        }
    }
    Ok(prepared)
}

/// A reason for polygon part `i` of `n`: prefixed with the part when there
/// is more than one.
pub(crate) fn part_reason(i: usize, n: usize, reason: &dyn std::fmt::Display) -> String {
    if n > 1 {
        format!("part {i}: {reason}")
    } else {
        reason.to_string()
    }
}

/// The reason a prepared polygon is invalid, if it is (self-intersection,
/// crossing or touching rings, holes outside the shell). The fix suggested
/// depends on whether `make_valid` already ran.
fn invalidity(parts: &[PreparedPolygon], make_valid: bool) -> Option<String> {
    let fix = if make_valid {
        "GDAL's MakeValid left it so; repair the source geometry"
    } else {
        "enable `prepare: { make_valid: true }` to repair it"
    };
    parts.iter().enumerate().find_map(|(i, p)| {
        crate::geometry::validity::problem(p)
            .map(|err| part_reason(i, parts.len(), &format!("invalid polygon: {err}; {fix}")))
    })
}
