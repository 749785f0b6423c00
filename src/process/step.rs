//! Steps registered beside the built-in ones: a step is one [`StepEntry`] —
//! its name, its place in the step order, its options (a type of its own:
//! their JSON Schema for `skeletonise schema`, `skeletonise methods` and
//! QGIS, parsed from the pipeline file by its own `build`), what it
//! [needs](Needs) beyond the feature (the medial axis's raw skeleton or its
//! diagram cells, the chosen graphs, longitude and latitude, a side input
//! layer, the coverage of `input.neighbours`, adjacent polygons merged
//! exactly), the layers it writes ([`StepLayer`]s, declared next to its
//! code) — and a [`FeatureStep`] that turns each feature's outcome into
//! rows of those layers (or rejects the feature with a reason), may keep a
//! value of each feature for later ([`FeatureStep::output`]) and, after the
//! last feature, may add rows of its own ([`FeatureStep::finish`],
//! [`FeatureStep::finish_rows`]; or stop the run with a reason). It may check
//! its options against the rest of the pipeline ([`FeatureStep::check`]).
//! The run records each registered step's CPU time under its name.
//! `partition`, `label` and `streets` are such steps.
//! Parsing (`config::load_with`), validation, the output plan, the run
//! driver (`process::Run`), the writer, the Python table and
//! `skeletonise methods` follow from the entry, as a method follows from
//! its `MethodEntry`.
//!
//! ```
//! use skeletonise::output::{Cell, ColumnType, GeometryKind, StepLayer, StepRow};
//! use skeletonise::process::step::{FeatureStep, StepEntry, StepInput, StepRows};
//!
//! /// Writes each feature's number of polygon parts.
//! #[derive(Debug)]
//! struct Parts;
//!
//! impl FeatureStep for Parts {
//!     fn rows(&self, input: &StepInput<'_>) -> StepRows {
//!         let cells = vec![("parts", Cell::Int(input.parts.len() as i64))];
//!         Ok(vec![("parts", StepRow { geometry: None, cells })])
//!     }
//! }
//!
//! const LAYERS: &[StepLayer] = &[StepLayer {
//!     name: "parts",
//!     geometry: GeometryKind::None,
//!     fields: None,
//!     columns: &[("parts", ColumnType::Int32)],
//! }];
//!
//! let registry = skeletonise::config::builtin_steps().with(StepEntry {
//!     name: "parts",
//!     after: "select",
//!     description: "the number of polygon parts of every feature",
//!     schema: || schemars::json_schema!({ "type": ["object", "null"] }),
//!     needs: skeletonise::process::step::Needs::NOTHING,
//!     layers: LAYERS,
//!     build: |_| Ok(std::sync::Arc::new(Parts)),
//! });
//! assert!(registry.get("parts").is_some());
//! ```

use super::FeatureOutcome;
use crate::geometry::PreparedPolygon;
use crate::layer::{LayerSource, StepLayer, StepRow};
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
    /// step [needs them](Needs::lonlat) and the run knows its CRS (a GDAL
    /// source does; a library caller may not).
    pub lonlat: Option<&'a LonLat>,
    /// The medial axis's raw skeleton of every polygon part, as the
    /// `skeleton` step made it with MA's default options, when the step
    /// [needs it](Needs::medial_axis) and MA succeeded; `None` otherwise
    /// (the step makes its own).
    pub medial_axis: Option<&'a [std::sync::Arc<crate::graph::SkeletonGraph>]>,
    /// The step's side input layer, when it [has one](Needs::side) and the
    /// pipeline gives it.
    pub side: Option<&'a SideLayer>,
    /// The coverage of `input.neighbours`, when the step
    /// [needs it](Needs::neighbours) (validation makes sure the pipeline
    /// gives it; a library caller may not).
    pub neighbours: Option<&'a crate::neighbours::Coverage>,
    /// The cells of MA's segment Voronoi diagram of every polygon part, when
    /// the step [needs them](Needs::cells) and MA succeeded: taken out of
    /// the candidate (no later step reads them), for the step to take in
    /// turn; their time is counted as the step's.
    pub cells: Option<&'a std::cell::RefCell<Vec<DiagramCells>>>,
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

/// Why a registered step rejects a feature (its reason in `rejected`, after
/// the step's name), or why its [finish](FeatureStep::finish) stops the run:
/// what went wrong, where, and how to fix it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct StepFailure(pub String);

