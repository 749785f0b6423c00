//! `skeletonise._core`: the Rust side of the Python package.
//!
//! The Python side (`skeletonise/__init__.py`) turns a GeoSeries into WKB or
//! GeoArrow-style ragged arrays (coordinates and offsets), repairs invalid
//! polygons with shapely's `make_valid` when the `prepare` step asks for
//! it, and assembles the GeoDataFrame. This side parses the geometries, runs
//! the per-feature path of the core (`process::feature_rows`, the same as
//! the command line's) on rayon's threads with the GIL released, and hands
//! back the columns of the `skeletons` (or `candidates`) layer as the
//! declarative tables of `skeletonise::output` describe them.

mod lonlat;
mod run;
mod wkb;

/// mimalloc for the Rust side's own allocations, as in the command line
/// (numpy buffers handed to Python own their memory through a capsule that
/// frees it here, so the two allocators never meet).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use skeletonise::config::{self, ConfigError, OnError, Steps};
use skeletonise::output::{ColumnType, Plan, When};

pyo3::create_exception!(
    _core,
    PipelineError,
    PyValueError,
    "An invalid pipeline file or option; the text is the command line's (exit status 78 there)."
);
pyo3::create_exception!(
    _core,
    RejectedError,
    PyRuntimeError,
    "A feature was rejected under `on_error: fail`; the text is the command line's (exit status 65 there)."
);

pyo3::create_exception!(
    _core,
    Cancelled,
    PyRuntimeError,
    "The call was cancelled through its `Cancel` flag before every feature was done; nothing of it is returned."
);

/// A cancel flag for `Pipeline.run`: another Python thread sets it (a QGIS
/// task's cancel) and the call stops before the next feature, raising
/// `Cancelled`. The flag is read without the GIL.
#[pyclass(frozen, module = "skeletonise._core")]
#[derive(Default)]
pub struct Cancel(std::sync::Arc<std::sync::atomic::AtomicBool>);

