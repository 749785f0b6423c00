//! `_core.labels`: the `label` step's labels of every feature — a line
//! where a polygon part is elongated enough for a curved name, else the
//! centre of its largest inscribed disc — WKB in, one row per labelled part
//! out, on rayon's threads with the GIL released.
//!
//! The features are read as `Pipeline.run` reads them ([`crate::run::features`]:
//! a repaired geometry keeps MakeValid's polygons, as the command line's
//! reader keeps them) and prepared as the command line's per-feature path
//! prepares them (`prepare_checked`).

use crate::run::{features, Input};
use geo::Geometry;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rayon::prelude::*;
use skeletonise::feature::Feature;
use skeletonise::label::{Label, LabelParams, Labelled};
use skeletonise::process::{prepare_checked, NotPrepared, PrepareParams};

/// One output row: the input row, the part, the label (or why the feature
/// has none).
type Row = (usize, Option<usize>, Result<Option<Labelled>, String>);

/// The labels of the features `wkbs` (`None`: NULL) with the `label`
/// step's options (`options`: JSON with its keys); `threads` worker
/// threads (`None`: rayon's global pool). `repaired`: which geometries
/// MakeValid repaired (of a repaired one only the polygons are labelled,
/// as the command line keeps them: a spike MakeValid turns into a line
/// does not reject the feature); `make_valid`: the `prepare` step's
/// `make_valid` (it words the reason of a polygon that stays invalid).
/// Returns the columns `(row, polygon_part, kind, length, max_width,
/// elongation, wkb, rejected)`: one row per labelled part; a feature that
/// cannot be prepared (NULL, not a polygon, invalid) one row with its
/// reason in `rejected`.
#[pyfunction]
#[pyo3(signature = (wkbs, options, threads = None, *, repaired = None, make_valid = false))]
pub fn labels<'py>(
    py: Python<'py>,
    wkbs: Vec<Option<Vec<u8>>>,
    options: &str,
    threads: Option<usize>,
    repaired: Option<Vec<bool>>,
    make_valid: bool,
) -> PyResult<Columns<'py>> {
    let params: LabelParams = serde_json::from_str(options)
        .map_err(|e| crate::PipelineError::new_err(format!("label options: {e}")))?;
    params
        .validate()
        .map_err(|(k, m)| crate::PipelineError::new_err(format!("`{k}`: {m}")))?;
    if let Some(r) = repaired.as_ref().filter(|r| r.len() != wkbs.len()) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "repaired has {} entries for {} geometries",
            r.len(),
            wkbs.len()
        )));
    }
    let prep = PrepareParams {
        make_valid,
        min_area: 0.0,
        max_vertices: 0,
    };
    let input = Input::Wkb(wkbs.iter().map(Option::as_deref).collect());
    let work = || {
        let feats = features(&input, None, repaired.as_deref(), input.len() > 1);
        label_rows(&feats, &params, &prep)
    };
    let rows: Vec<Row> = match threads {
        Some(n) => {
            let pool = crate::run::pool_of(n)?;
            py.detach(|| pool.install(work))
        }
        None => py.detach(work),
    };
    Ok(columns(py, rows))
}

/// The columns `labels` returns: `(row, polygon_part, kind, length,
/// max_width, elongation, wkb, rejected)`.
type Columns<'py> = (
    Vec<usize>,
    Vec<Option<usize>>,
    Vec<Option<&'static str>>,
    Vec<Option<f64>>,
    Vec<Option<f64>>,
    Vec<Option<f64>>,
    Vec<Option<Bound<'py, PyBytes>>>,
    Vec<Option<String>>,
);

/// Every feature's labels (one row per labelled part), or one row with
/// the reason a feature cannot be prepared.
fn label_rows(feats: &[Feature], params: &LabelParams, prep: &PrepareParams) -> Vec<Row> {
    feats
        .par_iter()
        .enumerate()
        .flat_map_iter(|(i, f)| -> Vec<Row> {
            if let Some(e) = &f.geometry_error {
                return vec![(i, None, Err(e.clone()))];
            }
            match prepare_checked(f.geometry.as_ref(), prep, f.checked) {
                Ok(parts) => params
                    .labels(&parts)
                    .into_iter()
                    .map(|(k, l)| (i, Some(k), Ok(l)))
                    .collect(),
                Err(NotPrepared::Rejected(r)) => vec![(i, None, Err(r))],
                Err(NotPrepared::Filtered) => vec![(i, None, Err("no polygon part".into()))],
            }
        })
        .collect()
}

/// The rows as the columns Python reads.
fn columns(py: Python<'_>, rows: Vec<Row>) -> Columns<'_> {
    let n = rows.len();
    let mut c: Columns<'_> = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for (i, k, l) in rows {
        c.0.push(i);
        c.1.push(k);
        let (kind, measures, g, reason) = match l {
            Ok(Some(l)) => {
                let mut out = Vec::new();
                let kind = match &l.label {
                    Label::Line(line) => {
                        crate::wkb::write_geometry(&Geometry::LineString(line.clone()), &mut out);
                        "line"
                    }
                    Label::Point(p) => {
                        crate::wkb::write_geometry(&Geometry::Point(p.to_owned().into()), &mut out);
                        "point"
                    }
                };
                let m = [Some(l.length), Some(l.max_width), Some(l.elongation)];
                (Some(kind), m, Some(PyBytes::new(py, &out)), None)
            }
            Ok(None) => (Some("none"), [None; 3], None, None),
            Err(r) => (None, [None; 3], None, Some(r)),
        };
        c.2.push(kind);
        c.3.push(measures[0]);
        c.4.push(measures[1]);
        c.5.push(measures[2]);
        c.6.push(g);
        c.7.push(reason);
    }
    c
}