impl From<String> for StepFailure {
    fn from(reason: String) -> Self {
        Self(reason)
    }
}

impl From<&str> for StepFailure {
    fn from(reason: &str) -> Self {
        Self(reason.into())
    }
}

/// A registered step's rows, each with its layer's name, or why it failed.
pub type StepRows = Result<Vec<(&'static str, StepRow)>, StepFailure>;

/// The cells of MA's segment Voronoi diagram of one polygon part (see
/// [`StepInput::cells`]).
pub type DiagramCells = Arc<crate::methods::medial_axis::cells::DiagramCells>;

pub use crate::output::Kept;

/// A step's work on one feature in full: its rows and what it keeps for
/// its finish.
pub type StepOutput = Result<(Vec<(&'static str, StepRow)>, Option<Kept>), StepFailure>;

/// What a step's [`FeatureStep::finish_rows`] makes after the last feature.
#[derive(Debug, Default)]
pub struct Finished {
    /// Rows of the step's layers, each with its layer, its `src_fid` (NULL
    /// for a summary; a side input feature's FID for a row of it) and the
    /// fields the layer carries (none, or the side input feature's).
    pub rows: Vec<(&'static str, crate::output::ExtraRow)>,
    /// Figures of the run the step reports (`area_held`), each under a name
    /// of a column of the run record (`skeletonise_runs`) that it fills.
    pub figures: Vec<(&'static str, f64)>,
}

/// What the pipeline around a step holds, for the step's own
/// [checks](FeatureStep::check): the methods of the `skeleton` step and the
/// names of the pipeline's steps, in order.
#[derive(Debug, Clone, Copy)]
pub struct StepContext<'a> {
    /// `skeleton.methods`.
    pub methods: &'a [crate::methods::MethodId],
    /// Every step's name.
    pub steps: &'a [&'a str],
}

/// A registered step's work on one feature: rows of its own layers, each
/// with the layer's name.
pub trait FeatureStep: Send + Sync + std::fmt::Debug + std::panic::RefUnwindSafe {
    /// The rows of the step's layers for one feature; an error rejects the
    /// feature (every row of it, as a method's failure on every part
    /// does), with the step's name and the reason in `rejected`, and the
    /// run goes on (or stops under `on_error: fail`).
    fn rows(&self, input: &StepInput<'_>) -> StepRows;

    /// [`Self::rows`] and what the step keeps of the feature for its
    /// [finish](Self::finish_rows) when its entry [keeps](Needs::finish)
    /// (the run calls this one; a step that keeps nothing writes `rows`
    /// alone).
    fn output(&self, input: &StepInput<'_>) -> StepOutput {
        self.rows(input).map(|rows| (rows, None))
    }

    /// Rows of the step's layers made once, after the last feature (a
    /// summary, what is left of the side input): written without source
    /// fields, `src_fid` NULL. `input.rows` holds the step's per-feature
    /// rows when its entry [keeps them](Needs::finish). An error stops the
    /// run (exit 65) and no output is written: for what cannot be made
    /// right afterwards, such as a coverage that would not be valid.
    fn finish(&self, input: &FinishInput<'_>) -> StepRows {
        let _ = input;
        Ok(Vec::new())
    }

    /// [`Self::finish`] in full (the run calls this one): rows with their
    /// own `src_fid` and fields, and the run's figures the step reports.
    fn finish_rows(&self, input: &FinishInput<'_>) -> Result<Finished, StepFailure> {
        let rows = self.finish(input)?;
        Ok(Finished {
            rows: rows
                .into_iter()
                .map(|(layer, row)| (layer, crate::output::ExtraRow::summary(row)))
                .collect(),
            figures: Vec::new(),
        })
    }

    /// What the step needs of the run, from what its entry declares (a step
    /// whose options need less may say so: `partition` reads MA's graphs
    /// only with `width`).
    fn needs(&self, declared: Needs) -> Needs {
        declared
    }

    /// Checks the step's options against the rest of the pipeline (a method
    /// they need, a step they cannot run with): `(key within the step,
    /// message)`.
    fn check(&self, context: &StepContext<'_>) -> Result<(), OptionError> {
        let _ = context;
        Ok(())
    }
}

/// What a registered step's [`FeatureStep::finish`] sees: the rows it made
/// for every feature (with the feature's FID, in read order) when its entry
/// keeps them, and its side input.
#[derive(Debug, Clone, Copy)]
pub struct FinishInput<'a> {
    /// `(src_fid, layer, row)` of every feature, when [`Needs::finish`].
    pub rows: &'a [(Option<u64>, &'static str, StepRow)],
    /// What the step [kept](FeatureStep::output) of every feature, with its
    /// `src_fid`, in read order, when [`Needs::finish`]: the step may take
    /// them (`kept.take()`) to own them without a copy.
    pub kept: &'a std::cell::RefCell<Vec<(Option<u64>, Kept)>>,
    /// The step's side input layer, when it has one.
    pub side: Option<&'a SideLayer>,
    /// The coverage of `input.neighbours`, when the step needs it.
    pub neighbours: Option<&'a crate::neighbours::Coverage>,
}

/// What a registered step needs beyond its feature's polygon parts and the
/// outcome of the steps before it. The run gives exactly what the steps of
/// a pipeline need together: the `skeleton` step keeps MA's raw skeleton
/// only for a step that reads it, longitude and latitude are made only for
/// a step that reads them, and a side input is read only for a step that
/// has one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Needs {
    /// The medial axis's raw skeleton of every part ([`StepInput::medial_axis`]).
    pub medial_axis: bool,
    /// Longitude and latitude of the run's coordinates ([`StepInput::lonlat`]).
    pub lonlat: bool,
    /// The key of the step's option that names a side input layer (a
    /// [`LayerSource`]: `source`, `layer`, `where`), read through the same
    /// path as `input.neighbours` and `input.connect`, reprojected to the
    /// polygons' CRS ([`StepInput::side`]), checked by `validate` and never
    /// written over; the Python package takes it as a GeoDataFrame
    /// (`apply_layers(sides=…)`), QGIS opens it from the pipeline file.
    pub side: Option<&'static str>,
    /// The run keeps the step's per-feature rows for its
    /// [`FeatureStep::finish`].
    pub finish: bool,
    /// The cells of the medial axis's segment Voronoi diagram of every
    /// part (what `partition` splits the polygon along), kept by the
    /// `skeleton` step when MA is among the methods.
    pub cells: bool,
    /// The chosen method's graphs of every part (pruned and extended), kept
    /// in the candidate beside its lines.
    pub graphs: bool,
    /// Adjacent polygons merged into one, exactly (every vertex kept),
    /// before any step sees them: the reader (or the Python call) merges
    /// them, and the `members` column lists the FIDs.
    pub merge: bool,
    /// The coverage of `input.neighbours` ([`StepInput::neighbours`]):
    /// validation asks for it, the command line reads it (reprojected to
    /// the polygons' CRS), the Python package takes it as a GeoDataFrame.
    pub neighbours: bool,
}

