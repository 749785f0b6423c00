//! GDAL's own error reports, routed through the project's logging.
//!
//! GDAL reports problems through its error handler (by default it prints
//! `ERROR 1: …` lines to stderr, which breaks `--log-format json`, and some
//! drivers report a bad attribute filter only there while the call itself
//! "succeeds"). [`install`] replaces the handler: every message goes to
//! `tracing` (warnings as warnings of the `gdal` target, but for the
//! harmless notices of [`HARMLESS`], which go to debug with the rest),
//! and failures are also kept per thread so that the reader and
//! writer can turn them into errors ([`take_failures`]) and add GDAL's words
//! to their own messages ([`last_failure`]).

use gdal::errors::CplErrType;
use std::cell::RefCell;
use std::sync::Once;

thread_local! {
    static FAILURES: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

/// GDAL warnings a user cannot act on, logged at debug level instead of
/// as warnings, by the start of their text:
///
/// * a GeoPackage written by a newer GDAL (pyogrio, QGIS) stamped
///   GeoPackage 1.4, which GDAL 3.6 reads in full all the same ("This
///   version of GeoPackage user_version=… may only be partially
///   supported").
pub const HARMLESS: &[&str] = &["This version of GeoPackage user_version="];

/// Whether a GDAL warning is one of the [`HARMLESS`] notices.
pub fn harmless(message: &str) -> bool {
    HARMLESS.iter().any(|h| message.starts_with(h))
}

/// Routes GDAL's error reports to `tracing` (once per process).
pub fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        gdal::config::set_error_handler(|class, number, message| match class {
            CplErrType::Failure | CplErrType::Fatal => {
                tracing::debug!(target: "gdal", number, "{message}");
                FAILURES.with(|f| f.borrow_mut().push(message.to_string()));
            }
            CplErrType::Warning if harmless(message) => {
                tracing::debug!(target: "gdal", number, "{message}")
            }
            CplErrType::Warning => tracing::warn!(target: "gdal", number, "{message}"),
            _ => tracing::debug!(target: "gdal", number, "{message}"),
        });
    });
}

/// The failures GDAL reported on this thread since the last call.
pub fn take_failures() -> Vec<String> {
    FAILURES.with(|f| std::mem::take(&mut *f.borrow_mut()))
}

/// The last failure GDAL reported on this thread, if any (kept).
pub fn last_failure() -> Option<String> {
    FAILURES.with(|f| f.borrow().last().cloned())
}

/// Forgets earlier failures on this thread (before a call whose failures
/// are to be checked).
pub fn clear() {
    FAILURES.with(|f| f.borrow_mut().clear());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_geopackage_version_notice_is_harmless_and_others_are_not() {
        assert!(harmless("This version of GeoPackage user_version=0x000028A0 (10400, v1.4.0) on 'x.gpkg' may only be partially supported"));
        assert!(!harmless("Field format 'x' not supported"));
    }
}
