//! One guard for every file the tool writes: the output GeoPackage, the
//! report and their temporary files.
//!
//! A path is written only when it is
//! - of the kind expected (`.gpkg` for the output, `.html`/`.htm` for the
//!   report), so that a slip of the keyboard cannot turn a data file into
//!   HTML;
//! - not a directory, a device, a FIFO or a socket (also through a link);
//! - none of the data sources the job reads or has just written (the
//!   input, the connect source, the polygons a report reads, the GeoPackage
//!   a report is made of): compared as files (device and inode) when they
//!   exist, after resolving links, and as resolved paths otherwise;
//! - new, or an existing regular file with `overwrite`;
//! - in an existing directory the process may write to.
//!
//! Temporary files are created with `O_EXCL` (never through a link or over
//! an existing file) and removed on every failure path.

use super::IoError;
use std::path::{Path, PathBuf};

/// What a written path holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The output GeoPackage (`.gpkg`).
    GeoPackage,
    /// The HTML report (`.html` or `.htm`).
    Report,
}

impl Kind {
    fn extensions(self) -> &'static [&'static str] {
        match self {
            Kind::GeoPackage => &["gpkg"],
            Kind::Report => &["html", "htm"],
        }
    }

    fn hint(self) -> &'static str {
        match self {
            Kind::GeoPackage => "the output is always a GeoPackage: give a path ending in `.gpkg` (`output.path` or `-o`)",
            Kind::Report => "the report is an HTML file: give a path ending in `.html` (`output.report.path` or `report -o`)",
        }
    }

    fn overwrite_hint(self) -> &'static str {
        match self {
            Kind::GeoPackage => "set `output.overwrite: true` (or `--overwrite`) or choose another path with `-o`",
            Kind::Report => "set `output.overwrite: true` in the pipeline (`report --overwrite` on the command line) or choose another path",
        }
    }
}

/// A data source that a written file must never replace, with what it is
/// to the job (for the message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Protected<'a> {
    /// What the source is to the job, e.g. "the input", "the output GeoPackage".
    pub role: &'static str,
    /// The data source string (a path, `/vsizip/…`, `PG:…`).
    pub source: &'a str,
}

impl<'a> Protected<'a> {
    /// `source` in the role `role`.
    pub fn new(role: &'static str, source: &'a str) -> Self {
        Self { role, source }
    }
}

/// A file to write and the rules it must pass.
#[derive(Debug, Clone, Copy)]
pub struct Target<'a> {
    /// The path to write.
    pub path: &'a Path,
    /// What it holds.
    pub kind: Kind,
    /// An existing regular file may be replaced.
    pub overwrite: bool,
    /// The sources it must not be.
    pub protected: &'a [Protected<'a>],
}

impl Target<'_> {
    fn error(&self, reason: String) -> IoError {
        IoError::Output {
            path: self.path.display().to_string(),
            reason,
        }
    }

    /// Checks every rule of the module documentation, creating nothing
    /// that stays (the directory is probed with a file that is removed).
    pub fn check(&self) -> Result<(), IoError> {
        let path = self.path;
        let right_kind = path.extension().is_some_and(|e| {
            self.kind
                .extensions()
                .iter()
                .any(|x| e.eq_ignore_ascii_case(x))
        });
        if !right_kind {
            return Err(self.error(self.kind.hint().into()));
        }
        // `dir.gpkg/` names a directory to the system, though its
        // extension reads as a file's.
        if path
            .as_os_str()
            .to_string_lossy()
            .ends_with(['/', std::path::MAIN_SEPARATOR])
        {
            return Err(self.error(format!(
                "it ends in a path separator, which makes it a directory; give a file name such as `{}`",
                Path::new(path.to_string_lossy().trim_end_matches(['/', std::path::MAIN_SEPARATOR]))
                    .display()
            )));
        }
        not_special(path).map_err(|r| self.error(r))?;
        self.not_protected(path)?;
        if std::fs::symlink_metadata(path).is_ok() && !self.overwrite {
            return Err(match self.kind {
                Kind::GeoPackage => IoError::OutputExists {
                    path: path.display().to_string(),
                },
                Kind::Report => self.error(format!(
                    "the file already exists; {}",
                    self.kind.overwrite_hint()
                )),
            });
        }
        let parent = parent_of(path);
        if !parent.is_dir() {
            return Err(self.error(format!(
                "directory `{}` does not exist; create it first",
                parent.display()
            )));
        }
        probe_writable(parent).map_err(|e| {
            self.error(format!(
                "directory `{}` cannot be written ({e}); choose a directory you may write to",
                parent.display()
            ))
        })
    }

    /// Fails when `path` is one of the protected sources.
    fn not_protected(&self, path: &Path) -> Result<(), IoError> {
        for p in self.protected {
            if let Some(src) = local_path(p.source) {
                if same_file(path, &src) {
                    return Err(self.error(format!(
                        "it is {} `{}`; writing it would destroy that data: choose another path",
                        p.role, p.source
                    )));
                }
            }
        }
        Ok(())
    }

    /// A temporary file beside the target for process `pid`, made sure to
    /// be none of the protected sources and no special file; an old file of
    /// that name (a run of a process with the same id) is removed.
    pub fn temporary(&self, pid: u32) -> Result<PathBuf, IoError> {
        let tmp = temporary_name(self.path, pid, self.kind);
        not_special(&tmp)
            .map_err(|r| self.error(format!("its temporary file `{}` is {r}", tmp.display())))?;
        self.not_protected(&tmp)?;
        let _ = std::fs::remove_file(&tmp);
        Ok(tmp)
    }
}

