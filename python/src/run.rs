//! One call of `Pipeline.run`: geometries in, the layer's columns out, all
//! the work done with the GIL released.

use crate::{type_name, wkb, Cancelled, RejectedError};
use geo::{Coord, Geometry, LineString, MultiPolygon, Polygon};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};
use skeletonise::feature::Feature;
use skeletonise::output::columns::{self as table, ColumnData, Item, Values};
use skeletonise::output::{ColumnType, Layer, Plan, Rows, When, CANDIDATE_LAYER, SKELETON_LAYER};
use skeletonise::process::{
    feature_rows, map_in_order, FeatureRows, ProcessParams, RowOptions, Run, Skeletons,
};
use std::time::Instant;

/// How to run and what to return.
pub struct Options {
    /// One row per polygon part.
    pub explode: bool,
    /// The `candidates` layer (every method's row) instead of `skeletons`.
    pub candidates: bool,
    /// Worker threads: `None` rayon's global pool, `n` a pool of `n` for the call.
    pub threads: Option<usize>,
    /// `on_error: fail`: the first rejected feature is an error.
    pub fail: bool,
    /// Return geometries as GeoArrow buffers (else WKB).
    pub geoarrow_out: bool,
    /// The layers and columns of the call: the pipeline's own plan
    /// (`config::Steps::call_plan`), as the command line's for the same file.
    pub plan: Plan,
    /// A step [needs](skeletonise::process::step::Needs::merge) adjacent
    /// input polygons merged exactly first (`partition`), as the command
    /// line's reader merges them.
    pub merge: bool,
    /// Also the `candidates` layer, among `layers` (one pass for both).
    pub with_candidates: bool,
    /// Stop before the next feature once set (`Cancel`).
    pub cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Another tool's skeletons to score, in place of the methods'.
    pub given: Option<Given>,
}

/// Skeletons made by another tool (`score`): its name and the lines joined
/// to each input polygon.
pub struct Given {
    /// The tool's name (the `method` column).
    pub label: String,
    /// The lines of each polygon, in input order.
    pub lines: Vec<geo::MultiLineString<f64>>,
}

/// Why a call returns no rows.
enum Stop {
    /// A rejected feature under `on_error: fail`: the command line's text.
    Rejected(String),
    /// The cancel flag was set.
    Cancelled,
    /// The work after the last feature failed (a unit of the partitioned
    /// coverage could not be made valid, a registered step's finish): the
    /// command line's text.
    Finish(String),
}

/// The geometries as handed over.
pub(crate) enum Input<'a> {
    /// WKB per feature (`None` for NULL).
    Wkb(Vec<Option<&'a [u8]>>),
    /// `shapely.to_ragged_array` of polygons (3) or multipolygons (6).
    Ragged {
        multi: bool,
        coords: &'a [f64],
        offsets: Vec<&'a [i64]>,
        null: Option<&'a [bool]>,
    },
}

impl Input<'_> {
    pub(crate) fn len(&self) -> usize {
        match self {
            Input::Wkb(v) => v.len(),
            Input::Ragged { offsets, .. } => {
                offsets.last().map_or(0, |o| o.len().saturating_sub(1))
            }
        }
    }

    /// Geometry `i`, `None` for NULL.
    fn geometry(&self, i: usize) -> Result<Option<Geometry<f64>>, String> {
        match self {
            Input::Wkb(v) => v[i].map(wkb::read).transpose(),
            Input::Ragged { null: Some(n), .. } if n[i] => Ok(None),
            Input::Ragged {
                multi,
                coords,
                offsets,
                ..
            } => {
                let ring = |r: usize| {
                    let (a, b) = (offsets[0][r] as usize, offsets[0][r + 1] as usize);
                    LineString(
                        coords[2 * a..2 * b]
                            .chunks_exact(2)
                            .map(|c| Coord { x: c[0], y: c[1] })
                            .collect(),
                    )
                };
                let polygon = |p: usize| {
                    let (a, b) = (offsets[1][p] as usize, offsets[1][p + 1] as usize);
                    let mut rings = (a..b).map(ring);
                    let ext = rings.next().unwrap_or_else(|| LineString(Vec::new()));
                    Polygon::new(ext, rings.collect())
                };
                let top = offsets.last().expect("checked");
                let (a, b) = (top[i] as usize, top[i + 1] as usize);
                Ok(Some(if *multi {
                    Geometry::MultiPolygon(MultiPolygon((a..b).map(polygon).collect()))
                } else {
                    // Polygons: offsets[1] is the geometry level itself.
                    let mut rings = (a..b).map(ring);
                    let ext = rings.next().unwrap_or_else(|| LineString(Vec::new()));
                    Geometry::Polygon(Polygon::new(ext, rings.collect()))
                }))
            }
        }
    }
}