#[pymethods]
impl Cancel {
    /// A flag not set.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Sets the flag: the calls given it stop before their next feature.
    fn set(&self) {
        self.0.store(true, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether the flag is set.
    fn is_set(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// The validated steps of a pipeline, from a file or from keyword options.
#[pyclass(frozen, module = "skeletonise._core")]
pub struct Pipeline {
    steps: Steps,
    /// The `--set` style overrides the file was loaded with: a refusal of a
    /// key one of them set names it, as the command line names it.
    overrides: Vec<String>,
    /// Made from keyword options (`from_options`): a refusal names the
    /// keyword (`prune.mode`), not the steps document's key path.
    keyword: bool,
}

/// Rewrites a key path of the steps document made from keyword options to
/// the keyword: `steps[2].prune.ratio` → `prune.ratio`; the options of
/// `prepare` and `skeleton` are keywords of their own (`steps[1].skeleton.methods` → `methods`).
fn keyword_key(key: &str) -> String {
    let Some(rest) = key.strip_prefix("steps[") else {
        return key.to_string();
    };
    let Some((_, path)) = rest.split_once("].") else {
        return key.to_string();
    };
    for flat in ["prepare.", "skeleton."] {
        if let Some(k) = path.strip_prefix(flat) {
            return k.to_string();
        }
    }
    path.to_string()
}

fn pipeline_error(e: ConfigError) -> PyErr {
    PipelineError::new_err(e.to_string())
}

impl Pipeline {
    /// The steps (every step runs here; what a GeoDataFrame cannot hold
    /// is refused by the Python functions).
    fn supported(steps: config::Steps) -> PyResult<Self> {
        Ok(Self {
            steps,
            overrides: Vec::new(),
            keyword: false,
        })
    }

    /// The coverage of `input.neighbours`, for the steps that read it
    /// (`reads`), from the units `neighbours` (WKB) and their FIDs, with
    /// `neighbour_snap` or else the pipeline file's `input.neighbours.snap`;
    /// an error when the one is given without the other.
    fn units(
        &self,
        reads: bool,
        neighbours: Option<Vec<Option<Vec<u8>>>>,
        neighbour_fids: Option<Vec<i64>>,
        neighbour_snap: Option<f64>,
    ) -> PyResult<Option<std::sync::Arc<skeletonise::neighbours::Coverage>>> {
        match (reads, neighbours) {
            (true, Some(units)) => {
                let from_file = self
                    .steps
                    .file
                    .input
                    .as_ref()
                    .and_then(|i| i.neighbours.as_ref())
                    .and_then(|n| n.snap);
                let snap = neighbour_snap.or(from_file);
                if snap.is_some_and(|s| !(s.is_finite() && s >= 0.0)) {
                    return Err(PipelineError::new_err(
                        "`neighbour_snap` must be ≥ 0 (CRS units of the polygons); leave it out for 1e-7 × each polygon's extent",
                    ));
                }
                let cov = coverage(&units, neighbour_fids.as_deref())?.with_snap(snap);
                Ok(Some(std::sync::Arc::new(cov)))
            }
            (true, None) => Err(PipelineError::new_err(format!(
                "{} reads the units of a coverage: give it as `neighbours` (the polygons of `input.neighbours`)",
                self.neighbour_readers()
            ))),
            (false, Some(_)) => Err(PipelineError::new_err(
                "`neighbours` is a coverage for a step that reads it (`partition`), and the pipeline has none",
            )),
            (false, None) => Ok(None),
        }
    }

    /// The steps of the pipeline that read `input.neighbours`, for messages
    /// (`` `partition` ``).
    fn neighbour_readers(&self) -> String {
        let names: Vec<String> = self
            .steps
            .file
            .steps
            .iter()
            .filter(|s| s.needs().neighbours)
            .map(|s| format!("the `{}` step", s.name()))
            .collect();
        names.join(" and ")
    }

    /// What the command line refuses of a file whose `input` lacks the
    /// lines (`connect`: they are given): `prune: {mode: network}` without
    /// `input.connect`, with the command line's message. Without this a
    /// run would prune every polygon with the fallback instead.
    fn refuse_without_lines(&self, connect: bool) -> PyResult<()> {
        let network = self.steps.file.steps.iter().position(
            |s| matches!(s, config::Step::Prune(p) if p.mode == skeletonise::graph::prune::PruneMode::Network),
        );
        match (network, connect) {
            (Some(i), false) => Err(pipeline_error(self.error_at(
                &format!("steps[{i}].prune.mode"),
                skeletonise::graph::prune::NETWORK_NEEDS_CONNECT,
            ))),
            _ => Ok(()),
        }
    }

    /// The error of key `key` (a key path of the steps document) as the
    /// command line's validation words it: the file's `line:column` of the
    /// key, or the override that set it; the keyword for keyword options.
    fn error_at(&self, key: &str, message: &str) -> ConfigError {
        let mut e = ConfigError {
            origin: self.steps.origin.clone(),
            position: None,
            key: key.to_string(),
            message: message.to_string(),
        };
        if self.keyword {
            e.key = keyword_key(key);
            return e;
        }
        let plain = strip_indices(key);
        let overridden = self.overrides.iter().find(|o| {
            let k = o.split_once('=').map_or(o.as_str(), |(k, _)| k);
            plain == k || plain.starts_with(&format!("{k}.")) || k.starts_with(&format!("{plain}."))
        });
        match overridden {
            Some(o) => e.origin = format!("--set {o}"),
            None => e.position = config::locate::Locations::index(&self.steps.text).key(key),
        }
        e
    }
}

use skeletonise::config::locate::strip_indices;

#[pymethods]
impl Pipeline {
    /// Loads and validates a pipeline file (`input` and `output` may be
    /// absent); `overrides` are `--set` style `KEY=VALUE` strings.
    #[staticmethod]
    #[pyo3(signature = (path, overrides = Vec::new()))]
    fn load(path: std::path::PathBuf, overrides: Vec<String>) -> PyResult<Self> {
        let mut p = config::load_steps(&path, &overrides)
            .map_err(pipeline_error)
            .and_then(Self::supported)?;
        p.overrides = overrides;
        Ok(p)
    }

    /// Validates a steps document made from keyword options (JSON text);
    /// `origin` names the caller in errors.
    #[staticmethod]
    fn from_options(text: &str, origin: &str) -> PyResult<Self> {
        config::load_steps_str(text, origin, &[])
            .map_err(|e| {
                pipeline_error(ConfigError {
                    key: keyword_key(&e.key),
                    position: None,
                    ..e
                })
            })
            .and_then(Self::supported)
            .map(|p| Self { keyword: true, ..p })
    }

    /// Refuses, before any work, what the command line refuses of the
    /// pipeline's inputs: `prune: {mode: network}` without the lines of
    /// `input.connect` (`connect`: they are given), with its message.
    /// `run` makes the same check.
    #[pyo3(signature = (*, connect))]
    fn check_inputs(&self, connect: bool) -> PyResult<()> {
        self.refuse_without_lines(connect)
    }

    /// Whether the pipeline has a `collapse` step (its kept areas come back
    /// as `areas` from `run`).
    #[getter]
    fn collapse(&self) -> bool {
        self.steps.process_params().collapse.is_some()
    }

    /// Whether the pipeline has a `partition` step (`run` then needs
    /// `neighbours` and also returns the partitioned coverage).
    #[getter]
    fn partition(&self) -> bool {
        self.steps
            .file
            .steps
            .iter()
            .any(|s| s.name() == "partition")
    }

    /// Whether the `prepare` step repairs invalid polygons.
    #[getter]
    fn make_valid(&self) -> bool {
        self.steps.process_params().prepare.make_valid
    }

    /// The names for which a source field is written as `src_<name>` by a
    /// call of this pipeline (every layer of its plan that carries the
    /// source's fields — a registered step's too — as the command line's
    /// writer renames them); with `neighbours`, those of a field of the
    /// units. `connect`: lines are given; `explode`: one row per part
    /// (default the file's `output.explode`), as for `run`.
    #[pyo3(signature = (neighbours = false, connect = false, explode = None))]
    fn reserved(
        &self,
        neighbours: bool,
        connect: bool,
        explode: Option<bool>,
    ) -> Vec<&'static str> {
        let plan = self
            .steps
            .call_plan(explode.unwrap_or_else(|| self.explode()), connect);
        match neighbours {
            true => plan.reserved_neighbour_names(),
            false => plan.reserved_names(),
        }
    }

    /// The columns of layer `name` of a call of this pipeline (its plan: a
    /// registered step's layers too) as `(name, type)` pairs, type one of
    /// `int32`, `int64`, `real`, `text`, and whether the layer carries the
    /// source's fields; `connect` and `explode` as for `run`.
    #[pyo3(signature = (name, connect = false, explode = None))]
    fn layer_columns(
        &self,
        name: &str,
        connect: bool,
        explode: Option<bool>,
    ) -> PyResult<(Vec<(&'static str, &'static str)>, bool)> {
        let plan = self
            .steps
            .call_plan(explode.unwrap_or_else(|| self.explode()), connect);
        let layers = plan.layers();
        let Some(layer) = layers.iter().find(|l| l.name() == name) else {
            let names: Vec<String> = layers.iter().map(|l| format!("`{}`", l.name())).collect();
            return Err(PyValueError::new_err(format!(
                "the pipeline writes no layer `{name}`; its layers are {}",
                names.join(", ")
            )));
        };
        Ok(plan_columns(&plan, *layer))
    }

    /// The side input layers the pipeline file names for its registered
    /// steps: `(step, option key, source, layer, where)` each, `layer` a
    /// name, an index or None (the first layer). A caller that can open
    /// them (QGIS) passes them to `run` as `sides`.
    #[getter]
    fn side_inputs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        let mut out = Vec::new();
        for e in &self.steps.process_params().extra {
            let Some((key, Ok(src))) = e.side_source() else {
                continue;
            };
            let layer: Bound<'py, PyAny> = match &src.layer {
                Some(config::LayerRef::Name(n)) => n.into_pyobject(py)?.into_any(),
                Some(config::LayerRef::Index(i)) => i.into_pyobject(py)?.into_any(),
                None => py.None().into_bound(py),
            };
            let item = (
                e.entry.name,
                key,
                src.source.clone(),
                layer,
                src.where_.clone(),
            );
            out.push(item.into_pyobject(py)?.into_any());
        }
        Ok(out)
    }

    /// Whether a registered step of the pipeline adds rows after the last
    /// feature from every feature's rows: its features must go through one
    /// call (as a partition's).
    #[getter]
    fn finishes(&self) -> bool {
        self.steps
            .process_params()
            .extra
            .iter()
            .any(|e| e.entry.needs.finish)
    }

    /// One row per polygon part (`output.explode`).
    #[getter]
    fn explode(&self) -> bool {
        self.steps.file.output.as_ref().is_some_and(|o| o.explode)
    }

    /// `reject` or `fail`.
    #[getter]
    fn on_error(&self) -> &'static str {
        match self.steps.file.on_error {
            OnError::Reject => "reject",
            OnError::Fail => "fail",
        }
    }

