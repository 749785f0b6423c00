//! The reader thread: the source opened on its own thread, its features in
//! batches (every one first, dissolved, with `input.merge_adjacent`), and
//! the line network of `input.connect`.

use super::{Batch, RunError};
use crate::config::InputSpec;
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

/// The lines of `input.connect`, reprojected to the CRS the polygons are
/// handed out in (`polygons`); a layer without lines is an error.
pub(super) fn read_network(
    c: &crate::config::ConnectSpec,
    polygons: &SourceInfo,
) -> Result<crate::connect::Network, RunError> {
    let mut reader =
        Reader::open(&c.input(polygons.srs_wkt.as_deref())).map_err(|e| connect_error(c, e))?;
    let mut lines = Vec::new();
    let mut features = 0;
    reader.read::<IoError>(1024, false, |batch| {
        features += batch.len();
        for f in batch {
            let mut ls = Vec::new();
            if let Some(g) = &f.geometry {
                crate::connect::lines_of(g, &mut ls);
            }
            lines.extend(ls.into_iter().map(|l| (f.fid, l)));
        }
        Ok(())
    })?;
    if lines.is_empty() {
        return Err(no_lines(c, reader.info(), features));
    }
    tracing::info!(source = %c.source, layer = %reader.info().layer, crs = %reader.info().crs_name, lines = lines.len(), "connect: line network read");
    Ok(crate::connect::Network::new(lines, c.snap))
}

/// An error opening `input.connect`, said to be about it.
fn connect_error(c: &crate::config::ConnectSpec, e: IoError) -> RunError {
    RunError::Io(IoError::Read {
        source_name: c.source.clone(),
        reason: second_input_error("connect", e),
    })
}

/// Why a second input (`input.<what>`) could not be opened, with the keys
/// of that input to fix (its `layer`, its `where`), not the polygons'.
fn second_input_error(what: &str, e: IoError) -> String {
    match e {
        IoError::NoLayer {
            source_name,
            layer,
            available,
        } => format!(
            "`input.{what}`: layer {layer} not found in `{source_name}`; available layers: {available}; choose one with `input.{what}.layer`"
        ),
        IoError::BadWhere { filter, reason } => format!(
            "`input.{what}`: invalid `input.{what}.where` filter `{filter}`: {reason}; use OGR SQL syntax, e.g. \"area_m2 > 1e6\""
        ),
        e => format!("`input.{what}`: {e}"),
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
    /// A partition's collapsed polygons: their union made exactly.
    Exactly,
}

/// The coverage of `input.neighbours`, reprojected to the CRS the polygons
/// are handed out in (`polygons`), and what its source holds.
pub(super) fn read_neighbours(
    n: &crate::config::NeighboursSpec,
    polygons: &SourceInfo,
) -> Result<(crate::partition::Coverage, SourceInfo), RunError> {
    use crate::partition::{Coverage, Unit};
    let error = |reason: String| {
        RunError::Io(IoError::Read {
            source_name: n.source.clone(),
            reason,
        })
    };
    let mut reader = Reader::open(&n.input(polygons.srs_wkt.as_deref()))
        .map_err(|e| error(second_input_error("neighbours", e)))?;
    let mut units = Vec::new();
    let mut bad = None;
    reader.read::<IoError>(1024, false, |batch| {
        for f in batch {
            match crate::partition::unit_geometry(f.fid, f.geometry.as_ref()) {
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
        Ok(())
    })?;
    if let Some(why) = bad {
        return Err(error(format!(
            "`input.neighbours`: {why} (layer `{}`; filter units out with `input.neighbours.where`)",
            reader.info().layer
        )));
    }
    if units.is_empty() {
        return Err(error(format!(
            "`input.neighbours`: layer `{}` has no units (after its `where`); give the coverage whose units take the area",
            reader.info().layer
        )));
    }
    units.sort_by_key(|u| u.fid);
    tracing::info!(source = %n.source, layer = %reader.info().layer, units = units.len(), "partition: coverage read");
    Ok((
        Coverage::new(units).with_snap(n.snap),
        reader.info().clone(),
    ))
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
