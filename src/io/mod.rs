//! Everything that touches GDAL: the [`reader`] turns any OGR source into
//! owned features with `geo` geometries; the [`writer`] writes the
//! GeoPackage layers; [`readback`] reads an output GeoPackage back for the
//! report. No GDAL type leaves this module.

pub mod gdal_errors;
pub mod guard;
pub mod lonlat;
pub mod readback;
pub mod reader;
pub(crate) mod signals;
pub mod writer;

/// Removes the temporary files of the runs in progress on SIGTERM, SIGINT
/// and SIGHUP, then exits with 128 + the signal (once per process; the
/// command line calls it at start). Fails only when the handlers cannot be
/// installed.
pub fn install_signal_handlers() -> std::io::Result<()> {
    signals::install()
}

pub use reader::{read_layer_polygons, FieldInfo, InputSpec, LayerRef, Reader, SourceInfo};

use thiserror::Error;

/// Errors opening, reading or writing data sources. Each says what went wrong,
/// where, and what to do about it.
#[derive(Debug, Error)]
pub enum IoError {
    /// The input could not be opened.
    #[error("cannot open input `{source_name}`: {reason}; check the path, the connection string or the file permissions")]
    Open {
        /// The data source string.
        source_name: String,
        /// GDAL's message.
        reason: String,
    },
    /// The requested layer does not exist.
    #[error("layer {layer} not found in `{source_name}`; available layers: {available}; choose one with `-l LAYER` (`input.layer`)")]
    NoLayer {
        /// The data source string.
        source_name: String,
        /// The requested layer (name or index).
        layer: String,
        /// Comma-separated names of the layers that exist.
        available: String,
    },
    /// Reading the source failed.
    #[error("reading `{source_name}` failed: {reason}; the run stops, nothing is written")]
    Read {
        /// The data source string.
        source_name: String,
        /// GDAL's messages.
        reason: String,
    },
    /// The attribute filter was rejected by OGR.
    #[error("invalid `input.where` filter `{filter}`: {reason}; use OGR SQL syntax, e.g. \"area_m2 > 1e6\"")]
    BadWhere {
        /// The filter text.
        filter: String,
        /// GDAL's message.
        reason: String,
    },
    /// The file given as an output of a run cannot be read as one.
    #[error("cannot read `{path}` as the output of `skeletonise run`: {reason}")]
    NotAnOutput {
        /// The file.
        path: String,
        /// Why.
        reason: String,
    },
    /// An attribute filter on a layer of an output GeoPackage was rejected.
    #[error("invalid filter `{filter}` on layer `{layer}` of `{path}`: {reason}; use OGR SQL on the layer's columns, e.g. \"distortion > 0.01\" or \"kind = 'lake'\"")]
    BadFilter {
        /// The GeoPackage.
        path: String,
        /// The layer filtered.
        layer: String,
        /// The filter text.
        filter: String,
        /// GDAL's message.
        reason: String,
    },
    /// A geographic CRS and no reprojection.
    #[error("layer `{layer}` has the geographic CRS {crs}; skeleton radii and scores need a projected CRS: {fix}")]
    Geographic {
        /// Layer name.
        layer: String,
        /// The CRS's name.
        crs: String,
        /// How to reproject, in the words of the command.
        fix: &'static str,
    },
    /// The reprojection target is unusable.
    #[error("invalid `input.reproject` value `{target}`: {reason}")]
    BadReproject {
        /// The requested CRS.
        target: String,
        /// Why it is unusable.
        reason: String,
    },
    /// The output exists and `overwrite` is off.
    #[error("output `{path}` already exists; set `output.overwrite: true` (or `--overwrite`) or choose another path with `-o`")]
    OutputExists {
        /// The output path.
        path: String,
    },
    /// The output cannot be written.
    #[error("cannot write output `{path}`: {reason}")]
    Output {
        /// The output path.
        path: String,
        /// What failed.
        reason: String,
    },
    /// Any other GDAL failure.
    #[error("{context}: {reason}")]
    Gdal {
        /// What was being done.
        context: String,
        /// GDAL's message.
        reason: String,
    },
}

/// Sets an OGR SQL attribute filter and makes the layer evaluate it once, so
/// that a filter the driver only rejects when it runs it (GeoPackage passes
/// it to SQLite) fails here, with the driver's message, instead of silently
/// selecting nothing.
pub(crate) fn set_filter(layer: &mut gdal::vector::Layer<'_>, filter: &str) -> Result<(), String> {
    use gdal::vector::LayerAccess;
    layer
        .set_attribute_filter(filter)
        .map_err(|e| e.to_string())?;
    // SAFETY: GDAL's thread-local error state, read and reset around one
    // call on this thread; the quiet handler keeps GDAL from printing it.
    unsafe {
        gdal_sys::CPLPushErrorHandler(Some(gdal_sys::CPLQuietErrorHandler));
        gdal_sys::CPLErrorReset();
    }
    let _ = layer.feature_count();
    let failed = unsafe {
        let failed = gdal_sys::CPLGetLastErrorType() >= gdal_sys::CPLErr::CE_Failure;
        let msg = std::ffi::CStr::from_ptr(gdal_sys::CPLGetLastErrorMsg())
            .to_string_lossy()
            .to_string();
        gdal_sys::CPLErrorReset();
        gdal_sys::CPLPopErrorHandler();
        failed.then_some(msg)
    };
    match failed {
        Some(msg) => {
            layer.clear_attribute_filter();
            Err(msg)
        }
        None => Ok(()),
    }
}

impl IoError {
    /// A GDAL failure while doing `context`, with GDAL's own last message
    /// (the error value alone often only says "returned error: '6'").
    pub(crate) fn gdal(context: impl Into<String>, e: impl std::fmt::Display) -> Self {
        let e = e.to_string();
        let reason = match gdal_errors::last_failure() {
            Some(m) if !e.contains(&m) => format!("{m} ({e})"),
            _ => e,
        };
        IoError::Gdal {
            context: context.into(),
            reason: with_full_disk_hint(reason),
        }
    }
}

/// `reason` with what to do when it is SQLite's or the system's word for a
/// full disk (or a file size limit reached), which says only "disk I/O
/// error", "database or disk is full", "cannot rollback" or, when SQLite
/// rolled the transaction back itself after the failed write, "cannot
/// commit - no transaction is active".
pub(crate) fn with_full_disk_hint(reason: String) -> String {
    const FULL: [&str; 6] = [
        "disk I/O error",
        "database or disk is full",
        "No space left",
        "File too large",
        "cannot rollback",
        "no transaction is active",
    ];
    if FULL.iter().any(|f| reason.contains(f)) {
        format!(
            "{reason}; the disk is probably full (or a file size limit was reached): free space there or write the output to another disk; nothing of this run was kept and an earlier output is unchanged"
        )
    } else {
        reason
    }
}