    /// The pipeline's name, if it has one.
    #[getter]
    fn name(&self) -> Option<String> {
        self.steps.file.name.clone()
    }

    /// The text the pipeline was read from.
    #[getter]
    fn text(&self) -> String {
        self.steps.text.clone()
    }

    /// Runs the steps on geometries given as WKB (`geometry` a list of bytes
    /// or None) or as ragged arrays (`geometry` a tuple `(type_id, coords,
    /// offsets, null)`, the layout of `shapely.to_ragged_array`).
    ///
    /// With a `collapse` step the result also holds `areas`: the kept areas
    /// (`row`, `columns`, `reals`, `geometry` as WKB polygons). `connect`
    /// (WKB lines, with `connect_fids`) is the line network of
    /// `input.connect`, `snap` its snap distance. With a `partition` step,
    /// `neighbours` (WKB polygons, with `neighbour_fids`) is the coverage of
    /// `input.neighbours` (`neighbour_snap` its `snap`, default the pipeline
    /// file's), and the result's `layers` hold `coverage`,
    /// `boundaries`, `given` and `areas`. `with_candidates`: the
    /// `candidates` layer too, among `layers`, from the same pass. `proj`:
    /// the geometries' CRS as a PROJ string, for the steps that need
    /// longitude and latitude (`label`'s `minzoom`). `sides`: each
    /// registered step's side input layer by the step's name, `(WKB
    /// geometries, FIDs or None)`.
    #[pyo3(signature = (geometry, *, fids = None, repaired = None, candidates = false, explode = None, threads = None, output = "geoarrow", cancel = None, connect = None, connect_fids = None, snap = 0.0, neighbours = None, neighbour_fids = None, neighbour_snap = None, with_candidates = false, proj = None, sides = None))]
    #[allow(clippy::too_many_arguments)]
    fn run<'py>(
        &self,
        py: Python<'py>,
        geometry: &Bound<'py, PyAny>,
        fids: Option<numpy::PyReadonlyArray1<'py, i64>>,
        repaired: Option<numpy::PyReadonlyArray1<'py, bool>>,
        candidates: bool,
        explode: Option<bool>,
        threads: Option<usize>,
        output: &str,
        cancel: Option<PyRef<'py, Cancel>>,
        connect: Option<Vec<Option<Vec<u8>>>>,
        connect_fids: Option<Vec<i64>>,
        snap: f64,
        neighbours: Option<Vec<Option<Vec<u8>>>>,
        neighbour_fids: Option<Vec<i64>>,
        neighbour_snap: Option<f64>,
        with_candidates: bool,
        proj: Option<&str>,
        sides: Option<SideInputs>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.refuse_without_lines(connect.is_some())?;
        let mut params = self.steps.process_params();
        if params.extra.iter().any(|e| e.entry.needs.lonlat) {
            params.lonlat = proj.and_then(lonlat::lonlat_of);
        }
        side_inputs(&mut params, sides.unwrap_or_default())?;
        let reads = params.needs().neighbours;
        params.neighbours = self.units(reads, neighbours, neighbour_fids, neighbour_snap)?;
        // Adjacent polygons are merged by FID: positions stand in for missing FIDs.
        let merge = params.needs().merge;
        let positions: Option<numpy::PyReadonlyArray1<'py, i64>> = match (&fids, merge) {
            (None, true) => {
                let n = geometry.len()? as i64;
                Some(numpy::PyArrayMethods::readonly(&numpy::PyArray1::from_vec(
                    py,
                    (0..n).collect(),
                )))
            }
            _ => None,
        };
        let fids = fids.or(positions);
        let connect_given = connect.is_some();
        if let Some(lines) = connect {
            params.connect = Some(std::sync::Arc::new(network(
                &lines,
                connect_fids.as_deref(),
                snap,
            )?));
        }
        let opts = run::Options {
            explode: explode.unwrap_or_else(|| self.explode()),
            candidates,
            threads,
            fail: self.steps.file.on_error == OnError::Fail,
            geoarrow_out: match output {
                "geoarrow" => true,
                "wkb" => false,
                other => {
                    return Err(PyValueError::new_err(format!(
                        "output must be `geoarrow` or `wkb`, not `{other}`"
                    )))
                }
            },
            plan: self
                .steps
                .call_plan(explode.unwrap_or_else(|| self.explode()), connect_given),
            merge,
            with_candidates,
            cancel: cancel.map(|c| c.0.clone()),
            given: None,
        };
        run::run(py, geometry, fids, repaired, &params, &opts)
    }
}