impl Needs {
    /// Nothing beyond the feature.
    pub const NOTHING: Needs = Needs {
        medial_axis: false,
        lonlat: false,
        side: None,
        finish: false,
        cells: false,
        graphs: false,
        merge: false,
        neighbours: false,
    };

    /// What `self` and `other` need together (the first side input key).
    pub const fn and(self, other: Needs) -> Needs {
        Needs {
            medial_axis: self.medial_axis || other.medial_axis,
            lonlat: self.lonlat || other.lonlat,
            side: match self.side {
                Some(s) => Some(s),
                None => other.side,
            },
            finish: self.finish || other.finish,
            cells: self.cells || other.cells,
            graphs: self.graphs || other.graphs,
            merge: self.merge || other.merge,
            neighbours: self.neighbours || other.neighbours,
        }
    }
}

/// A side input layer's features, reprojected to the polygons' CRS, with an
/// index of their bounding boxes.
#[derive(Debug, Default)]
pub struct SideLayer {
    features: Vec<(Option<u64>, geo::Geometry<f64>)>,
    index: rstar::RTree<
        rstar::primitives::GeomWithData<rstar::primitives::Rectangle<[f64; 2]>, usize>,
    >,
}

impl SideLayer {
    /// The layer of `features` (FID and geometry; empty geometries are kept
    /// but never near anything).
    pub fn new(features: Vec<(Option<u64>, geo::Geometry<f64>)>) -> Self {
        use geo::BoundingRect;
        use rstar::primitives::{GeomWithData, Rectangle};
        let boxes = features
            .iter()
            .enumerate()
            .filter_map(|(i, (_, g))| {
                let r = g.bounding_rect()?;
                let rect = Rectangle::from_corners([r.min().x, r.min().y], [r.max().x, r.max().y]);
                Some(GeomWithData::new(rect, i))
            })
            .collect();
        Self {
            features,
            index: rstar::RTree::bulk_load(boxes),
        }
    }