/// Checks that ragged offsets are non-decreasing and within what they index.
fn check_offsets(coords: usize, offsets: &[&[i64]]) -> Result<(), String> {
    let mut bound = coords;
    for (level, o) in offsets.iter().enumerate() {
        if o.is_empty()
            || o[0] != 0
            || o.windows(2).any(|w| w[0] > w[1])
            || o[o.len() - 1] as usize > bound
        {
            return Err(format!(
                "ragged offsets at level {level} are not valid GeoArrow offsets"
            ));
        }
        bound = o.len() - 1;
    }
    Ok(())
}

/// What the work gives back, owned, for the Python side.
struct Done {
    rows: Vec<i64>,
    columns: Vec<ColumnData>,
    rejected: Vec<Option<String>>,
    geometry: Encoded,
    counts: [u64; 4],
    timings: [f64; 3],
    /// The other layers of the plan (`areas` with `collapse`; `coverage`,
    /// `boundaries`, `given` and `areas` with `partition`).
    layers: Vec<LayerOut>,
}

/// The rows of a layer beside the skeletons: its columns, whose fields it
/// carries (`input`, `neighbours` or none; the Python side joins them by
/// `src_fid`) and its geometries as WKB (`None`: NULL, or a table).
struct LayerOut {
    name: &'static str,
    fields: Option<&'static str>,
    columns: Vec<ColumnData>,
    geometry: Vec<Option<Vec<u8>>>,
}

enum Encoded {
    Ragged(table::Ragged),
    Wkb(Vec<Option<Vec<u8>>>),
}

/// The features of the input (parsed, repaired parts kept as the command
/// line keeps them: MakeValid's polygons, not the lines and points a
/// collapsed spike becomes), as `Pipeline.run` and `score` read them.
pub(crate) fn features(
    input: &Input<'_>,
    fids: Option<&[i64]>,
    repaired: Option<&[bool]>,
    par: bool,
) -> Vec<Feature> {
    let idx: Vec<usize> = (0..input.len()).collect();
    map_in_order(&idx, par, |_, &i| {
        let repaired = repaired.is_some_and(|r| r[i]);
        let fid = fids.and_then(|f| u64::try_from(f[i]).ok());
        let mut f = Feature {
            repaired,
            ..Feature::new(fid, Vec::new())
        };
        match input.geometry(i) {
            Ok(Some(g)) if repaired => match wkb::areal_parts(g) {
                Ok(g) => f.geometry = Some(g),
                Err(e) => f.geometry_error = Some(e),
            },
            Ok(g) => f.geometry = g,
            Err(e) => f.geometry_error = Some(format!("unsupported geometry: {e}")),
        }
        f
    })
}