/// Scores another tool's skeleton lines against their polygons with the
/// paper's metrics, as `skeletonise score` does: the lines (WKB) are joined
/// to the polygons (WKB) by key (`polygon_keys` and `line_keys`, texts) or,
/// without keys, by location (the polygon holding the midpoint of a line's
/// first segment); every polygon gets a row (`method` = `label`), one
/// without lines a NULL one with the reason in `rejected`. Returns what
/// `Pipeline.run` returns, and `unjoined`: why some line rows joined no
/// polygon. Raises ValueError when no line joins any polygon.
#[pyfunction]
#[pyo3(signature = (polygons, lines, *, fids = None, polygon_keys = None, line_keys = None, label = "external".to_string(), threads = None, output = "wkb", cancel = None))]
#[allow(clippy::too_many_arguments)]
fn score<'py>(
    py: Python<'py>,
    polygons: &Bound<'py, PyAny>,
    lines: Vec<Option<Vec<u8>>>,
    fids: Option<numpy::PyReadonlyArray1<'py, i64>>,
    polygon_keys: Option<Vec<Option<String>>>,
    line_keys: Option<Vec<Option<String>>>,
    label: String,
    threads: Option<usize>,
    output: &str,
    cancel: Option<PyRef<'py, Cancel>>,
) -> PyResult<Bound<'py, PyAny>> {
    use skeletonise::score::join;
    let wkbs: Vec<Option<Vec<u8>>> = polygons.extract()?;
    let geoms: Vec<Option<geo::Geometry<f64>>> = wkbs
        .iter()
        .map(|w| w.as_deref().and_then(|w| wkb::read(w).ok()))
        .collect();
    let line_geoms: Vec<Vec<geo::LineString<f64>>> = lines
        .iter()
        .map(|w| join::lines_of(w.as_deref().and_then(|w| wkb::read(w).ok()).as_ref()))
        .collect();
    let mut unjoined = join::Unjoined::default();
    let assigned =
        match (polygon_keys, line_keys) {
            (Some(pk), Some(lk)) => {
                if pk.len() != geoms.len() || lk.len() != line_geoms.len() {
                    return Err(PyValueError::new_err(
                        "polygon_keys and line_keys must have one key per polygon and per line row",
                    ));
                }
                join::by_key(&pk, lk.into_iter().zip(line_geoms), &mut unjoined)
            }
            (None, None) => {
                let g: Vec<_> = geoms.iter().map(Option::as_ref).collect();
                join::by_location(&g, line_geoms, &mut unjoined)
            }
            _ => return Err(PyValueError::new_err(
                "give both polygon_keys and line_keys (join by key), or neither (join by location)",
            )),
        };
    if assigned.iter().all(Vec::is_empty) {
        return Err(PyValueError::new_err(
            unjoined.nothing_joined("the join keys"),
        ));
    }
    let params = skeletonise::process::ProcessParams {
        prepare: skeletonise::process::PrepareParams {
            make_valid: false,
            ..Default::default()
        },
        score: Some(skeletonise::score::ScoreParams::default()),
        ..Default::default()
    };
    let opts = run::Options {
        explode: false,
        candidates: false,
        threads,
        fail: false,
        geoarrow_out: output == "geoarrow",
        plan: run::bare_plan(),
        merge: false,
        with_candidates: false,
        cancel: cancel.map(|c| c.0.clone()),
        given: Some(run::Given {
            label,
            lines: assigned.into_iter().map(geo::MultiLineString).collect(),
        }),
    };
    let out = run::run(py, polygons, fids, None, &params, &opts)?;
    out.cast::<pyo3::types::PyDict>()?
        .set_item("unjoined", unjoined.reasons())?;
    Ok(out)
}

