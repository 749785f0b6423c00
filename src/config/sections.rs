//! The `input` and `output` sections of a pipeline file.

pub use crate::layer::{LayerRef, LayerSource};
use crate::report::Selection;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The `input` section of a pipeline file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// Any OGR data source string: file, folder, `PG:…`, `/vsizip/…`.
    pub source: String,
    /// Layer name or zero-based index; default the first layer.
    #[serde(default)]
    pub layer: Option<LayerRef>,
    /// OGR SQL attribute filter.
    #[serde(default, rename = "where")]
    pub where_: Option<String>,
    /// Spatial filter `[xmin, ymin, xmax, ymax]` in the source CRS.
    #[serde(default)]
    pub bbox: Option<[f64; 4]>,
    /// Target CRS (e.g. `EPSG:3035`); required when the source CRS is geographic.
    #[serde(default)]
    pub reproject: Option<String>,
    /// Process polygons that share boundary (river reaches, tiles, map sheets) as one: each group is dissolved before skeletonising, and the `members` column lists its FIDs.
    #[serde(default)]
    pub merge_adjacent: bool,
    /// With `merge_adjacent`: merge only polygons with the same value of this source field.
    #[serde(default)]
    pub merge_by: Option<String>,
    /// A line network (any OGR source and layer of lines, e.g. the rivers) to continue through the polygons: where a line touches or crosses a polygon's boundary (or ends within `snap` of it) the skeleton gets a leg to that point (layer `connections`).
    #[serde(default)]
    pub connect: Option<ConnectSpec>,
    /// A coverage of units read beside the polygons, for a step that reads it (the units that take the polygons' area): any OGR source and layer of polygons, reprojected to the polygons' CRS; only the units that pass its `where` are read, written and own anything.
    #[serde(default)]
    pub neighbours: Option<NeighboursSpec>,
}

/// The `input.neighbours` section: a coverage of units read beside the
/// polygons (the units a step gives the polygons' area to).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NeighboursSpec {
    /// Any OGR data source string of polygons (may be the same file as `input.source`).
    pub source: String,
    /// Layer name or zero-based index; default the first layer.
    #[serde(default)]
    pub layer: Option<LayerRef>,
    /// OGR SQL attribute filter: only these units are read, written and own bank.
    #[serde(default, rename = "where")]
    pub where_: Option<String>,
    /// Unit vertices and edges within this distance of a collapsed polygon's bank are moved onto it exactly, and gaps narrower than it closed (CRS units of the polygons). Default: 1e-7 × each polygon's extent (1 cm on a 100 km river), above the round-off of a reprojection.
    #[serde(default)]
    pub snap: Option<f64>,
}

impl NeighboursSpec {
    /// The coverage's layer.
    pub fn layer_source(&self) -> LayerSource {
        LayerSource {
            source: self.source.clone(),
            layer: self.layer.clone(),
            where_: self.where_.clone(),
        }
    }

    /// The coverage as an input of its own, reprojected to `crs` (the CRS
    /// the polygons are handed out in, as WKT; `None` when they have none).
    pub fn input(&self, crs: Option<&str>) -> InputSpec {
        self.layer_source().input(crs)
    }
}

/// The `input.connect` section: the line network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConnectSpec {
    /// Any OGR data source string of lines, in any CRS: reprojected to the CRS the polygons are processed in.
    pub source: String,
    /// Layer name or zero-based index; default the first layer.
    #[serde(default)]
    pub layer: Option<LayerRef>,
    /// A line end within this distance of a polygon's boundary connects (CRS units; default 0: lines that touch or cross it, and line ends within the round-off of a reprojection, 1e-7 × the polygon's extent, of it).
    #[serde(default)]
    pub snap: f64,
}

impl ConnectSpec {
    /// The network's layer.
    pub fn layer_source(&self) -> LayerSource {
        LayerSource {
            source: self.source.clone(),
            layer: self.layer.clone(),
            where_: None,
        }
    }

    /// The network's lines as an input of their own, reprojected to `crs`
    /// (a definition GDAL reads: the CRS the polygons are handed out in,
    /// as WKT; `None` when they have none).
    pub fn input(&self, crs: Option<&str>) -> InputSpec {
        self.layer_source().input(crs)
    }
}

impl LayerSource {
    /// The layer as an input of its own, reprojected to `crs` (the CRS the
    /// polygons are handed out in, as WKT; `None` when they have none).
    pub fn input(&self, crs: Option<&str>) -> InputSpec {
        InputSpec {
            source: self.source.clone(),
            layer: self.layer.clone(),
            where_: self.where_.clone(),
            bbox: None,
            reproject: crs.map(str::to_string),
            merge_adjacent: false,
            merge_by: None,
            connect: None,
            neighbours: None,
        }
    }
}

