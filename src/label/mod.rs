//! The `label` step: one label per polygon part, ready for a curved lake or
//! region name — a smooth line along the medial axis where the part is
//! elongated enough, otherwise a point at the centre of its largest
//! inscribed disc (see [`mod@line`] for the algorithm). The step uses the
//! medial axis whether or not `MA` is among the pipeline's methods, and
//! writes the layer `labels`:
//!
//! | column | meaning |
//! |---|---|
//! | source fields | the feature's |
//! | `polygon_part` | index of the part in the feature |
//! | `kind` | `line` or `point` |
//! | `length` | the line's length (0 for a point) |
//! | `max_width` | the largest inscribed disc's diameter 2r |
//! | `elongation` | the medial-axis path's length over `max_width` |
//! | `minzoom` | the smallest web-map zoom at which the line is `min_pixels` long (a point's disc that wide) at its latitude; NULL when the run's CRS is unknown |
//!
//! ```yaml
//! steps:
//!   - skeleton: { methods: [MA] }
//!   - label: { smooth: 60, margin: 0.9, min_elongation: 3 }
//! ```

pub mod line;

use crate::geometry::PreparedPolygon;
use crate::graph::extend::{prune_and_extend, ExtendParams};
use crate::graph::prune::PruneParams;
use crate::graph::SkeletonGraph;
use crate::layer::{Cell, ColumnType, GeometryKind, StepLayer, StepRow};
use crate::methods::{MethodContext, MethodId, SkeletonParams};
use crate::process::step::{
    FeatureStep, LonLat, Needs, OptionError, StepEntry, StepInput, StepRows,
};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

pub use line::{Label, Labelled};

/// Which polygon parts of a feature get a label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Parts {
    /// Every part its own label.
    #[default]
    Each,
    /// Only the largest part (by area).
    Largest,
}

/// Options of the `label` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct LabelParams {
    /// The most the line may turn over a stretch one local width long
    /// (degrees): the curve a label's letters still follow.
    #[schemars(range(max = 180), extend("exclusiveMinimum" = 0))]
    pub smooth: f64,
    /// The line keeps at least this fraction of the local radius from the
    /// shore (below 1).
    #[schemars(range(min = 0), extend("exclusiveMaximum" = 1))]
    pub margin: f64,
    /// A part whose medial-axis path is shorter than this many times its
    /// largest width gets a point instead of a line (0: every part a line).
    #[schemars(range(min = 0))]
    pub min_elongation: f64,
    /// Every part, or only the largest part of a feature.
    pub parts: Parts,
    /// A line is shown from the web-map zoom at which it is at least this
    /// many pixels long (256-pixel tiles, at the feature's latitude); a
    /// point from the zoom at which its largest disc is this many pixels
    /// wide (column `minzoom`).
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub min_pixels: f64,
}

/// Metres per pixel at zoom 0 on the equator: the web map's 256-pixel
/// tile over the WGS 84 equator (2π · 6 378 137 m / 256).
const EQUATOR_M_PER_PIXEL: f64 = 156_543.033_928_041;

/// The smallest web-map zoom (0–24) at which `metres` span at least
/// `pixels` at latitude `lat` (degrees); `None` for no length.
pub fn minzoom(metres: f64, lat: f64, pixels: f64) -> Option<i64> {
    if !(metres > 0.0 && metres.is_finite() && lat.is_finite()) {
        return None;
    }
    let per_pixel_z0 = EQUATOR_M_PER_PIXEL * lat.to_radians().cos();
    let z = (pixels * per_pixel_z0 / metres).log2().ceil();
    Some(z.clamp(0.0, 24.0) as i64)
}

/// Where a label's zoom is judged: the middle of its line (half its
/// length along it) or its point.
fn anchor(l: &Labelled) -> geo::Coord<f64> {
    match &l.label {
        Label::Point(c) => *c,
        Label::Line(line) => {
            use geo::{Euclidean, InterpolateLine};
            Euclidean
                .point_at_ratio_from_start(line, 0.5)
                .map_or(line.0[0], |p| p.0)
        }
    }
}