/// The rows of every feature in one [`Rows`], and the output rows of
/// `layer` in input order: the input row of each, the item (a row of the
/// layer, or an empty row for a rejected or filtered feature) and the
/// reason of each rejected one.
fn outputs(
    results: Vec<Rows>,
    feats: &[Feature],
    layer: &dyn Layer,
) -> (Vec<i64>, Rows, Vec<Item>, Vec<Option<String>>) {
    let (mut idx, mut items, mut reasons) = (Vec::new(), Vec::new(), Vec::new());
    let mut all = Rows::default();
    for (i, (r, f)) in results.into_iter().zip(feats).enumerate() {
        let before = layer.count(&all);
        let rejected: Vec<String> = r.rejected.iter().map(|j| j.reason.clone()).collect();
        all.append(r);
        let after = layer.count(&all);
        for k in before..after {
            idx.push(i as i64);
            items.push(Item::Row(k));
            reasons.push(None);
        }
        let none = after == before && rejected.is_empty();
        for reason in rejected {
            idx.push(i as i64);
            items.push(Item::Empty(f.fid));
            reasons.push(Some(reason));
        }
        if none {
            // Filtered by `min_area`: a row all the same, never a lost one.
            idx.push(i as i64);
            items.push(Item::Empty(f.fid));
            reasons.push(None);
        }
    }
    (idx, all, items, reasons)
}

/// The plan of a call without a pipeline (`score`): the skeleton layer
/// and the candidates layer.
pub fn bare_plan() -> Plan {
    Plan::new(
        skeletonise::output::SKELETONS.name,
        vec![When::Candidates],
        &[],
    )
}

/// What the `collapse` step adds to a plan (as the command line's
/// `config::plan_of`).
pub fn step_holds(collapse: bool) -> Vec<When> {
    match collapse {
        true => vec![When::Collapse],
        false => Vec::new(),
    }
}

/// Adjacent features merged into one (for a step that needs it, as the
/// command line's reader merges them), and the input row of every merged feature:
/// its smallest member's, whose FID it takes.
fn merged(feats: Vec<Feature>) -> (Vec<Feature>, Option<Vec<i64>>) {
    let by_fid: std::collections::HashMap<u64, i64> = feats
        .iter()
        .enumerate()
        .filter_map(|(i, f)| f.fid.map(|x| (x, i as i64)))
        .collect();
    let feats = skeletonise::process::merge::merge_adjacent_exactly(feats, None);
    let rows = feats
        .iter()
        .map(|f| f.fid.and_then(|x| by_fid.get(&x).copied()).unwrap_or(-1))
        .collect();
    (feats, Some(rows))
}

/// The skeleton lines as GeoArrow (`geoarrow`) or WKB, one per row.
fn encoded(lines: &[Option<geo::MultiLineString<f64>>], geoarrow: bool, par: bool) -> Encoded {
    if geoarrow {
        return Encoded::Ragged(table::ragged(lines));
    }
    Encoded::Wkb(map_in_order(lines, par, |_, g| {
        g.as_ref().map(|m| {
            let mut out = Vec::new();
            wkb::write_lines(m, &mut out);
            out
        })
    }))
}

/// Every feature's rows, in order (`None`: cancelled by the caller's flag,
/// read before each feature).
fn feature_rows_of(
    feats: &[Feature],
    params: &ProcessParams,
    opts: &Options,
    par: bool,
) -> Option<Vec<FeatureRows>> {
    // The call's plan, as the command line's (the network's skeleton rows
    // with `input.connect`), with the candidates only when asked for.
    let row_opts = RowOptions {
        explode: opts.explode,
        candidates: opts.candidates || opts.with_candidates,
        ..RowOptions::of(&opts.plan)
    };
    let cancelled = || {
        opts.cancel
            .as_ref()
            .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
    };
    let results: Vec<Option<FeatureRows>> = map_in_order(feats, par, |i, f| {
        (!cancelled()).then(|| {
            let skeletons = match &opts.given {
                None => Skeletons::Computed,
                Some(g) => Skeletons::Given {
                    label: &g.label,
                    lines: g.lines.get(i),
                },
            };
            feature_rows(f, skeletons, params, row_opts)
        })
    });
    results.into_iter().collect()
}

