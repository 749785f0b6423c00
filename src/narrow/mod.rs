//! Narrow and wide parts of a polygon along its medial axis — the geometry
//! of map production's partial collapse, shared by the `collapse` step (its
//! lines and kept areas) and `partition` (what is narrow with `width`). A
//! polygon is replaced by its skeleton line where it is narrower than the collapse
//! `width` and stays an area where it is wider; the two meet on a *cut*
//! across the polygon, on which the line ends, so that lines and kept areas
//! form one connected, gap-free network.
//!
//! The local width at a skeleton point is 2·r, r its distance to ∂P (the
//! medial axis transform for MA). The rule, on the skeleton sampled at most
//! `width / 4` apart:
//!
//! 1. A point is *narrow* where 2r ≤ `width`·(1 − `tolerance`), *wide* where
//!    2r ≥ `width`·(1 + `tolerance`); a point inside that band takes the class
//!    of the nearer (along the skeleton) point outside it. So a river that
//!    oscillates around the threshold changes class once, where it leaves the
//!    band, and every collapsed point is narrower than `width`·(1 + tol),
//!    every kept one wider than `width`·(1 − tol).
//! 2. A *stretch* (a connected run of one class) shorter than `min_length`
//!    is given its neighbours' class, shortest first, until none is left
//!    (a stretch that is a whole skeleton component keeps its class): a
//!    short pinch between two lakes stays area, a small pool in a river is
//!    collapsed, a lake's tapering tip stays part of the lake.
//! 3. `mode: whole` instead collapses a polygon part entirely when more than
//!    half of its area (the skeleton's length weighted by width) is narrow,
//!    and keeps it entirely otherwise.
//! 4. At each change of class the polygon is cut by the two radii from the
//!    change point p to the nearest boundary points on either side of the
//!    skeleton (the inscribed disc's contacts; each is visible from p, so the
//!    cut lies inside P; a contact within `1e-9 × extent` of a vertex is that
//!    vertex). The polygon is split exactly along the cuts
//!    (`crate::geometry::arrangement`): its own vertices keep their
//!    coordinates, a cut's ends are inserted into the edges they meet, rings
//!    touching at a vertex give valid pieces. A piece holding a wide stretch
//!    (or none) is kept; kept pieces that share a cut are one area. The
//!    skeleton is split at p (and wherever it passes a cut or a point of ∂P),
//!    and every piece of it is collapsed or kept as the piece of the polygon
//!    it lies in, so no collapsed line runs through a kept area; each
//!    collapsed line ends on a cut, on ∂P, or at another line.
//! 5. With `min_area`, a kept area smaller than it whose every cut has a
//!    collapsed face on its other side — a bead on a collapsed river, e.g.
//!    at a confluence where the river is briefly wider — is collapsed too:
//!    the skeleton through it joins the collapsed lines at its cuts, and its
//!    cuts go. Smallest areas first; an area with no cut (a polygon kept
//!    whole) is never collapsed by it.
//! 6. Connection legs (`input.connect`) take the class of the skeleton where
//!    they leave it: they continue the network, they are not the polygon's
//!    shape, so a leg to a kept lake's shore is kept and cuts no notch.
//!
//! The step works on the medial axis (MA alone in `skeleton.methods`): its
//! discs are what the local width and the cuts are made of, and another
//! method's lines are not centred on them.

mod classify;
mod split;

use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;
use geo::{Coord, LineString, Polygon};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How a polygon part is collapsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum CollapseMode {
    /// Lines where narrow, areas where wide, cut across the polygon between.
    #[default]
    Partial,
    /// The whole part collapses when more than half of its area is narrow,
    /// otherwise it is kept whole.
    Whole,
}

/// Options of the `collapse` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CollapseParams {
    /// Collapse width (CRS units): the polygon becomes a line where its local width 2r is below it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub width: f64,
    /// Band around `width` as a fraction of it (default 0.2): a point within width·(1 ± tolerance) takes the class of the nearer point outside the band, so that a river oscillating around the threshold is not chopped into pieces.
    #[serde(default = "default_tolerance")]
    #[schemars(range(min = 0), extend("exclusiveMaximum" = 1))]
    pub tolerance: f64,
    /// Shortest collapsed or kept stretch of skeleton (CRS units; default: `width`); a shorter one takes its neighbours' class.
    #[serde(default)]
    #[schemars(range(min = 0))]
    pub min_length: Option<f64>,
    /// `partial` (default): lines where narrow, areas where wide; `whole`: a polygon part collapses entirely when more than half of its area is narrow, otherwise it is kept.
    #[serde(default)]
    pub mode: CollapseMode,
    /// Smallest kept area (CRS units²; default 0: off): a kept area smaller than this whose every cut leads to a collapsed line (a bead on a collapsed river, at a confluence) is collapsed too; a few width² is typical.
    #[serde(default)]
    #[schemars(range(min = 0))]
    pub min_area: f64,
}

fn default_tolerance() -> f64 {
    0.2
}

impl CollapseParams {
    /// Collapse below `width` with the default tolerance, minimum length
    /// and mode.
    pub fn new(width: f64) -> Self {
        Self {
            width,
            tolerance: default_tolerance(),
            min_length: None,
            mode: CollapseMode::Partial,
            min_area: 0.0,
        }
    }