impl Default for LabelParams {
    fn default() -> Self {
        Self {
            smooth: 60.0,
            margin: 0.9,
            min_elongation: 3.0,
            parts: Parts::Each,
            min_pixels: 64.0,
        }
    }
}

impl LabelParams {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), OptionError> {
        if !(self.smooth > 0.0 && self.smooth <= 180.0) {
            return Err((
                "smooth".into(),
                "smooth is the most the line may turn over one local width, in degrees: above 0 and at most 180 (e.g. 45)".into(),
            ));
        }
        if !(0.0..1.0).contains(&self.margin) {
            return Err((
                "margin".into(),
                "margin is a fraction of the local radius kept from the shore: at least 0 and below 1 (e.g. 0.5)".into(),
            ));
        }
        if !(self.min_pixels > 0.0 && self.min_pixels.is_finite()) {
            return Err((
                "min_pixels".into(),
                "min_pixels is how many pixels long a line (or wide a point's disc) must be on the web map to be shown: above 0 (e.g. 64)".into(),
            ));
        }
        if !(self.min_elongation >= 0.0 && self.min_elongation.is_finite()) {
            return Err((
                "min_elongation".into(),
                "min_elongation is a ratio of length to width, ≥ 0 (e.g. 2; 0 gives every part a line)".into(),
            ));
        }
        Ok(())
    }

    /// The label of one polygon part (`None` when it has no medial axis: a
    /// polygon thinner than the axis's grid).
    pub fn label(&self, p: &PreparedPolygon) -> Option<Labelled> {
        self.label_on(p, None, &MethodContext::default())
    }

    /// The label of one polygon part from its medial axis's raw skeleton
    /// `raw` (MA with its default options), made here within `ctx`'s budget
    /// when not given.
    pub fn label_on(
        &self,
        p: &PreparedPolygon,
        raw: Option<&SkeletonGraph>,
        ctx: &MethodContext,
    ) -> Option<Labelled> {
        let made;
        let raw = match raw {
            Some(raw) => raw,
            None => {
                let params = SkeletonParams {
                    methods: vec![MethodId::MA],
                    ..Default::default()
                };
                made = crate::methods::build(MethodId::MA, &params)
                    .skeletonise(p, ctx)
                    .ok()?;
                &made
            }
        };
        let g = prune_and_extend(
            raw,
            p,
            Some(&PruneParams::default()),
            Some(&ExtendParams::default()),
        );
        line::label(
            p,
            raw,
            &g,
            line::Shape {
                smooth_deg: self.smooth,
                margin: self.margin,
                min_elongation: self.min_elongation,
            },
        )
    }
}

/// The `labels` layer.
pub const LABELS: &[StepLayer] = &[StepLayer {
    name: "labels",
    geometry: GeometryKind::Unknown,
    fields: Some(crate::layer::Fields::Input),
    columns: &[
        ("polygon_part", ColumnType::Int32),
        ("kind", ColumnType::Text),
        ("length", ColumnType::Real),
        ("max_width", ColumnType::Real),
        ("elongation", ColumnType::Real),
        ("minzoom", ColumnType::Int32),
    ],
}];

impl LabelParams {
    /// The labels of one feature's polygon parts (every part, or only the
    /// largest by area), each with the part's index: `None` for a part with
    /// no medial axis (thinner than the axis's grid).
    pub fn labels(&self, parts: &[PreparedPolygon]) -> Vec<(usize, Option<Labelled>)> {
        self.labels_on(parts, None, &MethodContext::default())
    }

    /// [`Self::labels`] from the parts' medial axes' raw skeletons
    /// (`medial_axis[i]` of part i, MA with its default options), made here
    /// when not given, within `ctx`'s budget: once its deadline has passed
    /// no further part is labelled (the caller, which owns the clock,
    /// rejects the feature).
    pub fn labels_on(
        &self,
        parts: &[PreparedPolygon],
        medial_axis: Option<&[Arc<SkeletonGraph>]>,
        ctx: &MethodContext,
    ) -> Vec<(usize, Option<Labelled>)> {
        use geo::Area;
        let raw = |i: usize| medial_axis.and_then(|m| m.get(i)).map(|g| &**g);
        let mut parts: Vec<(usize, &PreparedPolygon)> = parts.iter().enumerate().collect();
        if self.parts == Parts::Largest {
            parts.sort_by(|a, b| {
                b.1.polygon()
                    .unsigned_area()
                    .total_cmp(&a.1.polygon().unsigned_area())
            });
            parts.truncate(1);
        }
        parts
            .into_iter()
            .take_while(|_| !ctx.expired())
            .map(|(i, p)| (i, self.label_on(p, raw(i), ctx)))
            .collect()
    }

