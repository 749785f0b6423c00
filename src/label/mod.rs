//! The `label` step: one label per polygon part, ready for a curved lake or
//! region name — a smooth line along the medial axis where the part is
//! elongated enough, otherwise a point at the centre of its largest
//! inscribed disc (see [`line`] for the algorithm). The step uses the
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
use crate::layer::{Cell, ColumnType, GeometryKind, StepLayer, StepRow};
use crate::methods::{MethodContext, MethodId, SkeletonParams};
use crate::process::step::{FeatureStep, OptionError, StepEntry, StepInput};
use serde::Deserialize;
use std::sync::Arc;

pub use line::{Label, Labelled};

/// Which polygon parts of a feature get a label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Parts {
    /// Every part its own label.
    #[default]
    Each,
    /// Only the largest part (by area).
    Largest,
}

/// Options of the `label` step.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LabelParams {
    /// The most the line may turn over a stretch one local width long
    /// (degrees): the curve a label's letters still follow.
    pub smooth: f64,
    /// The line keeps at least this fraction of the local radius from the
    /// shore.
    pub margin: f64,
    /// A part whose medial-axis path is shorter than this many times its
    /// largest width gets a point instead of a line.
    pub min_elongation: f64,
    /// Every part, or only the largest part of a feature.
    pub parts: Parts,
}

impl Default for LabelParams {
    fn default() -> Self {
        Self {
            smooth: 60.0,
            margin: 0.9,
            min_elongation: 3.0,
            parts: Parts::Each,
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
        let params = SkeletonParams {
            methods: vec![MethodId::MA],
            ..Default::default()
        };
        let raw = crate::methods::build(MethodId::MA, &params)
            .skeletonise(p, &MethodContext::default())
            .ok()?;
        let g = prune_and_extend(
            &raw,
            p,
            Some(&PruneParams::default()),
            Some(&ExtendParams::default()),
        );
        line::label(
            p,
            &raw,
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
    attributes: true,
    columns: &[
        ("polygon_part", ColumnType::Int32),
        ("kind", ColumnType::Text),
        ("length", ColumnType::Real),
        ("max_width", ColumnType::Real),
        ("elongation", ColumnType::Real),
    ],
}];

impl LabelParams {
    /// The labels of one feature's polygon parts (every part, or only the
    /// largest by area), each with the part's index: `None` for a part with
    /// no medial axis (thinner than the axis's grid).
    pub fn labels(&self, parts: &[PreparedPolygon]) -> Vec<(usize, Option<Labelled>)> {
        use geo::Area;
        let mut parts: Vec<(usize, &PreparedPolygon)> = parts.iter().enumerate().collect();
        if self.parts == Parts::Largest {
            parts.sort_by(|a, b| {
                b.1.polygon()
                    .unsigned_area()
                    .total_cmp(&a.1.polygon().unsigned_area())
            });
            parts.truncate(1);
        }
        parts.into_iter().map(|(i, p)| (i, self.label(p))).collect()
    }
}

impl FeatureStep for LabelParams {
    fn rows(&self, input: &StepInput<'_>) -> Vec<(&'static str, StepRow)> {
        self.labels(input.parts)
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
                    Cell::Int(i as i64),
                    Cell::Text(kind.into()),
                    real(|l| l.length),
                    real(|l| l.max_width),
                    real(|l| l.elongation),
                ];
                ("labels", StepRow { geometry, cells })
            })
            .collect()
    }
}

/// The `label` step's entry in the step registry.
pub const ENTRY: StepEntry = StepEntry {
    name: "label",
    after: "skeleton",
    description: "one label per polygon part: a smooth line along the medial axis where the part is elongated, else the centre of its largest inscribed disc (layer `labels`)",
    options: &[
        ("smooth", "most the line turns over one local width, degrees (60)"),
        ("margin", "fraction of the local radius kept from the shore (0.9: the line stays within 0.1 r of the medial axis)"),
        ("min_elongation", "length / largest width below which a part gets a point (3)"),
        ("parts", "`each` (default) or `largest`: which parts of a feature get a label"),
    ],
    layers: LABELS,
    build: |v| {
        let p: LabelParams = if v.is_null() {
            LabelParams::default()
        } else {
            serde_json::from_value(v.clone()).map_err(|e| (String::new(), e.to_string()))?
        };
        p.validate()?;
        Ok(Arc::new(p))
    },
};