/// The coverage of `input.neighbours` from WKB polygons, each with its
/// source FID (a NULL geometry is a unit without area; anything but
/// polygons is refused, as the command line refuses it).
fn coverage(
    units: &[Option<Vec<u8>>],
    fids: Option<&[i64]>,
) -> PyResult<skeletonise::neighbours::Coverage> {
    if fids.is_some_and(|f| f.len() != units.len()) {
        return Err(PyValueError::new_err(
            "neighbour_fids must have one FID per polygon of neighbours",
        ));
    }
    let mut out = Vec::with_capacity(units.len());
    for (i, w) in units.iter().enumerate() {
        let fid = fids.map_or(Some(i as u64), |f| u64::try_from(f[i]).ok());
        let read = w.as_deref().map(wkb::read).transpose().map_err(|_| {
            PipelineError::new_err(format!(
                "`neighbours`: feature {} is not a polygon; the coverage is a layer of polygons",
                fid.map_or_else(|| i.to_string(), |f| f.to_string())
            ))
        })?;
        let geometry = skeletonise::neighbours::unit_geometry(fid, read.as_ref())
            .map_err(|e| PipelineError::new_err(format!("`neighbours`: {e}")))?;
        out.push(skeletonise::neighbours::Unit {
            fid,
            geometry,
            attributes: Vec::new(),
        });
    }
    Ok(skeletonise::neighbours::Coverage::new(out))
}