    /// A label's `minzoom` at its own latitude (`None`: no label, or no
    /// longitude and latitude for the run's coordinates).
    pub fn zoom_of(&self, l: Option<&Labelled>, lonlat: Option<&LonLat>) -> Option<i64> {
        let l = l?;
        let lat = lonlat?.of(anchor(l))?.y;
        let metres = match l.label {
            Label::Line(_) => l.length,
            Label::Point(_) => l.max_width,
        };
        minzoom(metres, lat, self.min_pixels)
    }
}

impl FeatureStep for LabelParams {
    fn rows(&self, input: &StepInput<'_>) -> StepRows {
        let rows = self
            .labels_on(input.parts, input.medial_axis, input.budget)
            .into_iter()
            .map(|(i, l)| {
                let (geometry, kind) = match l.as_ref().map(|l| &l.label) {
                    Some(Label::Line(line)) => {
                        (Some(geo::Geometry::LineString(line.clone())), "line")
                    }
                    Some(Label::Point(c)) => (Some(geo::Geometry::Point((*c).into())), "point"),
                    None => (None, "none"),
                };
                let real =
                    |f: fn(&Labelled) -> f64| l.as_ref().map_or(Cell::Null, |l| Cell::Real(f(l)));
                let cells = vec![
                    ("polygon_part", Cell::Int(i as i64)),
                    ("kind", Cell::Text(kind.into())),
                    ("length", real(|l| l.length)),
                    ("max_width", real(|l| l.max_width)),
                    ("elongation", real(|l| l.elongation)),
                    (
                        "minzoom",
                        self.zoom_of(l.as_ref(), input.lonlat)
                            .map_or(Cell::Null, Cell::Int),
                    ),
                ];
                ("labels", StepRow { geometry, cells })
            })
            .collect();
        Ok(rows)
    }
}

/// The `label` step's entry in the step registry.
pub const ENTRY: StepEntry = StepEntry {
    name: "label",
    after: "skeleton",
    description: "one label per polygon part: a smooth line along the medial axis where the part is elongated, else the centre of its largest inscribed disc (layer `labels`)",
    schema: || schemars::schema_for!(LabelParams),
    needs: Needs {
        medial_axis: true,
        lonlat: true,
        side: None,
        finish: false,
        ..Needs::NOTHING
    },
    layers: LABELS,
    build: |v| {
        let p: LabelParams = crate::process::step::step_options(v)?;
        p.validate()?;
        Ok(Arc::new(p))
    },
};

#[cfg(test)]
mod tests {
    use super::minzoom;

    #[test]
    fn minzoom_is_the_first_zoom_at_which_the_label_is_long_enough() {
        // On the equator a pixel is 156 543 m at zoom 0, 611.5 m at zoom 8:
        // a 64-pixel label needs 39 136 m there, so 40 km shows from 8, 39 km from 9.
        assert_eq!(minzoom(40_000.0, 0.0, 64.0), Some(8));
        assert_eq!(minzoom(39_000.0, 0.0, 64.0), Some(9));
        // At 60° a pixel covers half as much ground: one zoom level earlier.
        assert_eq!(minzoom(20_000.0, 60.0, 64.0), Some(8));
        // Clamped to the web map's zooms; no length, no zoom.
        assert_eq!(minzoom(1e9, 0.0, 64.0), Some(0));
        assert_eq!(minzoom(0.001, 0.0, 64.0), Some(24));
        assert_eq!(minzoom(0.0, 0.0, 64.0), None);
    }
}