fn work(
    input: &Input<'_>,
    fids: Option<&[i64]>,
    repaired: Option<&[bool]>,
    params: &ProcessParams,
    opts: &Options,
) -> Result<Done, Stop> {
    // One feature: no hop to a worker thread (waking one costs more than
    // a small polygon's work); a large one still splits its own work.
    let par = opts.threads != Some(1) && input.len() > 1;
    let t0 = Instant::now();
    let feats = features(input, fids, repaired, par);
    let (feats, input_rows) = match opts.merge {
        true => merged(feats),
        false => (feats, None),
    };
    let t1 = Instant::now();
    let results = feature_rows_of(&feats, params, opts, par).ok_or(Stop::Cancelled)?;
    let t2 = Instant::now();
    // The one run driver of the command line: counts, `on_error: fail`,
    // and the rows made after the last feature (the grown coverage).
    let mut run = Run::new(params, opts.fail);
    let mut kept = Vec::with_capacity(results.len());
    for (f, r) in feats.iter().zip(results) {
        let rows = run.add(f, r).map_err(|e| {
            Stop::Rejected(skeletonise::config::rejected_under_fail(&e.fid, &e.reason))
        })?;
        kept.push(rows);
    }
    let (finished, c) = run.finish().map_err(|e| Stop::Finish(e.to_string()))?;
    let counts = [input.len() as u64, c.written, c.rejected, c.filtered];
    let plan = &opts.plan;
    let layer: &dyn Layer = if opts.candidates {
        &CANDIDATE_LAYER
    } else {
        &SKELETON_LAYER
    };
    let (mut rows, mut all, items, rejected) = outputs(kept, &feats, layer);
    if let Some(input_rows) = &input_rows {
        for r in &mut rows {
            *r = input_rows[*r as usize];
        }
    }
    all.append(finished);
    let columns = table::columns(layer, plan, &all, &items);
    let geometry = encoded(&table::lines(layer, &all, &items), opts.geoarrow_out, par);
    let layers = if opts.candidates {
        Vec::new()
    } else {
        other_layers(plan, &all, opts.with_candidates)
    };
    let t3 = Instant::now();
    Ok(Done {
        rows,
        columns,
        rejected,
        geometry,
        layers,
        counts,
        timings: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
        ],
    })
}

/// The layers of the plan beside the skeletons (and the `rejected` layer,
/// whose reasons are the skeletons' `rejected`): the candidates when asked
/// for, and the steps' layers.
fn other_layers(plan: &Plan, all: &Rows, candidates: bool) -> Vec<LayerOut> {
    use skeletonise::layer::Fields;
    use skeletonise::output::Shape;
    let wanted: &[&dyn Layer] = if candidates { &[&CANDIDATE_LAYER] } else { &[] };
    wanted
        .iter()
        .copied()
        .chain(plan.layers().into_iter().filter(|l| {
            ![
                SKELETON_LAYER.name(),
                CANDIDATE_LAYER.name(),
                skeletonise::output::REJECTED.name,
                skeletonise::output::RUNS.name,
            ]
            .contains(&l.name())
        }))
        .map(|layer| {
            let items: Vec<Item> = (0..layer.count(all)).map(Item::Row).collect();
            let geometry = (0..items.len())
                .map(|i| {
                    let mut out = Vec::new();
                    match layer.shape(all, i)? {
                        Shape::Polygon(p) => wkb::write_polygon(p, &mut out),
                        Shape::MultiPolygon(m) => wkb::write_polygons(m, &mut out),
                        Shape::Lines(m) | Shape::LinesM(m, _) => wkb::write_lines(m, &mut out),
                        Shape::Line(l) => {
                            wkb::write_geometry(&geo::Geometry::LineString(l), &mut out);
                        }
                        Shape::Wkb(w) => out.extend_from_slice(w),
                        Shape::Geometry(g) => {
                            if !wkb::write_geometry(g, &mut out) {
                                return None;
                            }
                        }
                    }
                    Some(out)
                })
                .collect();
            LayerOut {
                name: layer.name(),
                fields: layer.fields().map(|f| match f {
                    Fields::Input => "input",
                    Fields::Neighbours => "neighbours",
                }),
                columns: table::columns(layer, plan, all, &items),
                geometry,
            }
        })
        .collect()
}

