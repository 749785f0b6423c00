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

mod labels;
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
use skeletonise::output::{ColumnType, Layer, Plan, When, CANDIDATE_LAYER, SKELETON_LAYER};

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
    /// The steps, unless they need what only the command line writes: the
    /// `collapse` step's kept areas are a second layer beside the lines, and
    /// the `partition` step reads a second source (`input.neighbours`) and
    /// writes the grown coverage once every polygon is done.
    fn supported(steps: config::Steps) -> PyResult<Self> {
        if steps.process_params().partition.is_some() {
            return Err(PipelineError::new_err(
                "the `partition` step reads the coverage of `input.neighbours` and writes it grown once every \
                 polygon is done, so it runs from the command line only (`skeletonise run`); leave it out \
                 of the pipeline given to Python",
            ));
        }
        if steps.process_params().collapse.is_some() {
            return Err(PipelineError::new_err(
                "the `collapse` step writes kept areas beside the lines and runs from the command line only \
                 (`skeletonise run`); leave it out of the pipeline given to Python",
            ));
        }
        Ok(Self { steps })
    }
}

#[pymethods]
impl Pipeline {
    /// Loads and validates a pipeline file (`input` and `output` may be
    /// absent); `overrides` are `--set` style `KEY=VALUE` strings.
    #[staticmethod]
    #[pyo3(signature = (path, overrides = Vec::new()))]
    fn load(path: std::path::PathBuf, overrides: Vec<String>) -> PyResult<Self> {
        config::load_steps(&path, &overrides)
            .map_err(pipeline_error)
            .and_then(Self::supported)
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
    }

    /// Whether the `prepare` step repairs invalid polygons.
    #[getter]
    fn make_valid(&self) -> bool {
        self.steps.process_params().prepare.make_valid
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
    #[pyo3(signature = (geometry, *, fids = None, repaired = None, candidates = false, explode = None, threads = None, output = "geoarrow", cancel = None))]
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
    ) -> PyResult<Bound<'py, PyAny>> {
        let params = self.steps.process_params();
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
            cancel: cancel.map(|c| c.0.clone()),
        };
        run::run(py, geometry, fids, repaired, &params, &opts)
    }
}

/// The columns of a layer (`skeletons` or `candidates`) as `(name, type)`
/// pairs, type one of `int32`, `int64`, `real`, `text`, and whether the
/// layer carries the source's attributes.
#[pyfunction]
#[pyo3(signature = (layer, explode = false))]
fn columns(layer: &str, explode: bool) -> PyResult<(Vec<(&'static str, &'static str)>, bool)> {
    let layer: &dyn Layer = match layer {
        "skeletons" => &SKELETON_LAYER,
        "candidates" => &CANDIDATE_LAYER,
        other => {
            return Err(PyValueError::new_err(format!(
                "no layer `{other}`; the layers are `skeletons` and `candidates`"
            )))
        }
    };
    let holds = if explode { vec![When::Explode] } else { vec![] };
    let plan = Plan::new(skeletonise::output::SKELETONS.name, holds, &[]);
    let cols = plan
        .columns(layer)
        .into_iter()
        .map(|(_, name, ty)| (name, type_name(ty)))
        .collect();
    Ok((cols, layer.fields().is_some()))
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
    m.add_function(wrap_pyfunction!(describe, m)?)?;
    m.add_function(wrap_pyfunction!(schema, m)?)?;
    m.add_function(wrap_pyfunction!(labels::labels, m)?)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::keyword_key;

    #[test]
    fn keys_of_keyword_options_name_the_keyword() {
        assert_eq!(keyword_key("steps[2].prune.ratoi"), "prune.ratoi");
        assert_eq!(keyword_key("steps[1].skeleton.methods[0]"), "methods[0]");
        assert_eq!(keyword_key("steps[0].prepare.min_area"), "min_area");
        assert_eq!(keyword_key("steps"), "steps");
    }
}
