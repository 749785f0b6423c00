//! Steps registered beside the built-in ones: a step is one [`StepEntry`] —
//! its name, its place in the step order, its options (parsed from the
//! pipeline file by its own `build`), the layers it writes
//! ([`StepLayer`]s, declared next to its code) — and a [`FeatureStep`] that
//! turns each feature's outcome into rows of those layers. Parsing
//! (`config::load_with`), validation, the output plan, the writer, the
//! Python table and `skeletonise methods` follow from the entry, as a
//! method follows from its `MethodEntry`.
//!
//! ```
//! use skeletonise::output::{Cell, ColumnType, GeometryKind, StepLayer, StepRow};
//! use skeletonise::process::step::{FeatureStep, StepEntry, StepInput};
//!
//! /// Writes each feature's number of polygon parts.
//! #[derive(Debug)]
//! struct Parts;
//!
//! impl FeatureStep for Parts {
//!     fn rows(&self, input: &StepInput<'_>) -> Vec<(&'static str, StepRow)> {
//!         let cells = vec![Cell::Int(input.parts.len() as i64)];
//!         vec![("parts", StepRow { geometry: None, cells })]
//!     }
//! }
//!
//! const LAYERS: &[StepLayer] = &[StepLayer {
//!     name: "parts",
//!     geometry: GeometryKind::None,
//!     attributes: false,
//!     columns: &[("parts", ColumnType::Int32)],
//! }];
//!
//! let registry = skeletonise::config::builtin_steps().with(StepEntry {
//!     name: "parts",
//!     after: "select",
//!     description: "the number of polygon parts of every feature",
//!     options: &[],
//!     layers: LAYERS,
//!     build: |_| Ok(std::sync::Arc::new(Parts)),
//! });
//! assert!(registry.get("parts").is_some());
//! ```

use super::FeatureOutcome;
use crate::geometry::PreparedPolygon;
use crate::layer::{StepLayer, StepRow};
use crate::methods::MethodContext;
use std::sync::Arc;

/// What a registered step sees of one feature (or one polygon part with
/// `explode`): its prepared polygon parts and the outcome of the steps
/// before it (every method's candidate, the chosen one, collapse, legs).
#[derive(Debug, Clone, Copy)]
pub struct StepInput<'a> {
    /// The polygon parts, normalised.
    pub parts: &'a [PreparedPolygon],
    /// The outcome so far.
    pub outcome: &'a FeatureOutcome,
    /// The run's coordinates as longitude and latitude (degrees), when the
    /// run knows its CRS (a GDAL source does; a library caller may not).
    pub lonlat: Option<&'a LonLat>,
    /// The medial axis's raw skeleton of every polygon part, as the
    /// `skeleton` step made it with MA's default options, when a step
    /// [uses it](FeatureStep::uses_medial_axis) and MA succeeded; `None`
    /// otherwise (the step makes its own).
    pub medial_axis: Option<&'a [std::sync::Arc<crate::graph::SkeletonGraph>]>,
    /// The clock of the steps after `select` on this feature
    /// (`skeleton.timeout_s` once more): a step with long work asks
    /// [`MethodContext::expired`] and stops; rows that come after the
    /// deadline are dropped and the feature rejected naming the step.
    pub budget: &'a MethodContext,
}

/// A map from the run's coordinates to longitude and latitude in degrees
/// (`None` where it cannot be done): what a step needs that depends on
/// where on Earth a feature lies (a label's minimum web-map zoom).
#[derive(Clone)]
pub struct LonLat(
    Arc<
        dyn Fn(geo::Coord<f64>) -> Option<geo::Coord<f64>>
            + Send
            + Sync
            + std::panic::RefUnwindSafe,
    >,
);

impl LonLat {
    /// The map `f`.
    pub fn new(
        f: impl Fn(geo::Coord<f64>) -> Option<geo::Coord<f64>>
            + Send
            + Sync
            + std::panic::RefUnwindSafe
            + 'static,
    ) -> Self {
        Self(Arc::new(f))
    }

    /// Longitude and latitude of `c`.
    pub fn of(&self, c: geo::Coord<f64>) -> Option<geo::Coord<f64>> {
        (self.0)(c)
    }
}

impl std::fmt::Debug for LonLat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LonLat")
    }
}

impl PartialEq for LonLat {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A registered step's work on one feature: rows of its own layers, each
/// with the layer's name.
pub trait FeatureStep: Send + Sync + std::fmt::Debug + std::panic::RefUnwindSafe {
    /// The rows of the step's layers for one feature.
    fn rows(&self, input: &StepInput<'_>) -> Vec<(&'static str, StepRow)>;

    /// True when the step reads the medial axis's raw skeleton
    /// ([`StepInput::medial_axis`]): the `skeleton` step then keeps the one
    /// it made (with MA among its methods and MA's default options) rather
    /// than the step making it again.
    fn uses_medial_axis(&self) -> bool {
        false
    }
}

/// Why a step's options are wrong: the key within the step and what to do.
pub type OptionError = (String, String);

/// One registered step.
#[derive(Debug, Clone, Copy)]
pub struct StepEntry {
    /// Its key in the pipeline file's `steps`.
    pub name: &'static str,
    /// The built-in step it runs after (its place in `Step::ORDER`).
    pub after: &'static str,
    /// One line for `skeletonise methods`.
    pub description: &'static str,
    /// Its options: name and meaning, for `skeletonise methods`.
    pub options: &'static [(&'static str, &'static str)],
    /// The layers it writes.
    pub layers: &'static [StepLayer],
    /// The step from its options (the YAML mapping under its key, as JSON).
    pub build: fn(&serde_json::Value) -> Result<Arc<dyn FeatureStep>, OptionError>,
}

/// A registered step's options as `T`, from the YAML mapping under its key
/// (as JSON; null: `T::default()`): a wrong value is reported at its key
/// (`parts`, not the step), with serde's reason.
pub fn step_options<T: serde::de::DeserializeOwned + Default>(
    v: &serde_json::Value,
) -> Result<T, OptionError> {
    if v.is_null() {
        return Ok(T::default());
    }
    serde_path_to_error::deserialize(v.clone()).map_err(|e| {
        let key = e.path().to_string();
        let key = if key == "." { String::new() } else { key };
        (key, e.into_inner().to_string())
    })
}

/// Registered steps: those every pipeline file may use
/// ([`crate::config::builtin_steps`], assembled above the steps), and what a
/// caller adds (the other built-in steps are the variants of
/// `config::Step`).
#[derive(Debug, Clone, Default)]
pub struct StepRegistry {
    entries: Vec<StepEntry>,
}

impl StepRegistry {
    /// This registry and `entry`.
    pub fn with(mut self, entry: StepEntry) -> Self {
        self.entries.retain(|e| e.name != entry.name);
        self.entries.push(entry);
        self
    }

    /// The entry of step `name`.
    pub fn get(&self, name: &str) -> Option<&StepEntry> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// Every entry.
    pub fn entries(&self) -> &[StepEntry] {
        &self.entries
    }
}

/// A registered step of a pipeline: its entry, its options and the step.
#[derive(Debug, Clone)]
pub struct Extra {
    /// The entry.
    pub entry: StepEntry,
    /// The options as written.
    pub options: serde_json::Value,
    /// The step.
    pub step: Arc<dyn FeatureStep>,
}

impl PartialEq for Extra {
    fn eq(&self, other: &Self) -> bool {
        self.entry.name == other.entry.name && self.options == other.options
    }
}