/// The temporary name of `path` for process `pid`: `.NAME.PID.tmp.gpkg`
/// (or `.tmp.html`) beside it.
pub fn temporary_name(path: &Path, pid: u32, kind: Kind) -> PathBuf {
    let (default, ext) = match kind {
        Kind::GeoPackage => ("out.gpkg", "gpkg"),
        Kind::Report => ("report.html", "html"),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| default.into());
    path.with_file_name(format!(".{name}.{pid}.tmp.{ext}"))
}

/// Writes `bytes` to the new file `path` (`O_EXCL`: never through a link
/// or over a file that exists).
pub fn create_new(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)?;
    let r = f.write_all(bytes).and_then(|_| f.sync_all());
    if r.is_err() {
        drop(f);
        let _ = std::fs::remove_file(path);
    }
    r
}

/// Why `path` (followed through links) cannot be written as a file, if it
/// exists and is not a regular file.
fn not_special(path: &Path) -> Result<(), String> {
    let Ok(meta) = std::fs::metadata(path) else {
        // A link to nowhere would be replaced by the rename, not followed.
        return Ok(());
    };
    if meta.is_file() {
        return Ok(());
    }
    let what = if meta.is_dir() {
        "a directory"
    } else {
        "not a regular file (a device, FIFO or socket)"
    };
    Err(format!("{what}; choose the path of a file"))
}

/// Whether `a` and `b` are the same file: the same device and inode when
/// both exist, else the same path after resolving links.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    resolved(a) == resolved(b)
}

/// The directory of `path` (`.` for a bare file name).
fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `path` with links resolved (its parent's when it does not exist yet).
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    match (std::fs::canonicalize(parent_of(path)), path.file_name()) {
        (Ok(p), Some(n)) => p.join(n),
        _ => path.to_path_buf(),
    }
}

/// The file behind an OGR data source string, when it is a local file
/// (`PG:` and other connection strings are not).
pub(crate) fn local_path(source: &str) -> Option<PathBuf> {
    let s = source
        .trim_start_matches("/vsizip/")
        .trim_start_matches("/vsigzip/")
        .trim_start_matches("/vsitar/");
    if s.is_empty()
        || s.starts_with("/vsi")
        || s.contains("://")
        || s.split_once(':')
            .is_some_and(|(a, _)| a.len() > 1 && !a.contains('/'))
    {
        return None;
    }
    // A path inside an archive: the archive is the file.
    let archive = [".zip/", ".gz/", ".tar/"]
        .iter()
        .find_map(|ext| s.find(ext).map(|i| &s[..i + ext.len() - 1]));
    Some(PathBuf::from(archive.unwrap_or(s)))
}

/// Creates and removes a file in `dir`.
fn probe_writable(dir: &Path) -> std::io::Result<()> {
    let probe = dir.join(format!(".skeletonise-probe-{}", std::process::id()));
    let _ = std::fs::remove_file(&probe);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)?;
    std::fs::remove_file(&probe)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target<'a>(path: &'a Path, kind: Kind, protected: &'a [Protected<'a>]) -> Target<'a> {
        Target {
            path,
            kind,
            overwrite: true,
            protected,
        }
    }

    #[test]
    fn a_hard_link_to_the_input_is_the_input() {
        let d = tempfile::tempdir().unwrap();
        let input = d.path().join("in.gpkg");
        std::fs::write(&input, b"data").unwrap();
        let link = d.path().join("other.gpkg");
        std::fs::hard_link(&input, &link).unwrap();
        let src = input.display().to_string();
        let p = [Protected::new("the input", &src)];
        let e = target(&link, Kind::GeoPackage, &p).check().unwrap_err();
        assert!(e.to_string().contains("it is the input"), "{e}");
        let free = d.path().join("free.gpkg");
        target(&free, Kind::GeoPackage, &p).check().unwrap();
    }

    #[test]
    fn reports_are_html_and_replace_a_file_only_with_overwrite() {
        let d = tempfile::tempdir().unwrap();
        let gpkg = d.path().join("x.gpkg");
        let e = target(&gpkg, Kind::Report, &[]).check().unwrap_err();
        assert!(e.to_string().contains(".html"), "{e}");
        let html = d.path().join("r.html");
        std::fs::write(&html, b"old").unwrap();
        let mut t = target(&html, Kind::Report, &[]);
        t.check().unwrap();
        t.overwrite = false;
        let e = t.check().unwrap_err();
        assert!(e.to_string().contains("already exists"), "{e}");
    }

    #[test]
    fn devices_and_fifos_are_refused_also_through_a_link() {
        let d = tempfile::tempdir().unwrap();
        let link = d.path().join("null.html");
        std::os::unix::fs::symlink("/dev/null", &link).unwrap();
        let e = target(&link, Kind::Report, &[]).check().unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        let fifo = d.path().join("f.html");
        let c = std::ffi::CString::new(fifo.display().to_string()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
        let e = target(&fifo, Kind::Report, &[]).check().unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }

    #[test]
    fn temporary_files_never_follow_a_link() {
        let d = tempfile::tempdir().unwrap();
        let victim = d.path().join("victim.txt");
        std::fs::write(&victim, b"keep").unwrap();
        let tmp = d.path().join("t.html");
        std::os::unix::fs::symlink(&victim, &tmp).unwrap();
        assert!(create_new(&tmp, b"html").is_err());
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
    }
}