/// Runs with the GIL released, in a pool of `threads` when given: also for
/// one thread, since the per-feature path runs the methods and the bars in
/// parallel and would otherwise fill rayon's global pool (a Dask worker
/// asked for one core would take them all).
fn detached(
    py: Python<'_>,
    input: &Input<'_>,
    fids: Option<&[i64]>,
    repaired: Option<&[bool]>,
    params: &ProcessParams,
    opts: &Options,
) -> PyResult<Result<Done, Stop>> {
    match opts.threads {
        Some(0) => Err(PyValueError::new_err(
            "threads must be ≥ 1 (or None for one per core)",
        )),
        Some(n) => {
            let pool = pool_of(n)?;
            Ok(py.detach(|| pool.install(|| work(input, fids, repaired, params, opts))))
        }
        _ => Ok(py.detach(|| work(input, fids, repaired, params, opts))),
    }
}

thread_local! {
    /// The pools of `threads=n` calls made on this (Python) thread, kept for
    /// its next calls: starting threads costs more than a call on a small
    /// polygon. Per calling thread, so that calls from different threads (a
    /// Dask worker running several tasks) never share, nor wait for, a pool.
    static POOLS: std::cell::RefCell<Vec<(usize, std::sync::Arc<rayon::ThreadPool>)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// This thread's pool of `n` worker threads.
pub(crate) fn pool_of(n: usize) -> PyResult<std::sync::Arc<rayon::ThreadPool>> {
    POOLS.with(|pools| {
        if let Some((_, p)) = pools.borrow().iter().find(|(k, _)| *k == n) {
            return Ok(p.clone());
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|_| PyValueError::new_err(format!("cannot start {n} worker threads")))?;
        let pool = std::sync::Arc::new(pool);
        let mut pools = pools.borrow_mut();
        // A handful of sizes at most in practice; never an unbounded set of threads.
        if pools.len() >= 4 {
            pools.remove(0);
        }
        pools.push((n, pool.clone()));
        Ok(pool)
    })
}

/// `(type id, coords, offsets per level, null mask)` as the Python side
/// passes `shapely.to_ragged_array`'s result.
type RaggedTuple<'py> = (
    i32,
    PyReadonlyArray2<'py, f64>,
    Vec<PyReadonlyArray1<'py, i64>>,
    Option<PyReadonlyArray1<'py, bool>>,
);

/// The arrays of a [`RaggedTuple`], kept while their data are borrowed.
struct RaggedArrays<'py> {
    coords: PyReadonlyArray2<'py, f64>,
    offsets: Vec<PyReadonlyArray1<'py, i64>>,
    null: Option<PyReadonlyArray1<'py, bool>>,
}

/// The ragged arrays of geometry type `type_id` (3: polygons, two offset
/// levels; 6: multipolygons, three) as the run's input, checked.
fn ragged_input<'a>(type_id: i32, arrays: &'a RaggedArrays<'_>) -> PyResult<Input<'a>> {
    let multi = match (type_id, arrays.offsets.len()) {
        (3, 2) => false,
        (6, 3) => true,
        _ => {
            return Err(PyValueError::new_err(format!(
                "ragged arrays of geometry type {type_id} with {} offset levels: only polygons (3, two levels) and multipolygons (6, three levels)",
                arrays.offsets.len()
            )))
        }
    };
    let coords = arrays.coords.as_slice().map_err(value_error)?;
    let offsets = arrays
        .offsets
        .iter()
        .map(|o| o.as_slice())
        .collect::<Result<Vec<_>, _>>()
        .map_err(value_error)?;
    check_offsets(coords.len() / 2, &offsets).map_err(PyValueError::new_err)?;
    let null = arrays
        .null
        .as_ref()
        .map(|n| n.as_slice())
        .transpose()
        .map_err(value_error)?;
    Ok(Input::Ragged {
        multi,
        coords,
        offsets,
        null,
    })
}