/// Registered steps' side input layers by step name: WKB geometries and
/// their FIDs (`None`: positions).
type SideInputs = std::collections::HashMap<String, (Vec<Option<Vec<u8>>>, Option<Vec<i64>>)>;

/// Gives each registered step of `params` its side input layer from
/// `sides`; a step whose pipeline file names a side input that is not
/// given, or a layer given for a step without one, is an error.
fn side_inputs(
    params: &mut skeletonise::process::ProcessParams,
    mut sides: SideInputs,
) -> PyResult<()> {
    for e in &mut params.extra {
        let Some(key) = e.entry.needs.side else {
            continue;
        };
        let name = e.entry.name;
        match sides.remove(name) {
            Some((wkbs, fids)) => {
                if fids.as_ref().is_some_and(|f| f.len() != wkbs.len()) {
                    return Err(PyValueError::new_err(format!(
                        "sides[{name:?}]: one FID per geometry"
                    )));
                }
                let mut features = Vec::with_capacity(wkbs.len());
                for (i, w) in wkbs.iter().enumerate() {
                    let fid = fids
                        .as_ref()
                        .map_or(Some(i as u64), |f| u64::try_from(f[i]).ok());
                    let Some(w) = w else { continue };
                    let g = wkb::read(w).map_err(|err| {
                        PyValueError::new_err(format!(
                            "sides[{name:?}]: feature {i}: unsupported geometry: {err}"
                        ))
                    })?;
                    features.push((fid, g));
                }
                e.side = Some(std::sync::Arc::new(
                    skeletonise::process::step::SideLayer::new(features),
                ));
            }
            None if e.side_source().is_some() => {
                return Err(PipelineError::new_err(format!(
                    "the `{name}` step reads a layer (`steps.{name}.{key}`), which the Python package does not open: pass it as sides={{{name:?}: frame}}"
                )));
            }
            None => {}
        }
    }
    match sides.into_keys().next() {
        Some(name) => Err(PyValueError::new_err(format!(
            "sides[{name:?}]: the pipeline has no registered step `{name}` that reads a side input"
        ))),
        None => Ok(()),
    }
}