    /// Every feature: FID and geometry, in read order.
    pub fn features(&self) -> &[(Option<u64>, geo::Geometry<f64>)] {
        &self.features
    }

    /// The indices (into [`Self::features`]) of the features whose bounding
    /// boxes meet `rect`, ascending.
    pub fn near(&self, rect: geo::Rect<f64>) -> Vec<usize> {
        let env =
            rstar::AABB::from_corners([rect.min().x, rect.min().y], [rect.max().x, rect.max().y]);
        let mut found: Vec<usize> = self
            .index
            .locate_in_envelope_intersecting(&env)
            .map(|g| g.data)
            .collect();
        found.sort_unstable();
        found
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
    /// The JSON Schema of its options (e.g. `|| schemars::schema_for!(T)`):
    /// `skeletonise schema` and `skeletonise methods` list them, QGIS makes
    /// its parameters from them.
    pub schema: fn() -> schemars::Schema,
    /// What it needs beyond the feature.
    pub needs: Needs,
    /// The layers it writes.
    pub layers: &'static [StepLayer],
    /// The step from its options (the YAML mapping under its key, as JSON).
    pub build: fn(&serde_json::Value) -> Result<Arc<dyn FeatureStep>, OptionError>,
}

/// A registered step's options as `T`, from the YAML mapping under its key
/// (as JSON; null as an empty mapping): a wrong value is reported at its
/// key (`parts`, not the step), with serde's reason.
pub fn step_options<T: serde::de::DeserializeOwned>(
    v: &serde_json::Value,
) -> Result<T, OptionError> {
    let v = match v {
        serde_json::Value::Null => serde_json::json!({}),
        v => v.clone(),
    };
    serde_path_to_error::deserialize(v).map_err(|e| {
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

impl StepEntry {
    /// Whether every row of `rows` is of a layer this step declares and
    /// fits it ([`StepLayer::check`]); else a failure that says the step
    /// made a row it cannot have (a bug in the step, reported as such).
    pub fn check(&self, rows: &[(&'static str, StepRow)]) -> Result<(), StepFailure> {
        self.check_each(rows.iter().map(|(name, row)| (*name, row)))
    }

    /// [`Self::check`] of rows given one by one.
    pub fn check_each<'r>(
        &self,
        rows: impl IntoIterator<Item = (&'static str, &'r StepRow)>,
    ) -> Result<(), StepFailure> {
        for (name, row) in rows {
            let layer = self.layers.iter().find(|l| l.name == name).ok_or_else(|| {
                StepFailure(format!(
                    "internal error in the step: a row of layer `{name}`, which it does not declare; please report it"
                ))
            })?;
            layer.check(row).map_err(|why| {
                StepFailure(format!(
                    "internal error in the step: {why}; please report it"
                ))
            })?;
        }
        Ok(())
    }

    /// `made` when its rows all [fit](Self::check) the step's layers.
    pub fn checked(&self, made: StepRows) -> StepRows {
        made.and_then(|rows| self.check(&rows).map(|()| rows))
    }

    /// [`Self::checked`] of a step's [full output](FeatureStep::output).
    pub fn checked_output(&self, made: StepOutput) -> StepOutput {
        made.and_then(|(rows, kept)| self.check(&rows).map(|()| (rows, kept)))
    }

    /// [`Self::checked`] of a step's [finish](FeatureStep::finish_rows).
    pub fn checked_finish(
        &self,
        made: Result<Finished, StepFailure>,
    ) -> Result<Finished, StepFailure> {
        made.and_then(|f| {
            self.check_each(f.rows.iter().map(|(name, r)| (*name, &r.row)))
                .map(|()| f)
        })
    }
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
    /// Its side input layer, once the caller has read it (or been given
    /// it): see [`Needs::side`].
    pub side: Option<Arc<SideLayer>>,
}

impl Extra {
    /// The side input layer its options name, when the step has one and the
    /// pipeline file gives it: `(its key, the layer)`.
    pub fn side_source(&self) -> Option<(&'static str, Result<LayerSource, serde_json::Error>)> {
        let key = self.entry.needs.side?;
        let v = self.options.get(key).filter(|v| !v.is_null())?;
        Some((key, serde_json::from_value(v.clone())))
    }
}

impl PartialEq for Extra {
    fn eq(&self, other: &Self) -> bool {
        self.entry.name == other.entry.name && self.options == other.options
    }
}