/// Fails unless `fids`, `repaired` and the ragged input's `null` (when
/// given) have one entry per geometry.
fn check_lengths(input: &Input<'_>, fids: Option<usize>, repaired: Option<usize>) -> PyResult<()> {
    let n = input.len();
    let null = match input {
        Input::Ragged { null: Some(nl), .. } => Some(nl.len()),
        _ => None,
    };
    for (what, len) in [("fids", fids), ("repaired", repaired), ("null", null)] {
        if let Some(len) = len.filter(|&l| l != n) {
            return Err(PyValueError::new_err(format!(
                "{what} has {len} entries for {n} geometries"
            )));
        }
    }
    Ok(())
}

/// `Pipeline.run`.
pub fn run<'py>(
    py: Python<'py>,
    geometry: &Bound<'py, PyAny>,
    fids: Option<PyReadonlyArray1<'py, i64>>,
    repaired: Option<PyReadonlyArray1<'py, bool>>,
    params: &ProcessParams,
    opts: &Options,
) -> PyResult<Bound<'py, PyAny>> {
    let fids = fids
        .as_ref()
        .map(|a| a.as_slice())
        .transpose()
        .map_err(value_error)?;
    let repaired = repaired
        .as_ref()
        .map(|a| a.as_slice())
        .transpose()
        .map_err(value_error)?;
    // The Python objects stay alive (and borrowed) while their data are read.
    let wkbs: Vec<Option<Bound<'py, PyBytes>>>;
    let arrays: RaggedArrays<'py>;
    let input = if let Ok(t) = geometry.cast::<PyTuple>() {
        let (type_id, coords, offsets, null): RaggedTuple<'py> = t.extract()?;
        arrays = RaggedArrays {
            coords,
            offsets,
            null,
        };
        ragged_input(type_id, &arrays)?
    } else {
        wkbs = geometry.extract()?;
        Input::Wkb(
            wkbs.iter()
                .map(|b| b.as_ref().map(|b| b.as_bytes()))
                .collect(),
        )
    };
    check_lengths(&input, fids.map(<[i64]>::len), repaired.map(<[bool]>::len))?;
    let done = detached(py, &input, fids, repaired, params, opts)?.map_err(|e| match e {
        Stop::Rejected(text) => RejectedError::new_err(text),
        Stop::Cancelled => Cancelled::new_err("cancelled"),
        Stop::Finish(text) => crate::PipelineError::new_err(text),
    })?;
    to_python(py, done)
}

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("arrays must be C-contiguous: {e}"))
}

/// Texts as Arrow's large-string buffers, `(offsets, data, null)`: the
/// start of every text in `data` (UTF-8) and the end, and which are NULL
/// (`None` when none is, `True` when all are, else a mask). Python makes
/// the column from them without a Python string per row.
fn text_buffers<'py>(py: Python<'py>, v: &[Option<String>]) -> PyResult<Bound<'py, PyAny>> {
    let mut offsets = Vec::with_capacity(v.len() + 1);
    let mut data = Vec::new();
    offsets.push(0i64);
    for s in v {
        data.extend_from_slice(s.as_deref().unwrap_or_default().as_bytes());
        offsets.push(data.len() as i64);
    }
    let nulls = v.iter().filter(|s| s.is_none()).count();
    let null = if nulls == 0 {
        py.None().into_bound(py)
    } else if nulls == v.len() {
        true.into_pyobject(py)?.to_owned().into_any()
    } else {
        PyArray1::from_iter(py, v.iter().map(Option::is_none)).into_any()
    };
    Ok((
        PyArray1::from_vec(py, offsets),
        PyBytes::new(py, &data),
        null,
    )
        .into_pyobject(py)?
        .into_any())
}