/// The line network of `input.connect` from WKB lines (any line or
/// polygon geometry: its lines), each with its source FID.
fn network(
    lines: &[Option<Vec<u8>>],
    fids: Option<&[i64]>,
    snap: f64,
) -> PyResult<skeletonise::connect::Network> {
    if fids.is_some_and(|f| f.len() != lines.len()) {
        return Err(PyValueError::new_err(
            "connect_fids must have one FID per line of connect",
        ));
    }
    if !(snap.is_finite() && snap >= 0.0) {
        return Err(PipelineError::new_err(format!(
            "`snap`: {snap} is not a distance ≥ 0"
        )));
    }
    let mut out = Vec::new();
    for (i, w) in lines.iter().enumerate() {
        let Some(w) = w else { continue };
        let g = wkb::read(w).map_err(|e| {
            PyValueError::new_err(format!("connecting line {i}: unsupported geometry: {e}"))
        })?;
        let mut ls = Vec::new();
        skeletonise::connect::lines_of(&g, &mut ls);
        let fid = fids.and_then(|f| u64::try_from(f[i]).ok());
        out.extend(ls.into_iter().map(|l| (fid, l)));
    }
    if out.is_empty() {
        return Err(PipelineError::new_err(
            "the connecting layer has no lines: give a line layer (rivers, roads) that meets the polygons",
        ));
    }
    Ok(skeletonise::connect::Network::new(out, snap))
}

/// The columns of a layer (`skeletons`, `candidates`, or `areas`, the
/// `collapse` step's kept areas) as `(name, type)` pairs, type one of
/// `int32`, `int64`, `real`, `text`, and whether the layer carries the
/// source's attributes; `collapse`: the pipeline has a `collapse` step (a
/// registered step's layers: `Pipeline.layer_columns`).
#[pyfunction]
#[pyo3(signature = (layer, explode = false, collapse = false))]
fn columns(
    layer: &str,
    explode: bool,
    collapse: bool,
) -> PyResult<(Vec<(&'static str, &'static str)>, bool)> {
    let names = ["skeletons", "candidates", "areas"];
    let Some(layer) = skeletonise::output::BUILTIN
        .iter()
        .copied()
        .find(|l| l.name() == layer && names.contains(&layer))
    else {
        return Err(PyValueError::new_err(format!(
            "no layer `{layer}`; the layers are {}",
            names.map(|n| format!("`{n}`")).join(", ")
        )));
    };
    let mut holds = if explode { vec![When::Explode] } else { vec![] };
    holds.extend(run::step_holds(collapse));
    let plan = Plan::new(skeletonise::output::SKELETONS.name, holds, &[]);
    Ok(plan_columns(&plan, layer))
}

/// A layer's columns in `plan` as `(name, type)` pairs, and whether it
/// carries the source's fields.
fn plan_columns(
    plan: &Plan,
    layer: &dyn skeletonise::output::Layer,
) -> (Vec<(&'static str, &'static str)>, bool) {
    let cols = plan
        .columns(layer)
        .into_iter()
        .map(|(_, name, ty)| (name, type_name(ty)))
        .collect();
    let carries = layer.fields() == Some(skeletonise::layer::Fields::Input);
    (cols, carries)
}

/// The names for which a source field is written as `src_<name>` (in every
/// layer alike, as the command line's writer renames them), with or without
/// a `collapse` step; with `neighbours`, those of a field of the units
/// (`input.neighbours`, in the layers of the registered steps that carry
/// them). A pipeline's own: `Pipeline.reserved`.
#[pyfunction]
#[pyo3(signature = (collapse = false, neighbours = false))]
fn reserved(collapse: bool, neighbours: bool) -> Vec<&'static str> {
    let registry = config::builtin_steps();
    let steps: Vec<&skeletonise::layer::StepLayer> = registry
        .entries()
        .iter()
        .flat_map(|e| e.layers)
        .filter(|l| neighbours && l.fields == Some(skeletonise::layer::Fields::Neighbours))
        .collect();
    let plan = Plan::new(
        skeletonise::output::SKELETONS.name,
        run::step_holds(collapse),
        &steps,
    );
    match neighbours {
        true => plan.reserved_neighbour_names(),
        false => plan.reserved_names(),
    }
}

