//! The visual report: one self-contained HTML file (inline SVG, CSS and
//! script, no network access) that shows what the paper's Figs. 7–9 show —
//! each feature's polygon with every method's final skeleton side by side
//! and the table of its scores — together with a summary of the whole file.
//!
//! - **Summary**: per method the features won, mean Z, s, S, coverage and
//!   legs, the chosen-method counts, and the run's provenance from
//!   `skeletonise_runs`.
//! - **A section per selected feature** ([`Selection`]): small multiples of
//!   the polygon (grey) with each method's skeleton (the chosen one framed),
//!   the bars coloured by z on demand, the score table; the panels of a
//!   section pan and zoom together, and a click on a line shows the node
//!   radius r (distance to ∂P) and the width 2r there.
//! - **Bounded size**: polygons, skeletons and bars are simplified for
//!   display only ([`POLYGON_VERTICES`], [`SKELETON_VERTICES`],
//!   [`BARS_PER_METHOD`]), so a section never takes more than
//!   [`section_bound`] bytes whatever the size of the feature.
//!
//! This module is pure: it renders a [`Report`] made of the output's own row
//! types. Reading the GeoPackage and the polygons is [`crate::reporting`]'s.
//!
//! ```
//! use skeletonise::report::{render, Report};
//! let html = render(&Report {
//!     title: "empty".into(),
//!     run: None,
//!     units: "m".into(),
//!     features: 0,
//!     summary: Vec::new(),
//!     selection: "none".into(),
//!     sections: Vec::new(),
//!     notes: Vec::new(),
//! });
//! assert!(html.starts_with("<!DOCTYPE html>") && !html.contains("http://") && !html.contains("https://"));
//! ```

mod draw;
mod page;
pub mod summary;

pub use draw::{section_bound, BARS_PER_METHOD, POLYGON_VERTICES, SKELETON_VERTICES, Z_CLASSES};
pub use summary::{by_feature, disagreement, ranked, summarise, Key, MethodSummary, Selection};

use crate::output::{BarRow, CandidateRow, RunRecord};

/// Everything the report shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The page's title (the run's name and layer).
    pub title: String,
    /// The run that wrote the file.
    pub run: Option<RunRecord>,
    /// Short name of the CRS unit (`m`), for s, S, r and widths.
    pub units: String,
    /// Features in the file (with candidates).
    pub features: usize,
    /// Every method's statistics over all features.
    pub summary: Vec<MethodSummary>,
    /// How the sections were chosen, in words.
    pub selection: String,
    /// The features shown.
    pub sections: Vec<Section>,
    /// Remarks on the whole report (e.g. bars recomputed).
    pub notes: Vec<String>,
}

/// One feature (or polygon part) shown with every method's skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Polygon part, with `explode`.
    pub polygon_part: Option<usize>,
    /// Source fields worth a heading: `(name, value)`.
    pub attributes: Vec<(String, String)>,
    /// The polygon, when it could be read.
    pub polygon: Option<geo::MultiPolygon<f64>>,
    /// Every method's candidate with its skeleton, in method order.
    pub candidates: Vec<CandidateRow>,
    /// The bars of every method.
    pub bars: Vec<BarRow>,
    /// How much the methods disagree ([`disagreement`]).
    pub disagreement: f64,
    /// Remarks on this feature (e.g. polygon not found).
    pub notes: Vec<String>,
}

/// The report as one self-contained HTML page.
pub fn render(report: &Report) -> String {
    page::page(report)
}
