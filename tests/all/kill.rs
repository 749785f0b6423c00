//! A run stopped mid-way — SIGTERM (a Kubernetes eviction, an Airflow
//! timeout), SIGINT (Ctrl-C), SIGHUP, or SIGKILL — leaves the previous
//! output byte for byte as it was and, once the next run on the same output
//! has started, no temporary file.

use crate::common::*;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The temporary files beside `out`.
fn temporaries(out: &Path) -> Vec<PathBuf> {
    let name = out.file_name().unwrap().to_string_lossy().to_string();
    std::fs::read_dir(out.parent().unwrap())
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(&format!(".{name}.")))
        })
        .collect()
}

/// Starts a long run writing `out` and waits until its temporary file exists.
fn start_long_run(out: &Path) -> std::process::Child {
    let child = Command::new(env!("CARGO_BIN_EXE_skeletonise"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "pipelines/compare-methods.yaml",
            "--set",
            "input.layer=islands_hebrides",
            "--set",
            "output.bars=true",
            "--threads",
            "1",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let t = Instant::now();
    while temporaries(out).is_empty() {
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "no temporary file appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // Well into the work.
    std::thread::sleep(Duration::from_millis(300));
    child
}

fn previous_output(dir: &Path) -> (PathBuf, Vec<u8>) {
    let out = dir.join("out.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&out).unwrap();
    (out, bytes)
}

#[test]
fn a_caught_signal_removes_the_temporary_file_and_exits_128_plus_the_signal() {
    for (sig, num) in [("TERM", 15), ("INT", 2), ("HUP", 1)] {
        let d = tmp();
        let (out, before) = previous_output(d.path());
        let mut child = start_long_run(&out);
        let k = Command::new("kill")
            .args([format!("-{sig}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(k.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(128 + num), "SIG{sig}");
        assert!(
            temporaries(&out).is_empty(),
            "SIG{sig}: {:?}",
            temporaries(&out)
        );
        assert_eq!(
            std::fs::read(&out).unwrap(),
            before,
            "SIG{sig}: the previous output changed"
        );
    }
}

#[test]
fn after_sigkill_the_next_run_removes_what_was_left() {
    let d = tmp();
    let (out, before) = previous_output(d.path());
    let mut child = start_long_run(&out);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !temporaries(&out).is_empty(),
        "SIGKILL cannot be caught: the file stays for now"
    );
    assert_eq!(
        std::fs::read(&out).unwrap(),
        before,
        "the previous output changed"
    );
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-q",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.overwrite=true",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(temporaries(&out).is_empty(), "{:?}", temporaries(&out));
}