/// The names source fields `names` are written under beside the tool's
/// columns `reserved`: `src_` repeated until free, as the command line's
/// writer names them (`skeletonise::output::source_names`).
#[pyfunction]
fn source_names(names: Vec<String>, reserved: Vec<String>) -> Vec<String> {
    let reserved: Vec<&str> = reserved.iter().map(String::as_str).collect();
    skeletonise::output::source_names(&names, &reserved)
}

pub(crate) fn type_name(t: ColumnType) -> &'static str {
    match t {
        ColumnType::Int32 => "int32",
        ColumnType::Int64 => "int64",
        ColumnType::Real => "real",
        ColumnType::Text => "text",
    }
}

/// The methods and every step's options with their defaults (the text of
/// `skeletonise methods`).
#[pyfunction]
fn describe() -> String {
    config::describe(&skeletonise::methods::Registry::builtin())
}

/// The layers of the registered steps every pipeline file may use:
/// `(step, layer, geometry, carries the source's fields)`, geometry one of
/// `linestring`, `multilinestring`, `polygon`, `multipolygon`, `point`, `unknown`
/// (mixed), `none` (a table): what a host (QGIS) declares outputs for.
#[pyfunction]
fn step_layers() -> Vec<(&'static str, &'static str, &'static str, bool)> {
    use skeletonise::layer::GeometryKind as G;
    config::builtin_steps()
        .entries()
        .iter()
        .flat_map(|e| e.layers.iter().map(move |l| (e.name, l)))
        .map(|(step, l)| {
            let geometry = match l.geometry {
                G::LineString => "linestring",
                G::MultiLineString => "multilinestring",
                G::Polygon => "polygon",
                G::MultiPolygon => "multipolygon",
                G::Point => "point",
                G::Unknown => "unknown",
                G::None => "none",
            };
            (
                step,
                l.name,
                geometry,
                l.fields == Some(skeletonise::layer::Fields::Input),
            )
        })
        .collect()
}

/// The JSON Schema of the pipeline file, as JSON text.
#[pyfunction]
fn schema() -> String {
    config::json_schema().to_string()
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("PipelineError", m.py().get_type::<PipelineError>())?;
    m.add("RejectedError", m.py().get_type::<RejectedError>())?;
    m.add("Cancelled", m.py().get_type::<Cancelled>())?;
    m.add_class::<Pipeline>()?;
    m.add_class::<Cancel>()?;
    m.add_function(wrap_pyfunction!(columns, m)?)?;
    m.add_function(wrap_pyfunction!(score, m)?)?;
    m.add_function(wrap_pyfunction!(reserved, m)?)?;
    m.add_function(wrap_pyfunction!(source_names, m)?)?;
    m.add_function(wrap_pyfunction!(describe, m)?)?;
    m.add_function(wrap_pyfunction!(schema, m)?)?;
    m.add_function(wrap_pyfunction!(step_layers, m)?)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::keyword_key;

    #[test]
    fn indices_are_left_out_of_a_key_as_an_override_writes_it() {
        assert_eq!(
            super::strip_indices("steps[2].prune.mode"),
            "steps.prune.mode"
        );
        assert_eq!(super::strip_indices("steps"), "steps");
    }

    #[test]
    fn keys_of_keyword_options_name_the_keyword() {
        assert_eq!(keyword_key("steps[2].prune.ratoi"), "prune.ratoi");
        assert_eq!(keyword_key("steps[1].skeleton.methods[0]"), "methods[0]");
        assert_eq!(keyword_key("steps[0].prepare.min_area"), "min_area");
        assert_eq!(keyword_key("steps"), "steps");
    }
}