impl InputSpec {
    /// Checks the section: `(key, message)` of the first wrong option.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if self.source.trim().is_empty() {
            return Err(("source".into(), "give the input data source".into()));
        }
        if self.merge_by.is_some() && !self.merge_adjacent {
            return Err((
                "merge_by".into(),
                "merge_by only applies with `merge_adjacent: true`; set it, or remove merge_by"
                    .into(),
            ));
        }
        if let Some(c) = &self.connect {
            if c.source.trim().is_empty() {
                return Err((
                    "connect.source".into(),
                    "give the line network's data source".into(),
                ));
            }
            if !(c.snap.is_finite() && c.snap >= 0.0) {
                return Err(("connect.snap".into(), "snap must be ≥ 0 (CRS units)".into()));
            }
        }
        if let Some(n) = &self.neighbours {
            if n.source.trim().is_empty() {
                return Err((
                    "neighbours.source".into(),
                    "give the coverage's data source".into(),
                ));
            }
            if n.snap.is_some_and(|s| !(s.is_finite() && s >= 0.0)) {
                return Err((
                    "neighbours.snap".into(),
                    "snap must be ≥ 0 (CRS units of the polygons); leave it out for 1e-7 × each polygon's extent".into(),
                ));
            }
        }
        if let Some([x0, y0, x1, y1]) = self.bbox {
            if ![x0, y0, x1, y1].iter().all(|v| v.is_finite()) {
                return Err((
                    "bbox".into(),
                    "bbox values must be finite numbers [xmin, ymin, xmax, ymax] in the source CRS"
                        .into(),
                ));
            }
            if x0 > x1 || y0 > y1 {
                return Err((
                    "bbox".into(),
                    format!("bbox [{x0}, {y0}, {x1}, {y1}] is empty: xmin ≤ xmax and ymin ≤ ymax"),
                ));
            }
        }
        Ok(())
    }

    /// A whole layer of a source by name: no filter, no reprojection.
    pub fn layer(source: &str, layer: &str) -> Self {
        Self {
            source: source.into(),
            layer: Some(LayerRef::Name(layer.into())),
            where_: None,
            bbox: None,
            reproject: None,
            merge_adjacent: false,
            merge_by: None,
            connect: None,
            neighbours: None,
        }
    }
}

fn default_layer() -> String {
    "skeletons".into()
}

/// The `output` section of a pipeline file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Path of the GeoPackage to write.
    pub path: String,
    /// Name of the skeleton layer.
    #[serde(default = "default_layer")]
    pub layer: String,
    /// Replace an existing output file.
    #[serde(default)]
    pub overwrite: bool,
    /// Also write every method's skeleton and scores (layer `candidates`).
    #[serde(default)]
    pub candidates: bool,
    /// Also write the scoring bars (layer `bars`).
    #[serde(default)]
    pub bars: bool,
    /// One row per polygon part instead of per feature.
    #[serde(default)]
    pub explode: bool,
    /// Also write the chosen skeleton segment by segment with the local width
    /// of the polygon (2 × disc radius) at both ends (layer `widths`): the
    /// medial axis transform, for deciding what is narrow enough to collapse.
    #[serde(default)]
    pub widths: bool,
    /// `width`: the skeleton layer's lines carry an M value per vertex, the polygon's local width 2r there (XYM geometry), so that a symbol can be drawn with the river's real width; `none` (default): XY.
    #[serde(default)]
    pub measures: Measures,
    /// Also write the visual report: one self-contained HTML file with every
    /// method's skeleton of the selected features side by side, their score
    /// tables and a summary of the run (`skeletonise report` makes it from
    /// any output later).
    #[serde(default)]
    pub report: Option<ReportSpec>,
}

/// What the skeleton layer's M values hold (`output.measures`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Measures {
    /// No M values (XY lines).
    #[default]
    None,
    /// The local width 2r at every vertex.
    Width,
}

impl OutputSpec {
    /// Where the report goes: `report.path`, or the GeoPackage's path with
    /// the extension `.html`; `None` without a report.
    pub fn report_path(&self) -> Option<PathBuf> {
        let r = self.report.as_ref()?;
        Some(match &r.path {
            Some(p) => PathBuf::from(p),
            None => PathBuf::from(&self.path).with_extension("html"),
        })
    }
}

/// The `output.report` section: the visual report written after the run.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReportSpec {
    /// Path of the HTML file; default the output's path with `.html`.
    #[serde(default)]
    pub path: Option<String>,
    /// The features that get a section: `{top: N}` (default 20: those on
    /// which the methods disagree most), `{fids: [..]}` or `{where: "SQL"}`
    /// (OGR SQL on the skeleton layer's columns).
    #[serde(default)]
    pub features: Selection,
}
