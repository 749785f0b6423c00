//! A killed run leaves nothing behind.
//!
//! The output is written under a temporary name beside it and renamed into
//! place at the end ([`crate::io::writer`]). On SIGTERM (a Kubernetes
//! eviction, an Airflow timeout), SIGINT (Ctrl-C) or SIGHUP the temporary
//! files of the runs in progress are removed and the process exits with
//! status 128 + the signal's number; the previous output, if any, stays as
//! it was. A SIGKILL cannot be caught: the next run on the same output
//! removes what such a run left ([`remove_stale`]).

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

static TEMPORARY: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Files SQLite may keep beside a GeoPackage while it is written.
const COMPANIONS: [&str; 4] = ["", "-journal", "-wal", "-shm"];

/// Removes `p` and the files SQLite may have kept beside it.
pub(crate) fn remove_with_companions(p: &Path) {
    for suffix in COMPANIONS {
        let mut f = p.as_os_str().to_owned();
        f.push(suffix);
        let _ = std::fs::remove_file(PathBuf::from(f));
    }
}

/// Starts removing temporary files on SIGTERM, SIGINT and SIGHUP (once per
/// process). Fails only when the signal handlers cannot be installed.
pub fn install() -> std::io::Result<()> {
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = signal_hook::iterator::Signals::new([SIGTERM, SIGINT, SIGHUP]).map(|mut s| {
            std::thread::spawn(move || {
                if let Some(sig) = s.forever().next() {
                    let files = TEMPORARY.lock().map(|v| v.clone()).unwrap_or_default();
                    for f in &files {
                        remove_with_companions(f);
                    }
                    tracing::error!(
                        signal = sig,
                        "stopped by signal {sig}: the unfinished output was removed, the previous output (if any) is unchanged"
                    );
                    std::process::exit(128 + sig);
                }
            });
        });
    });
    result
}

/// Registers a temporary file to remove if the process is stopped.
pub fn register(p: &Path) {
    if let Ok(mut v) = TEMPORARY.lock() {
        v.push(p.to_path_buf());
    }
}

/// Forgets a temporary file (renamed into place or removed).
pub fn unregister(p: &Path) {
    if let Ok(mut v) = TEMPORARY.lock() {
        v.retain(|x| x != p);
    }
}

/// Removes the temporary files of earlier runs on output `path` whose
/// process no longer runs (killed with SIGKILL, or a crashed machine).
pub fn remove_stale(path: &Path) {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().to_string()) else {
        return;
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().to_string();
        let Some(pid) = file
            .strip_prefix(&prefix)
            .and_then(|r| {
                r.strip_suffix(".tmp.gpkg")
                    .or_else(|| r.strip_suffix(".tmp.html"))
            })
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !alive(pid) {
            tracing::info!(file = %e.path().display(), "removing what an interrupted run left");
            remove_with_companions(&e.path());
        }
    }
}

/// Whether process `pid` exists.
fn alive(pid: u32) -> bool {
    Path::new(&format!("/proc/{pid}")).exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::io::guard::Kind;

    fn temporary_name(path: &Path, pid: u32) -> PathBuf {
        crate::io::guard::temporary_name(path, pid, Kind::GeoPackage)
    }

    #[test]
    fn stale_temporary_files_of_dead_processes_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.gpkg");
        // A pid that cannot be alive (above the kernel's pid_max).
        let stale = temporary_name(&out, 4_194_305);
        std::fs::write(&stale, b"x").unwrap();
        std::fs::write(format!("{}-journal", stale.display()), b"x").unwrap();
        let own = temporary_name(&out, std::process::id());
        std::fs::write(&own, b"x").unwrap();
        remove_stale(&out);
        assert!(!stale.exists());
        assert!(!Path::new(&format!("{}-journal", stale.display())).exists());
        assert!(own.exists(), "a living run's file is kept");
    }
}