/// Columns for Python: `(name, type, values)` each (integers as `(values,
/// null mask)`, texts as Arrow buffers, reals as their row in the block),
/// and the real columns as one `(k, n)` block (a row each, as pandas keeps
/// them).
fn columns_to_python(
    py: Python<'_>,
    columns: Vec<ColumnData>,
    n: usize,
) -> PyResult<(Bound<'_, PyList>, Bound<'_, PyAny>)> {
    let (mut reals, mut real_rows): (Vec<f64>, usize) = (Vec::new(), 0);
    let cols = PyList::empty(py);
    for c in columns {
        let values = match c.values {
            Values::Int(v, null) if c.ty == ColumnType::Int32 => (
                // In the column's width (the values came from 32-bit cells).
                PyArray1::from_iter(py, v.iter().map(|&x| x as i32)),
                PyArray1::from_vec(py, null),
            )
                .into_pyobject(py)?
                .into_any(),
            Values::Int(v, null) => (PyArray1::from_vec(py, v), PyArray1::from_vec(py, null))
                .into_pyobject(py)?
                .into_any(),
            Values::Real(v) => {
                reals.extend_from_slice(&v);
                real_rows += 1;
                (real_rows - 1).into_pyobject(py)?.into_any()
            }
            Values::Text(v) => text_buffers(py, &v)?,
        };
        cols.append((c.name, type_name(c.ty), values))?;
    }
    let reals = PyArray1::from_vec(py, reals)
        .reshape([real_rows, n])?
        .into_any();
    Ok((cols, reals))
}

fn to_python(py: Python<'_>, d: Done) -> PyResult<Bound<'_, PyAny>> {
    let out = PyDict::new(py);
    // One row per input row, in order (no candidates, no parts, no rows
    // added): the input's index is the output's as it is.
    let in_order = d.rows.len() as u64 == d.counts[0]
        && d.rows.iter().enumerate().all(|(i, &r)| r == i as i64);
    out.set_item("in_order", in_order)?;
    let n = d.rows.len();
    out.set_item("row", PyArray1::from_vec(py, d.rows))?;
    let (cols, reals) = columns_to_python(py, d.columns, n)?;
    out.set_item("columns", cols)?;
    out.set_item("reals", reals)?;
    let layers = PyDict::new(py);
    for l in d.layers {
        let layer = PyDict::new(py);
        let n = l.geometry.len();
        layer.set_item("fields", l.fields)?;
        let (cols, reals) = columns_to_python(py, l.columns, n)?;
        layer.set_item("columns", cols)?;
        layer.set_item("reals", reals)?;
        let list = PyList::empty(py);
        for g in l.geometry {
            match g {
                Some(b) => list.append(PyBytes::new(py, &b))?,
                None => list.append(py.None())?,
            }
        }
        layer.set_item("geometry", ("wkb", list))?;
        layers.set_item(l.name, layer)?;
    }
    out.set_item("layers", layers)?;
    out.set_item("rejected", text_buffers(py, &d.rejected)?)?;
    match d.geometry {
        Encoded::Ragged(r) => out.set_item(
            "geometry",
            (
                "geoarrow",
                PyArray1::from_vec(py, r.coords),
                PyArray1::from_vec(py, r.line_offsets),
                PyArray1::from_vec(py, r.geom_offsets),
                PyArray1::from_vec(py, r.null),
            ),
        )?,
        Encoded::Wkb(w) => {
            let list = PyList::empty(py);
            for g in w {
                match g {
                    Some(b) => list.append(PyBytes::new(py, &b))?,
                    None => list.append(py.None())?,
                }
            }
            out.set_item("geometry", ("wkb", list))?;
        }
    }
    let counts = PyDict::new(py);
    for (k, v) in ["read", "written", "rejected", "filtered"]
        .iter()
        .zip(d.counts)
    {
        counts.set_item(k, v)?;
    }
    out.set_item("counts", counts)?;
    let timings = PyDict::new(py);
    for (k, v) in ["parse_s", "compute_s", "encode_s"].iter().zip(d.timings) {
        timings.set_item(k, v)?;
    }
    out.set_item("timings", timings)?;
    Ok(out.into_any())
}
