//! The reader thread: the source opened on its own thread, its features in
//! batches (every one first, dissolved, with `input.merge_adjacent`), and
//! the line network of `input.connect`.

use super::{Batch, RunError};
use crate::config::{InputSpec, LayerSource};
use crate::feature::Feature;
use crate::io::reader::Reader;
use crate::io::{IoError, SourceInfo};
use std::sync::mpsc;

/// The reader thread: opens the source, sends what it holds, then its
/// features batch by batch until the source ends, an error, or nobody
/// listens any more.
pub(super) fn read_batches(
    input: &InputSpec,
    merge: Merge,
    batch: usize,
    make_valid: bool,
    info_tx: mpsc::SyncSender<Result<SourceInfo, IoError>>,
    batch_tx: mpsc::SyncSender<Batch>,
) {
    let mut reader = match Reader::open(input) {
        Ok(r) => r,
        Err(e) => {
            let _ = info_tx.send(Err(e));
            return;
        }
    };
    if info_tx.send(Ok(reader.info().clone())).is_err() {
        return;
    }
    if merge != Merge::None {
        return read_merged(&mut reader, input, merge, (batch, make_valid), batch_tx);
    }
    let r = reader.read::<Stop>(batch, make_valid, |features| {
        batch_tx.send(Ok(features)).map_err(|_| Stop::Gone)
    });
    if let Err(Stop::Failed(e)) = r {
        let _ = batch_tx.send(Err(e));
    }
}

/// The index of `input.merge_by` among the source's fields, or the error
/// naming the fields there are.
pub(super) fn merge_field(input: &InputSpec, info: &SourceInfo) -> Result<Option<usize>, IoError> {
    let Some(name) = &input.merge_by else {
        return Ok(None);
    };
    let fields = &info.fields;
    fields
        .iter()
        .position(|f| &f.name == name)
        .map(Some)
        .ok_or_else(|| {
            let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
            IoError::Read {
                source_name: input.source.clone(),
                reason: format!(
                    "`input.merge_by`: the layer has no field `{name}`; its fields are {}",
                    names.join(", ")
                ),
            }
        })
}

/// Every feature of a layer read beside the polygons — `input.connect`,
/// `input.neighbours`, a registered step's side input — reprojected to the
/// CRS the polygons are handed out in (`polygons`), and what its source
/// holds. `key` (`input.connect`, `steps.<step>.<option>`) names it in
/// errors, with its own `layer` and `where` to fix, not the polygons'.
pub(super) fn read_side(
    src: &LayerSource,
    key: &str,
    polygons: &SourceInfo,
) -> Result<(Vec<Feature>, SourceInfo), RunError> {
    let error = |reason: String| {
        RunError::Io(IoError::Read {
            source_name: src.source.clone(),
            reason,
        })
    };
    let mut reader = Reader::open(&src.input(polygons.srs_wkt.as_deref()))
        .map_err(|e| error(side_error(key, e)))?;
    let mut all = Vec::new();
    reader.read::<IoError>(1024, false, |batch| {
        all.extend(batch);
        Ok(())
    })?;
    Ok((all, reader.info().clone()))
}

/// A registered step's side input layer: its features' FIDs and geometries.
pub(super) fn read_step_side(
    src: &LayerSource,
    key: &str,
    polygons: &SourceInfo,
) -> Result<crate::process::step::SideLayer, RunError> {
    let (features, info) = read_side(src, key, polygons)?;
    tracing::info!(source = %src.source, layer = %info.layer, features = features.len(), "{key}: side input read");
    Ok(crate::process::step::SideLayer::new(
        features
            .into_iter()
            .filter_map(|f| Some((f.fid, f.geometry?)))
            .collect(),
    ))
}

/// The lines of `input.connect`, reprojected to the CRS the polygons are
/// handed out in (`polygons`); a layer without lines is an error.
pub(super) fn read_network(
    c: &crate::config::ConnectSpec,
    polygons: &SourceInfo,
) -> Result<crate::connect::Network, RunError> {
    let (features, info) = read_side(&c.layer_source(), "input.connect", polygons)?;
    let mut lines = Vec::new();
    for f in &features {
        let mut ls = Vec::new();
        if let Some(g) = &f.geometry {
            crate::connect::lines_of(g, &mut ls);
        }
        lines.extend(ls.into_iter().map(|l| (f.fid, l)));
    }
    if lines.is_empty() {
        return Err(no_lines(c, &info, features.len()));
    }
    tracing::info!(source = %c.source, layer = %info.layer, crs = %info.crs_name, lines = lines.len(), "connect: line network read");
    Ok(crate::connect::Network::new(lines, c.snap))
}