    /// The shortest stretch kept apart (`min_length`, default `width`).
    pub fn min_length(&self) -> f64 {
        self.min_length.unwrap_or(self.width)
    }

    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if !(self.width.is_finite() && self.width > 0.0) {
            return Err((
                "width".into(),
                "width must be a positive number of CRS units (the local width 2r below which the polygon becomes a line)".into(),
            ));
        }
        if !(0.0..1.0).contains(&self.tolerance) {
            return Err((
                "tolerance".into(),
                "tolerance must be at least 0 and below 1 (a fraction of width, e.g. 0.2)".into(),
            ));
        }
        if !(self.min_area.is_finite() && self.min_area >= 0.0) {
            return Err((
                "min_area".into(),
                "min_area must be ≥ 0 (CRS units², e.g. 4 × width²; 0 turns it off)".into(),
            ));
        }
        if let Some(m) = self.min_length {
            if !(m.is_finite() && m >= 0.0) {
                return Err((
                    "min_length".into(),
                    "min_length must be ≥ 0 (CRS units)".into(),
                ));
            }
        }
        Ok(())
    }
}

/// A kept area: a piece of the polygon wider than the collapse width.
#[derive(Debug, Clone, PartialEq)]
pub struct Area {
    /// The piece.
    pub polygon: Polygon<f64>,
    /// How many cuts bound it (where collapsed lines meet it).
    pub cuts: usize,
}

/// One polygon part, collapsed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PartCollapse {
    /// The skeleton where the part is narrow: the collapsed lines.
    pub collapsed: Vec<LineString<f64>>,
    /// The skeleton through the kept areas (for a network continued through
    /// them).
    pub kept: Vec<LineString<f64>>,
    /// The kept areas.
    pub areas: Vec<Area>,
    /// The cuts between collapsed lines and kept areas, each from one
    /// boundary contact through the change point to the other.
    pub cuts: Vec<LineString<f64>>,
    /// With `output.measures: width`: the local width at every vertex of
    /// `collapsed`, line by line.
    pub collapsed_measures: Vec<Vec<f64>>,
    /// The same for `kept`.
    pub kept_measures: Vec<Vec<f64>>,
}

/// Collapses polygon part `p` with its finished skeleton `g` (see the
/// module documentation); `legs` are the connection legs `g` holds (from
/// the skeleton to the boundary), which take the class of the skeleton
/// where they leave it.
pub fn collapse(
    g: &SkeletonGraph,
    p: &PreparedPolygon,
    params: &CollapseParams,
    legs: &[(Coord<f64>, Coord<f64>)],
) -> PartCollapse {
    // Without a deadline nothing stops it.
    collapse_within(g, p, params, legs, &|| false).unwrap_or_default()
}

/// [`collapse`] that asks `expired()` between its stages (sampling the
/// lines, classifying, merging, splitting the polygon) and stops with
/// `None` once the time is up.
pub fn collapse_within(
    g: &SkeletonGraph,
    p: &PreparedPolygon,
    params: &CollapseParams,
    legs: &[(Coord<f64>, Coord<f64>)],
    expired: &dyn Fn() -> bool,
) -> Option<PartCollapse> {
    if g.is_empty() {
        return Some(PartCollapse {
            areas: vec![Area {
                polygon: p.polygon().clone(),
                cuts: 0,
            }],
            ..PartCollapse::default()
        });
    }
    let go = || (!expired()).then_some(());
    let mut s = classify::Samples::of(g, p, params.width, legs);
    go()?;
    s.classify(params);
    s.follow_legs();
    go()?;
    match params.mode {
        CollapseMode::Partial => s.merge_short(params.min_length()),
        CollapseMode::Whole => s.whole(),
    }
    s.follow_legs();
    go()?;
    Some(split::split(&s, p, params.min_area))
}

/// The point at parameter `t` of segment `a`–`b`.
fn lerp(a: Coord<f64>, b: Coord<f64>, t: f64) -> Coord<f64> {
    a + (b - a) * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::GraphBuilder;
    use geo::{polygon, Area as _};

    /// A 100 × 10 rectangle's centreline collapsed at `width`.
    fn rectangle(width: f64) -> PartCollapse {
        let r = polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 10.), (x: 0., y: 10.)];
        let p = PreparedPolygon::new(&r).unwrap();
        let mut b = GraphBuilder::new();
        b.segment(Coord { x: 0., y: 5. }, Coord { x: 100., y: 5. });
        collapse(
            &b.finish(p.boundary()),
            &p,
            &CollapseParams::new(width),
            &[],
        )
    }

    #[test]
    fn a_narrow_rectangle_collapses_whole_and_a_wide_one_stays() {
        let narrow = &rectangle(20.0);
        assert!(narrow.areas.is_empty(), "{narrow:?}");
        assert!(!narrow.collapsed.is_empty());
        let wide = &rectangle(5.0);
        assert_eq!(wide.areas.len(), 1);
        assert!(wide.collapsed.is_empty(), "{wide:?}");
        assert!((wide.areas[0].polygon.unsigned_area() - 1000.0).abs() < 1e-6);
    }

    #[test]
    fn validate_names_the_wrong_option() {
        assert_eq!(CollapseParams::new(0.0).validate().unwrap_err().0, "width");
        let mut p = CollapseParams::new(1.0);
        p.tolerance = 1.0;
        assert_eq!(p.validate().unwrap_err().0, "tolerance");
        p.tolerance = 0.2;
        p.min_length = Some(-1.0);
        assert_eq!(p.validate().unwrap_err().0, "min_length");
    }
}