/// Why a layer read beside the polygons (`key`) could not be opened, with
/// the keys of that layer to fix (its `layer`, its `where`).
fn side_error(key: &str, e: IoError) -> String {
    match e {
        IoError::NoLayer {
            source_name,
            layer,
            available,
        } => format!(
            "`{key}`: layer {layer} not found in `{source_name}`; available layers: {available}; choose one with `{key}.layer`"
        ),
        IoError::BadWhere { filter, reason } => format!(
            "`{key}`: invalid `{key}.where` filter `{filter}`: {reason}; use OGR SQL syntax, e.g. \"area_m2 > 1e6\""
        ),
        e => format!("`{key}`: {e}"),
    }
}

/// The error of a connect layer without lines.
fn no_lines(c: &crate::config::ConnectSpec, info: &SourceInfo, features: usize) -> RunError {
    RunError::Io(IoError::Read {
        source_name: c.source.clone(),
        reason: format!(
            "`input.connect`: layer `{}` has no lines ({features} features read, none a LINESTRING or MULTILINESTRING); give the layer of the line network (`input.connect.layer`)",
            info.layer
        ),
    })
}

/// `input.merge_adjacent`: every feature read first, the adjacent ones
/// dissolved into one per group, then sent in batches.
fn read_merged(
    reader: &mut Reader,
    input: &InputSpec,
    merge: Merge,
    (batch, make_valid): (usize, bool),
    batch_tx: mpsc::SyncSender<Batch>,
) {
    let by = match merge_field(input, reader.info()) {
        Ok(by) => by,
        Err(e) => {
            let _ = batch_tx.send(Err(e));
            return;
        }
    };
    let mut all = Vec::new();
    let r = reader.read::<Stop>(batch, make_valid, |features| {
        all.extend(features);
        Ok(())
    });
    if let Err(Stop::Failed(e)) = r {
        let _ = batch_tx.send(Err(e));
        return;
    }
    let merged = match merge {
        Merge::Exactly => crate::process::merge::merge_adjacent_exactly(all, by),
        _ => crate::process::merge::merge_adjacent(all, by),
    };
    for chunk in merged.chunks(batch) {
        if batch_tx.send(Ok(chunk.to_vec())).is_err() {
            return;
        }
    }
}

/// How the reader thread merges adjacent polygons.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Merge {
    /// Not at all.
    None,
    /// `input.merge_adjacent`: dissolved.
    Dissolve,
    /// For a step that [needs it](crate::process::step::Needs::merge):
    /// their union made exactly.
    Exactly,
}

/// The coverage of `input.neighbours`, reprojected to the CRS the polygons
/// are handed out in (`polygons`), and what its source holds.
pub(super) fn read_neighbours(
    n: &crate::config::NeighboursSpec,
    polygons: &SourceInfo,
) -> Result<(crate::neighbours::Coverage, SourceInfo), RunError> {
    use crate::neighbours::{unit_geometry, Coverage, Unit};
    let error = |reason: String| {
        RunError::Io(IoError::Read {
            source_name: n.source.clone(),
            reason,
        })
    };
    let (features, info) = read_side(&n.layer_source(), "input.neighbours", polygons)?;
    let mut units = Vec::new();
    let mut bad = None;
    for f in features {
        match unit_geometry(f.fid, f.geometry.as_ref()) {
            Ok(geometry) => units.push(Unit {
                fid: f.fid,
                geometry,
                attributes: f.attributes,
            }),
            Err(why) => {
                bad.get_or_insert(why);
            }
        }
    }
    if let Some(why) = bad {
        return Err(error(format!(
            "`input.neighbours`: {why} (layer `{}`; filter units out with `input.neighbours.where`)",
            info.layer
        )));
    }
    if units.is_empty() {
        return Err(error(format!(
            "`input.neighbours`: layer `{}` has no units (after its `where`); give the coverage whose units take the area",
            info.layer
        )));
    }
    units.sort_by_key(|u| u.fid);
    tracing::info!(source = %n.source, layer = %info.layer, units = units.len(), "input.neighbours: coverage read");
    Ok((Coverage::new(units).with_snap(n.snap), info))
}

/// Why the reader thread stops before the end of the source.
enum Stop {
    /// Nobody takes batches any more (the run stopped).
    Gone,
    /// Reading failed.
    Failed(IoError),
}

impl From<IoError> for Stop {
    fn from(e: IoError) -> Self {
        Stop::Failed(e)
    }
}

/// The reader thread ended without a word: it panicked.
pub(super) fn reader_gone(reader: std::thread::ScopedJoinHandle<'_, ()>) -> RunError {
    let _ = reader.join();
    RunError::Io(IoError::Output {
        path: String::new(),
        reason: "the reader thread failed with an internal error; please report it".into(),
    })
}
