//! The bad-input corpus (SPEC §11 and the reliability issue): every case is
//! built here — a GeoPackage layer of the given WKT geometries, or a broken
//! pipeline file or path — and run through the real binary, with its exact
//! outcome: exit code, a fragment of the message, and the run's counts of
//! features read, written and rejected (from `skeletonise_runs`).

use crate::common::*;
use std::path::Path;

/// What a case must give.
struct Expect {
    code: i32,
    message: &'static str,
    /// (read, written, rejected) when the run finishes.
    counts: Option<(i64, i64, i64)>,
}

fn ok(read: i64, written: i64, rejected: i64) -> Expect {
    Expect {
        code: 0,
        message: "",
        counts: Some((read, written, rejected)),
    }
}

fn fails(code: i32, message: &'static str) -> Expect {
    Expect {
        code,
        message,
        counts: None,
    }
}

/// Runs `pipelines/compare-methods.yaml` over a layer of `wkts` (EPSG
/// `epsg`) with `args` and checks the outcome; returns the directory (kept
/// while the caller looks) and the output path.
fn case(
    name: &str,
    epsg: u32,
    wkts: &[Option<&str>],
    args: &[&str],
    want: Expect,
) -> (tempfile::TempDir, std::path::PathBuf) {
    let d = tmp();
    let dir = d.path().to_path_buf();
    let src = dir.join("in.gpkg");
    make_layer(&src, "bad", epsg, wkts);
    let out = dir.join("out.gpkg");
    let mut argv = vec![
        "run",
        "pipelines/compare-methods.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=bad",
        "-o",
        out.to_str().unwrap(),
    ];
    argv.extend_from_slice(args);
    check(name, &argv, &out, want);
    (d, out)
}

fn check(name: &str, argv: &[&str], out: &Path, want: Expect) {
    let o = skeletonise(argv);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, want.code, "{name}: {err}");
    assert!(
        err.contains(want.message),
        "{name}: `{}` not in {err}",
        want.message
    );
    if let Some((r, w, j)) = want.counts {
        let ds = open(out);
        let got = (
            ints(&ds, "skeletonise_runs", "features_read")[0].unwrap(),
            ints(&ds, "skeletonise_runs", "features_written")[0].unwrap(),
            ints(&ds, "skeletonise_runs", "features_rejected")[0].unwrap(),
        );
        assert_eq!(got, (r, w, j), "{name}: (read, written, rejected)");
        assert_eq!(count(&ds, "skeletons") as i64, w, "{name}");
        assert_eq!(count(&ds, "rejected") as i64, j, "{name}");
    }
}

fn rejected_reason(out: &Path) -> String {
    strings(&open(out), "rejected", "reason")[0]
        .clone()
        .unwrap_or_default()
}

macro_rules! geometry_case {
    ($name:ident, $wkts:expr, $args:expr, $want:expr $(, $reason:expr)?) => {
        #[test]
        fn $name() {
            let (_dir, _out) = case(stringify!($name), 3035, &$wkts, &$args, $want);
            $( assert!(rejected_reason(&_out).contains($reason), "{}: {}", stringify!($name), rejected_reason(&_out)); )?
        }
    };
}

const SQUARE: &str = "POLYGON((0 0,100 0,100 100,0 100,0 0))";
const BOW_TIE: &str = "POLYGON((0 0,100 100,100 0,0 60,0 0))";
const NO_REPAIR: [&str; 2] = ["--set", "steps.prepare.make_valid=false"];

geometry_case!(null_geometry, [None], [], ok(1, 0, 1), "NULL geometry");
geometry_case!(
    empty_geometry,
    [Some("POLYGON EMPTY")],
    [],
    ok(1, 0, 1),
    "empty"
);
geometry_case!(
    point_geometry,
    [Some("POINT(1 2)")],
    [],
    ok(1, 0, 1),
    "point"
);
geometry_case!(
    line_geometry,
    [Some("LINESTRING(0 0,10 10)")],
    [],
    ok(1, 0, 1),
    "line"
);
geometry_case!(bow_tie_repaired, [Some(BOW_TIE)], [], ok(1, 1, 0));
geometry_case!(
    bow_tie_without_repair,
    [Some(BOW_TIE)],
    NO_REPAIR,
    ok(1, 0, 1),
    "make_valid: true"
);
geometry_case!(
    self_intersecting_without_repair,
    [Some("POLYGON((0 0,100 0,100 100,50 -20,0 100,0 0))")],
    NO_REPAIR,
    ok(1, 0, 1),
    "invalid polygon"
);
geometry_case!(
    spike_repaired,
    [Some(
        "POLYGON((0 0,100 0,100 100,50 100,50 200,50 100,0 100,0 0))"
    )],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    duplicate_vertices,
    [Some("POLYGON((0 0,0 0,100 0,100 0,100 100,0 100,0 0))")],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    hole_touching_shell_at_a_vertex,
    [Some(
        "POLYGON((0 0,100 0,100 100,0 100,0 0),(0 0,30 20,20 30,0 0))"
    )],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    hole_touching_shell_inside_an_edge,
    [Some(
        "POLYGON((0 0,100 0,100 100,0 100,0 0),(0 50,30 40,30 60,0 50))"
    )],
    NO_REPAIR,
    ok(1, 1, 0)
);
geometry_case!(
    z_and_m,
    [Some(
        "POLYGON ZM((0 0 1 2,100 0 1 2,100 100 1 2,0 100 1 2,0 0 1 2))"
    )],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    curved,
    [Some(
        "CURVEPOLYGON(CIRCULARSTRING(0 0,100 100,200 0,100 -100,0 0))"
    )],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    huge_coordinates,
    [Some("POLYGON((10000000 10000000,10000100 10000000,10000100 10000030,10000000 10000030,10000000 10000000))")],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    tiny,
    [Some("POLYGON((0 0,0.000001 0,0 0.000001,0 0))")],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    sliver,
    [Some("POLYGON((0 0,1000000 0,1000000 0.001,0 0.001,0 0))")],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    multipolygon,
    [Some(
        "MULTIPOLYGON(((0 0,10 0,10 10,0 10,0 0)),((20 0,40 0,40 5,20 5,20 0)))"
    )],
    [],
    ok(1, 1, 0)
);
geometry_case!(
    good_and_bad_together,
    [Some(SQUARE), None, Some("POINT(0 0)"), Some(SQUARE)],
    [],
    ok(4, 2, 2)
);
geometry_case!(
    on_error_fail_stops_at_the_first_rejection,
    [Some(SQUARE), None],
    ["--set", "on_error=fail"],
    fails(65, "on_error: fail")
);
geometry_case!(
    too_many_vertices,
    [Some(SQUARE)],
    ["--set", "steps.prepare.max_vertices=3"],
    ok(1, 0, 1),
    "max_vertices"
);

#[test]
fn geographic_crs_without_reproject() {
    let d = tmp();
    let src = d.path().join("geo.gpkg");
    make_layer(&src, "bad", 4326, &[Some("POLYGON((0 0,1 0,1 1,0 1,0 0))")]);
    let out = d.path().join("o.gpkg");
    let argv = [
        "run",
        "pipelines/compare-methods.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=bad",
        "-o",
        out.to_str().unwrap(),
    ];
    check("geographic", &argv, &out, fails(1, "input.reproject"));
    assert!(!out.exists());
}

#[test]
fn unreadable_sources_missing_layers_and_bad_filters() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = out.to_str().unwrap();
    let garbage = d.path().join("garbage.gpkg");
    std::fs::write(&garbage, b"not a geopackage").unwrap();
    for (name, argv, want) in [
        (
            "missing source",
            vec![
                "run",
                "pipelines/demo.yaml",
                "-i",
                "/no/such/file.gpkg",
                "-o",
                o,
            ],
            fails(1, "cannot open input"),
        ),
        (
            "unreadable source",
            vec![
                "run",
                "pipelines/demo.yaml",
                "-i",
                garbage.to_str().unwrap(),
                "-o",
                o,
            ],
            fails(1, "cannot open input"),
        ),
        (
            "missing layer",
            vec![
                "run",
                "pipelines/demo.yaml",
                "--set",
                "input.layer=nope",
                "-o",
                o,
            ],
            fails(1, "not found"),
        ),
        (
            "bad where",
            vec![
                "run",
                "pipelines/demo.yaml",
                "--set",
                "input.where=kind = = 1",
                "-o",
                o,
            ],
            fails(1, "invalid `input.where`"),
        ),
        (
            "bbox NaN",
            vec![
                "run",
                "pipelines/demo.yaml",
                "--set",
                "input.bbox=[.nan, 0, 1, 1]",
                "-o",
                o,
            ],
            fails(78, "finite"),
        ),
        (
            "zero threads",
            vec!["run", "pipelines/demo.yaml", "--threads", "0", "-o", o],
            fails(2, "between 1 and"),
        ),
        (
            "too many threads",
            vec!["run", "pipelines/demo.yaml", "--threads", "257", "-o", o],
            fails(2, "between 1 and 256"),
        ),
    ] {
        check(name, &argv, &out, want);
        assert!(!out.exists(), "{name}: an output was written");
    }
}

#[test]
fn broken_pipeline_files_exit_78_with_the_place() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    for (name, text, message) in [
        ("invalid YAML", "input: [unclosed\n", "invalid YAML"),
        ("unknown key", "input: {source: x.gpkg}\nsteps:\n  - skeleton: {methods: [MA]}\n  - prune: {ratoi: 2}\noutput: {path: o.gpkg}\n", "unknown field `ratoi`"),
        ("wrong type", "input: {source: x.gpkg}\nsteps:\n  - skeleton: {methods: MA}\noutput: {path: o.gpkg}\n", "steps[0].skeleton"),
        ("steps out of order", "input: {source: x.gpkg}\nsteps:\n  - prune: {}\n  - skeleton: {}\noutput: {path: o.gpkg}\n", "must come before"),
        ("unknown method", "input: {source: x.gpkg}\nsteps:\n  - skeleton: {methods: [XYZ]}\noutput: {path: o.gpkg}\n", "unknown method `XYZ`"),
        ("empty file", "", "empty"),
    ] {
        let p = pipeline(d.path(), "p.yaml", text);
        check(name, &["run", p.to_str().unwrap(), "-o", out.to_str().unwrap()], &out, fails(78, message));
    }
}

/// `prune.fallback` is what `mode: network` gives a polygon no line meets:
/// in any other mode it does nothing, and `validate` and `run` refuse it
/// (exit 78, naming the key) rather than accept it silently; with
/// `mode: network` it is taken. `mode: network` without `input.connect` is
/// refused with the message the Python package and QGIS give too.
#[test]
fn a_prune_fallback_outside_network_mode_is_an_invalid_pipeline() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let train = root(TRAIN);
    for (mode, fallback) in [
        ("significance", "trunk"),
        ("trunk", "drop"),
        ("length", "trunk"),
    ] {
        let text = basic_pipeline(
            &train,
            "lakes_scotland",
            &out,
            &format!("  - prune: {{ mode: {mode}, fallback: {fallback} }}\n"),
        );
        let p = pipeline(d.path(), "p.yaml", &text);
        for command in ["validate", "run"] {
            let (code, err) = code_and_err(&skeletonise(&[command, p.to_str().unwrap()]));
            assert_eq!(code, 78, "{command} {mode}/{fallback}: {err}");
            assert!(
                err.contains("`steps[1].prune.fallback`")
                    && err.contains(skeletonise::graph::prune::FALLBACK_OUTSIDE_NETWORK),
                "{command} {mode}/{fallback}: {err}"
            );
        }
        assert!(!out.exists(), "{mode}/{fallback}: nothing written");
    }
    // Without `fallback`, and with it under `mode: network` (and its lines), the file is valid.
    let plain = basic_pipeline(
        &train,
        "lakes_scotland",
        &out,
        "  - prune: { mode: trunk }\n",
    );
    let p = pipeline(d.path(), "plain.yaml", &plain);
    let (code, err) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    let network = plain.replace(
        "  layer: lakes_scotland\n",
        &format!(
            "  layer: lakes_scotland\n  connect: {{ source: {}, layer: lines_lakes_scotland }}\n",
            root("tests/data/network-train.gpkg")
        ),
    );
    for fallback in ["significance", "trunk", "drop"] {
        let text = network.replace(
            "mode: trunk }",
            &format!("mode: network, fallback: {fallback} }}"),
        );
        let p = pipeline(d.path(), "network.yaml", &text);
        let (code, err) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
        assert_eq!(code, 0, "network/{fallback}: {err}");
    }
    let without_lines = plain.replace("mode: trunk }", "mode: network }");
    let p = pipeline(d.path(), "lines.yaml", &without_lines);
    let (code, err) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
    assert_eq!(code, 78, "{err}");
    assert!(
        err.contains("`steps[1].prune.mode`")
            && err.contains(skeletonise::graph::prune::NETWORK_NEEDS_CONNECT),
        "{err}"
    );
}

#[test]
fn outputs_that_must_not_be_written() {
    let d = tmp();
    let existing = d.path().join("exists.gpkg");
    std::fs::write(&existing, b"keep me").unwrap();
    let input = d.path().join("in.gpkg");
    std::fs::copy(root(DEMO), &input).unwrap();
    for (name, out, extra, message) in [
        (
            "existing without overwrite",
            existing.to_str().unwrap(),
            "output.overwrite=false",
            "already exists",
        ),
        (
            "missing directory",
            "/no/such/dir/o.gpkg",
            "output.overwrite=true",
            "does not exist",
        ),
        (
            "the input itself",
            input.to_str().unwrap(),
            "output.overwrite=true",
            "it is the input",
        ),
        (
            "a device",
            "/dev/null",
            "output.overwrite=true",
            "GeoPackage",
        ),
        ("another format", "o.shp", "output.overwrite=true", ".gpkg"),
    ] {
        let argv = [
            "run",
            "pipelines/demo.yaml",
            "-i",
            input.to_str().unwrap(),
            "-o",
            out,
            "--set",
            extra,
        ];
        check(name, &argv, Path::new(out), fails(1, message));
    }
    assert_eq!(std::fs::read(&existing).unwrap(), b"keep me");
}

// Reliability round 3: every path the tool writes goes through one guard.

/// A finished demo run in `dir` (its GeoPackage and a copy of its input),
/// with candidates so that a report has something to show.
fn demo_output(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let input = dir.join("src.gpkg");
    std::fs::copy(root(DEMO), &input).unwrap();
    let out = dir.join("x.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.report=null",
        "-q",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    (input, out)
}

/// Runs `args` and checks that it fails with exit 1 and `message`, and that
/// every file in `kept` still has the bytes it had.
fn refused(name: &str, args: &[&str], message: &str, kept: &[&Path]) {
    refused_with(1, name, args, message, kept);
}

/// [`refused`] with the exit code `want`.
fn refused_with(want: i32, name: &str, args: &[&str], message: &str, kept: &[&Path]) {
    let before: Vec<Vec<u8>> = kept.iter().map(|p| std::fs::read(p).unwrap()).collect();
    let o = skeletonise(args);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, want, "{name}: {err}");
    assert!(err.contains(message), "{name}: `{message}` not in {err}");
    for (p, b) in kept.iter().zip(&before) {
        assert_eq!(
            &std::fs::read(p).unwrap(),
            b,
            "{name}: {} changed",
            p.display()
        );
    }
}

#[test]
fn the_report_never_replaces_the_output_or_a_source() {
    let d = tmp();
    let (input, out) = demo_output(d.path());
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    refused(
        "report over its own GeoPackage",
        &["report", o, "-o", o],
        "give a path ending in `.html`",
        &[&out],
    );
    refused(
        "report over the polygons source",
        &["report", o, "--polygons", i, "-o", i],
        "give a path ending in `.html`",
        &[&out, &input],
    );
    // The same files under an .html name (hard links): refused as files, not
    // by their names.
    let gpkg_link = d.path().join("x-link.html");
    std::fs::hard_link(&out, &gpkg_link).unwrap();
    refused(
        "report over a link to its GeoPackage",
        &[
            "report",
            o,
            "-o",
            gpkg_link.to_str().unwrap(),
            "--overwrite",
        ],
        "it is the GeoPackage reported on",
        &[&out],
    );
    let src_link = d.path().join("src-link.html");
    std::fs::hard_link(&input, &src_link).unwrap();
    refused(
        "report over a link to the polygons",
        &[
            "report",
            o,
            "--polygons",
            i,
            "-o",
            src_link.to_str().unwrap(),
            "--overwrite",
        ],
        "it is the polygons source",
        &[&input],
    );
    refused(
        "report over a link to the run's recorded input",
        &["report", o, "-o", src_link.to_str().unwrap(), "--overwrite"],
        "it is the run's input",
        &[&input],
    );
}

#[test]
fn the_report_path_of_a_run_is_checked_before_any_work_by_run_and_validate() {
    let d = tmp();
    let input = d.path().join("src.gpkg");
    std::fs::copy(root(DEMO), &input).unwrap();
    let link = d.path().join("in.html");
    std::fs::hard_link(&input, &link).unwrap();
    let out = d.path().join("o.gpkg");
    for (name, report, code, message) in [
        ("the input", input.to_str().unwrap(), 1, "`.html`"),
        (
            "a link to the input",
            link.to_str().unwrap(),
            1,
            "it is the input",
        ),
        (
            "the output",
            out.to_str().unwrap(),
            78,
            "would overwrite the GeoPackage",
        ),
    ] {
        let set = format!("output.report.path={report}");
        for cmd in ["run", "validate"] {
            refused_with(
                code,
                &format!("{cmd}: report over {name}"),
                &[
                    cmd,
                    "pipelines/demo.yaml",
                    "-i",
                    input.to_str().unwrap(),
                    "-o",
                    out.to_str().unwrap(),
                    "--set",
                    &set,
                ],
                message,
                &[&input],
            );
            assert!(!out.exists(), "{cmd} {name}: the run went on");
        }
    }
}

#[test]
fn a_report_never_replaces_a_device_a_fifo_or_an_existing_file_without_overwrite() {
    let d = tmp();
    let (_, out) = demo_output(d.path());
    let o = out.to_str().unwrap();
    refused(
        "report to /dev/null",
        &["report", o, "-o", "/dev/null", "--overwrite"],
        "",
        &[],
    );
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    let null_link = d.path().join("null.html");
    std::os::unix::fs::symlink("/dev/null", &null_link).unwrap();
    refused(
        "report to a link to /dev/null",
        &[
            "report",
            o,
            "-o",
            null_link.to_str().unwrap(),
            "--overwrite",
        ],
        "not a regular file",
        &[],
    );
    let fifo = d.path().join("fifo.html");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    refused(
        "report to a FIFO",
        &["report", o, "-o", fifo.to_str().unwrap(), "--overwrite"],
        "not a regular file",
        &[],
    );
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let html = d.path().join("r.html");
    std::fs::write(&html, b"my notes").unwrap();
    refused(
        "report over an existing file",
        &["report", o, "-o", html.to_str().unwrap()],
        "already exists",
        &[&html],
    );
    let ok = skeletonise(&[
        "report",
        o,
        "-o",
        html.to_str().unwrap(),
        "--overwrite",
        "-q",
    ]);
    assert_eq!(code_and_err(&ok).0, 0, "{}", code_and_err(&ok).1);
    assert!(std::fs::read_to_string(&html)
        .unwrap()
        .starts_with("<!DOCTYPE html>"));
    // A run's report follows `output.overwrite`.
    let input = d.path().join("src.gpkg");
    refused(
        "run over an existing report",
        &[
            "run",
            "pipelines/demo.yaml",
            "-i",
            input.to_str().unwrap(),
            "-o",
            d.path().join("new.gpkg").to_str().unwrap(),
            "--set",
            "output.overwrite=false",
            "--set",
            &format!("output.report.path={}", html.display()),
        ],
        "already exists",
        &[&html],
    );
    let leftovers: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.contains(".tmp."))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// Runs the binary with the size of any file it writes limited to `bytes`
/// (RLIMIT_FSIZE, with SIGXFSZ ignored so that the write fails with EFBIG
/// as on a full disk).
fn skeletonise_with_file_limit(args: &[&str], bytes: u64) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_skeletonise"));
    cmd.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    unsafe {
        cmd.pre_exec(move || {
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            let lim = libc::rlimit {
                rlim_cur: bytes,
                rlim_max: bytes,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    cmd.output().expect("the binary runs")
}

#[test]
fn a_run_that_fails_on_a_full_disk_leaves_no_temporary_file() {
    let d = tmp();
    let out = d.path().join("dated-2026-12-04.gpkg");
    let mut failed = 0;
    // From a file too small for the empty layers to one that fails only at
    // the last commit (few rows: the final commit is the first) or in a
    // batch (many rows): every way of failing cleans up.
    let few = ["output.widths=false", "output.candidates=false"];
    let many = ["output.bars=true", "output.widths=true"];
    for (rows, kbs) in [
        (few, &[100u64, 130, 160, 190][..]),
        (many, &[96, 256, 512, 1024][..]),
    ] {
        for &kb in kbs {
            let args = [
                "run",
                "pipelines/demo.yaml",
                "-o",
                out.to_str().unwrap(),
                "--set",
                "output.overwrite=true",
                "--set",
                "output.report=null",
                "--set",
                rows[0],
                "--set",
                rows[1],
                "-q",
            ];
            let before = std::fs::read(&out).ok();
            let o = skeletonise_with_file_limit(&args, kb * 1024);
            let (code, err) = code_and_err(&o);
            let left: Vec<String> = std::fs::read_dir(d.path())
                .unwrap()
                .flatten()
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| n.contains(".tmp."))
                .collect();
            assert!(
                left.is_empty(),
                "{kb} KB, {rows:?} (exit {code}): left {left:?}\n{err}"
            );
            if code != 0 {
                assert_eq!(code, 1, "{kb} KB: {err}");
                assert!(
                    err.contains("the disk is probably full"),
                    "{kb} KB: the message says what to do: {err}"
                );
                assert_eq!(
                    std::fs::read(&out).ok(),
                    before,
                    "{kb} KB: a failed run changed the output"
                );
                failed += 1;
            }
        }
    }
    assert!(failed >= 6, "the limits must make runs fail: {failed}");
}

/// Runs the binary with the environment variables `env` set.
fn skeletonise_env(args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_skeletonise"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

#[test]
fn a_variable_that_is_set_but_empty_is_an_error_naming_it_for_every_key() {
    let d = tmp();
    let src = d.path().join("in.gpkg");
    make_layer(&src, "first", 3035, &[Some(SQUARE)]);
    make_layer(&src, "3", 3035, &[Some(SQUARE), Some(SQUARE)]);
    let out = d.path().join("o.gpkg");
    let body = |input: &str| {
        format!(
            "input:\n  source: {}\n{input}steps:\n  - skeleton: {{ methods: [MA] }}\noutput:\n  path: {}\n  overwrite: true\n",
            src.display(),
            out.display()
        )
    };
    for (name, input, var) in [
        ("layer", "  layer: \"${LAYER}\"\n", "LAYER"),
        (
            "connect.layer",
            "  connect: { source: \"SRC\", layer: \"${NET}\" }\n",
            "NET",
        ),
        (
            "merge_by",
            "  merge_adjacent: true\n  merge_by: \"${RIVER_ID}\"\n",
            "RIVER_ID",
        ),
    ] {
        let text = body(&input.replace("SRC", src.to_str().unwrap()));
        let p = pipeline(d.path(), "env.yaml", &text);
        for cmd in ["validate", "run"] {
            let o = skeletonise_env(&[cmd, p.to_str().unwrap()], &[(var, "")]);
            let (code, err) = code_and_err(&o);
            assert_eq!(code, 78, "{cmd} {name}: {err}");
            assert!(
                err.contains(&format!("`{var}` is set but empty")),
                "{cmd} {name}: {err}"
            );
            assert!(!out.exists(), "{cmd} {name}: something was written");
        }
    }
    // `:-` gives the default for an empty variable too, as in the shell.
    let p = pipeline(
        d.path(),
        "default.yaml",
        &body("  layer: \"${LAYER:-first}\"\n"),
    );
    let o = skeletonise_env(&["run", p.to_str().unwrap(), "-q"], &[("LAYER", "")]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    assert_eq!(
        ints(&open(&out), "skeletonise_runs", "features_read"),
        [Some(1)]
    );
    // A substituted layer stays a name: `3` is the layer called "3", not the
    // fourth layer; a numeric key still gets its number.
    let text = body("  layer: \"${LAYER}\"\n").replace(
        "  - skeleton: { methods: [MA] }\n",
        "  - skeleton: { methods: [MA] }\n  - prune: { ratio: \"${RATIO}\" }\n",
    );
    let p = pipeline(d.path(), "typed.yaml", &text);
    let o = skeletonise_env(
        &["run", p.to_str().unwrap(), "-q"],
        &[("LAYER", "3"), ("RATIO", "2")],
    );
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let ds = open(&out);
    assert_eq!(ints(&ds, "skeletonise_runs", "features_read"), [Some(2)]);
    let recorded = strings(&ds, "skeletonise_runs", "input_layer");
    assert_eq!(recorded, [Some("3".to_string())]);
}

/// Lines across the Danube reach (UTM 34N, the training layer's CRS).
fn danube_network(dir: &Path) -> std::path::PathBuf {
    let net = dir.join("net.gpkg");
    let lines: Vec<String> = [5_855_000, 5_857_000, 5_859_000, 5_861_000, 5_863_000]
        .iter()
        .map(|y| format!("LINESTRING(-627000 {y},-612000 {y})"))
        .collect();
    let wkts: Vec<Option<&str>> = lines.iter().map(|l| Some(l.as_str())).collect();
    make_layer(&net, "lines", 32634, &wkts);
    net
}

/// Runs the Danube with `connect` (a flow mapping's inside) and returns the
/// exit code, stderr and the number of connection rows.
fn danube_connected(dir: &Path, connect: &str) -> (i32, String, u64) {
    let out = dir.join("c.gpkg");
    let text = format!(
        "input:\n  source: {}\n  layer: river_danube\n  connect: {{ {connect} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - prune: {{}}\n  - extend: {{}}\noutput:\n  path: {}\n  overwrite: true\n",
        root(TRAIN),
        out.display()
    );
    let p = pipeline(dir, "connect.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap()]);
    let (code, err) = code_and_err(&o);
    let n = if code == 0 {
        count(&open(&out), "connections")
    } else {
        0
    };
    let _ = std::fs::remove_file(&out);
    (code, err, n)
}

#[test]
fn a_connect_layer_in_another_crs_is_reprojected_and_one_without_lines_is_an_error() {
    let d = tmp();
    let net = danube_network(d.path());
    let (code, err, same) = danube_connected(
        d.path(),
        &format!("source: {}, layer: lines", net.display()),
    );
    assert_eq!(code, 0, "{err}");
    assert!(same >= 10, "the lines cross the river: {same}");
    assert!(
        err.contains(&format!(
            "connect: {same} connections made, 5 of the network's 5 lines used"
        )),
        "{err}"
    );
    // The same lines in ETRS89-LAEA.
    let laea = d.path().join("laea.gpkg");
    let o = std::process::Command::new("ogr2ogr")
        .args(["-t_srs", "EPSG:3035", "-nln", "lines"])
        .arg(&laea)
        .arg(&net)
        .arg("lines")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (code, err, other) = danube_connected(
        d.path(),
        &format!("source: {}, layer: lines", laea.display()),
    );
    assert_eq!((code, other), (0, same), "{err}");
    // A layer of points, and an empty layer.
    make_layer(&net, "points", 32634, &[Some("POINT(-620000 5858000)")]);
    make_layer(&net, "empty", 32634, &[]);
    for layer in ["points", "empty"] {
        let c = format!("source: {}, layer: {layer}", net.display());
        let (code, err, _) = danube_connected(d.path(), &c);
        assert_eq!(code, 1, "{layer}: {err}");
        assert!(err.contains("has no lines"), "{layer}: {err}");
        assert!(err.contains("input.connect"), "{layer}: {err}");
    }
}

#[test]
fn every_crossing_gets_its_leg_whatever_the_snap() {
    let d = tmp();
    let net = danube_network(d.path());
    let c = |snap: &str| format!("source: {}, layer: lines, snap: {snap}", net.display());
    let (_, err, exact) = danube_connected(d.path(), &c("0"));
    for snap in ["300", "1000", "100000"] {
        let (code, err, n) = danube_connected(d.path(), &c(snap));
        assert_eq!(code, 0, "{err}");
        assert_eq!(n, exact, "snap {snap}: crossings dropped or added\n{err}");
    }
    assert!(exact >= 10, "{err}");
}

#[test]
fn a_report_filter_that_fails_only_when_it_runs_is_an_error() {
    let d = tmp();
    let (_, out) = demo_output(d.path());
    let html = d.path().join("r.html");
    for w in [
        "abs(-9223372036854775808) > 0",
        "json_extract(method, '$.a') = 1",
    ] {
        refused(
            w,
            &[
                "report",
                out.to_str().unwrap(),
                "-o",
                html.to_str().unwrap(),
                "--where",
                w,
            ],
            "invalid filter",
            &[&out],
        );
        assert!(!html.exists(), "{w}: a report was written");
        // The same filter in a pipeline's report: the run says so.
        let o = skeletonise(&[
            "run",
            "pipelines/demo.yaml",
            "-o",
            d.path().join("run.gpkg").to_str().unwrap(),
            "--set",
            "output.overwrite=true",
            "--set",
            &format!(
                "output.report={{path: {}, features: {{where: \"{w}\"}}}}",
                html.display()
            ),
            "-q",
        ]);
        let (code, err) = code_and_err(&o);
        assert_eq!(code, 1, "{w}: {err}");
        assert!(err.contains("invalid filter"), "{w}: {err}");
        let i = skeletonise(&[
            "run",
            "pipelines/demo.yaml",
            "-o",
            d.path().join("where.gpkg").to_str().unwrap(),
            "--set",
            &format!("input.where={w}"),
            "-q",
        ]);
        let (code, err) = code_and_err(&i);
        assert_eq!(code, 1, "input.where {w}: {err}");
        assert!(err.contains("invalid `input.where`"), "{w}: {err}");
    }
}

#[test]
fn a_timeout_too_large_for_a_deadline_is_an_invalid_pipeline() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    for t in ["1.8e19", "1e300", "-1", ".inf"] {
        for cmd in ["validate", "run"] {
            let o = skeletonise(&[
                cmd,
                "pipelines/demo.yaml",
                "-o",
                out.to_str().unwrap(),
                "--set",
                &format!("steps.skeleton.timeout_s={t}"),
            ]);
            let (code, err) = code_and_err(&o);
            assert_eq!(code, 78, "{cmd} {t}: {err}");
            assert!(
                err.contains("timeout_s is a number of seconds between 0 and"),
                "{err}"
            );
            assert!(!out.exists());
        }
    }
    // The largest allowed is no limit in practice: every feature written.
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "steps.skeleton.timeout_s=1e9",
        "--set",
        "output.report=null",
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    assert_eq!(count(&open(&out), "rejected"), 0);
}

/// Runs `score` of the square layer `bad` in `src` against the lines `wkts`
/// (with `id` the row number, `key` joined to the polygon FID as given).
fn score_case(
    dir: &Path,
    lines: &[(Option<&str>, Option<&str>)],
    extra: &[&str],
) -> (i32, String, std::path::PathBuf) {
    let src = dir.join("polys.gpkg");
    if !src.exists() {
        make_layer(
            &src,
            "bad",
            3035,
            &[
                Some(SQUARE),
                Some("POLYGON((200 0,300 0,300 10,200 10,200 0))"),
            ],
        );
    }
    let sk = dir.join("lines.gpkg");
    let _ = std::fs::remove_file(&sk);
    let wkts: Vec<Option<&str>> = lines.iter().map(|l| l.0).collect();
    make_layer(&sk, "l", 3035, &wkts);
    // A text key column: the polygon FID, or NULL.
    let ds = gdal::Dataset::open_ex(
        &sk,
        gdal::DatasetOptions {
            open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE | gdal::GdalOpenFlags::GDAL_OF_VECTOR,
            ..Default::default()
        },
    )
    .unwrap();
    ds.execute_sql(
        "ALTER TABLE l ADD COLUMN pkey TEXT",
        None,
        gdal::vector::sql::Dialect::SQLITE,
    )
    .unwrap();
    for (i, (_, k)) in lines.iter().enumerate() {
        let v = k.map_or("NULL".to_string(), |k| format!("'{k}'"));
        ds.execute_sql(
            format!("UPDATE l SET pkey = {v} WHERE id = {i}"),
            None,
            gdal::vector::sql::Dialect::SQLITE,
        )
        .unwrap();
    }
    drop(ds);
    let out = dir.join("scored.gpkg");
    let mut argv = vec![
        "score",
        "--polygons",
        src.to_str().unwrap(),
        "--skeletons",
        sk.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--overwrite",
    ];
    argv.extend_from_slice(extra);
    let o = skeletonise(&argv);
    let (code, err) = code_and_err(&o);
    (code, err, out)
}

#[test]
fn score_explains_lines_outside_and_counts_what_it_leaves_out() {
    let d = tmp();
    let key = ["--skeleton-key", "pkey"];
    // The square's skeleton drawn 1 km away: not "too thin to score".
    let (code, err, out) = score_case(
        d.path(),
        &[
            (Some("LINESTRING(1000 50,1100 50)"), Some("1")),
            (Some("LINESTRING(200 5,300 5)"), Some("2")),
        ],
        &key,
    );
    assert_eq!(code, 0, "{err}");
    let reasons = strings(&open(&out), "rejected", "reason");
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    let r = reasons[0].clone().unwrap();
    assert!(
        r.contains("lies outside its polygon") && !r.contains("too thin"),
        "{r}"
    );
    // Partly outside: scored, with a note saying so.
    let (code, err, out) = score_case(
        d.path(),
        &[
            (Some("LINESTRING(0 50,150 50)"), Some("1")),
            (Some("LINESTRING(200 5,300 5)"), Some("2")),
        ],
        &key,
    );
    assert_eq!(code, 0, "{err}");
    let notes = strings(&open(&out), "skeletons", "note");
    assert!(
        notes[0]
            .as_deref()
            .unwrap_or("")
            .contains("33.33 % of the skeleton's length"),
        "{notes:?}"
    );
    assert_eq!(notes[1], None);
    // Unknown keys, NULL keys and non-line rows are counted in a warning.
    let (code, err, _) = score_case(
        d.path(),
        &[
            (Some("LINESTRING(0 50,100 50)"), Some("1")),
            (Some("LINESTRING(0 50,100 50)"), Some("77")),
            (Some("LINESTRING(0 50,100 50)"), None),
            (Some("POINT(5 5)"), Some("2")),
            (Some("POLYGON((0 0,1 0,1 1,0 0))"), Some("2")),
        ],
        &key,
    );
    assert_eq!(code, 0, "{err}");
    for part in [
        "1 with a NULL key",
        "1 with a key no polygon has (e.g. `77`)",
        "2 without a line geometry",
    ] {
        assert!(err.contains(part), "`{part}` not in {err}");
    }
    // Nothing joins: an error, not an empty success; the output of the run
    // before stays.
    let before = std::fs::read(d.path().join("scored.gpkg")).unwrap();
    let (code, err, out) = score_case(
        d.path(),
        &[
            (Some("LINESTRING(0 50,100 50)"), Some("x1")),
            (Some("LINESTRING(0 50,100 50)"), Some("x2")),
        ],
        &key,
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("no skeleton line could be joined"), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), before);
}

#[test]
fn score_of_geographic_layers_names_its_own_option() {
    let d = tmp();
    let polys = d.path().join("geo.gpkg");
    make_layer(&polys, "p", 4326, &[Some("POLYGON((0 0,1 0,1 1,0 1,0 0))")]);
    make_layer(&polys, "l", 4326, &[Some("LINESTRING(0 0.5,1 0.5)")]);
    let o = skeletonise(&[
        "score",
        "--polygons",
        polys.to_str().unwrap(),
        "--polygons-layer",
        "p",
        "--skeletons",
        polys.to_str().unwrap(),
        "--skeletons-layer",
        "l",
        "-o",
        d.path().join("o.gpkg").to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--reproject EPSG:<code>"), "{err}");
    assert!(!err.contains("input.reproject"), "{err}");
}

const SQUARE_AND_SLIVER: &str =
    "MULTIPOLYGON(((0 0,100 0,100 100,0 100,0 0)),((200 0,1000200 0,1000200 0.001,200 0.001,200 0)))";
const MA_ONLY: [&str; 2] = ["--set", "steps.skeleton.methods=[MA]"];

// MA has no skeleton of the sliver part: alone the feature is rejected
// with that part's reason, never written without the part.
geometry_case!(
    a_part_no_method_can_skeletonise_rejects_the_feature_with_the_reason,
    [Some(SQUARE_AND_SLIVER)],
    MA_ONLY,
    ok(1, 0, 1),
    "part 1: MA gives no skeleton of this polygon part"
);

/// A river from a water mask (`gdal_polygonize -8`, repaired): a reach
/// 3 km by 300 m traced along 30 m pixels, and a one-pixel piece touching
/// its end at a corner.
fn river_and_pixel() -> String {
    let bottom = (0..=100).map(|i| format!("{} 0", 30 * i));
    let top = (0..=100).rev().map(|i| format!("{} 300", 30 * i));
    let ring: Vec<String> = bottom.chain(top).chain(["0 0".to_string()]).collect();
    format!(
        "MULTIPOLYGON((({})),((3000 300,3030 300,3030 330,3000 330,3000 300)))",
        ring.join(",")
    )
}

// VD has no skeleton of the pixel, so with VD alone the feature is
// rejected; the reason gives the piece's area and the fixes, and the
// `min_area` it suggests lets the river through.
#[test]
fn a_pixel_vd_cannot_skeletonise_is_named_with_its_area_and_the_fixes() {
    let wkt = river_and_pixel();
    let vd = ["--set", "steps.skeleton.methods=[VD]"];
    let (_d, out) = case("pixel", 3035, &[Some(&wkt)], &vd, ok(1, 0, 1));
    assert_eq!(
        rejected_reason(&out),
        "VD: part 1: VD gives no skeleton of this polygon part (too thin or too small for the method): it has 900 CRS units² of the feature's 900900; skip parts that small with `prepare: { min_area: 909 }`, or list another method in `skeleton.methods` (e.g. MA)"
    );
    let skip = [vd[0], vd[1], "--set", "steps.prepare.min_area=909"];
    case("pixel skipped", 3035, &[Some(&wkt)], &skip, ok(1, 1, 0));
}

#[test]
fn the_method_chosen_for_a_multipolygon_has_a_skeleton_of_every_part() {
    let (_d, out) = case(
        "all methods",
        3035,
        &[Some(SQUARE_AND_SLIVER)],
        &["--set", "output.report=null"],
        ok(1, 1, 0),
    );
    let ds = open(&out);
    assert_eq!(ints(&ds, "skeletons", "components"), [Some(2)]);
    let errors = strings(&ds, "candidates", "error");
    let methods = strings(&ds, "candidates", "method");
    let ma = methods
        .iter()
        .position(|m| m.as_deref() == Some("MA"))
        .unwrap();
    assert!(
        errors[ma].as_deref().unwrap_or("").contains("part 1"),
        "{errors:?}"
    );
}

// With `explode`, a part that cannot be processed rejects the feature once
// (counted once, its other parts not written).
geometry_case!(
    explode_with_a_bad_part_rejects_the_feature_once,
    [Some(SQUARE_AND_SLIVER), Some(SQUARE)],
    [
        "--set",
        "steps.skeleton.methods=[MA]",
        "--set",
        "output.explode=true",
        "--set",
        "output.report=null"
    ],
    ok(2, 1, 1),
    "part 1: "
);

#[test]
fn a_skeleton_layer_named_like_one_of_the_tools_layers_is_an_invalid_pipeline() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    for name in [
        "rejected",
        "Candidates",
        "skeletonise_runs",
        "gpkg_contents",
        "",
    ] {
        for cmd in ["validate", "run"] {
            let o = skeletonise(&[
                cmd,
                "pipelines/demo.yaml",
                "-o",
                out.to_str().unwrap(),
                "--set",
                &format!("output.layer=\"{name}\""),
            ]);
            let (code, err) = code_and_err(&o);
            assert_eq!(code, 78, "{cmd} `{name}`: {err}");
            assert!(err.contains("output.layer"), "{err}");
            assert!(!out.exists(), "{cmd} `{name}`: processed");
        }
    }
}

#[test]
fn a_report_of_unknown_fids_is_an_error_and_repeated_fids_show_once() {
    let d = tmp();
    let (_, out) = demo_output(d.path());
    let html = d.path().join("r.html");
    let (o, h) = (out.to_str().unwrap(), html.to_str().unwrap());
    refused(
        "unknown FIDs",
        &["report", o, "-o", h, "--fid", "999,1000"],
        "none of the source FIDs 999, 1000",
        &[],
    );
    assert!(!html.exists());
    let ok = skeletonise(&["report", o, "-o", h, "--fid", "1,1,1,999", "-q"]);
    assert_eq!(code_and_err(&ok).0, 0, "{}", code_and_err(&ok).1);
    let page = std::fs::read_to_string(&html).unwrap();
    let ids: Vec<&str> = page
        .split(" id=\"")
        .skip(1)
        .map(|t| &t[..t.find('"').unwrap()])
        .collect();
    let mut unique = ids.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(ids.len(), unique.len(), "duplicate ids: {ids:?}");
    assert!(page.contains("Source FID 999 is not in the file."));
}

#[test]
fn a_tiny_collapse_width_runs_like_any_other() {
    // 1e-7 m on the demo's lakes, islands and river: nothing but tips is
    // that narrow; the samples stay at 1e-4 of each polygon's extent (the
    // library's test counts them), so every feature is written.
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "steps.skeleton.methods=[MA]",
        "--set",
        "steps.collapse={width: 1e-7}",
        "--set",
        "output.report=null",
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let ds = open(&out);
    assert_eq!(count(&ds, "rejected"), 0);
    assert_eq!(
        ints(&ds, "skeletonise_runs", "features_written"),
        [Some(17)]
    );
}

/// The bounding box of an SVG path of `M x y` and relative `l dx dy …`
/// steps (as the report draws polygons).
fn path_extent(d: &str) -> (f64, f64) {
    let mut nums = Vec::new();
    let (mut x, mut y) = (0.0, 0.0);
    let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
    let mut mode = 'M';
    let mut flush = |mode: char, nums: &mut Vec<f64>, x: &mut f64, y: &mut f64| {
        for p in nums.chunks(2).filter(|p| p.len() == 2) {
            if mode == 'M' {
                (*x, *y) = (p[0], p[1]);
            } else {
                (*x, *y) = (*x + p[0], *y + p[1]);
            }
            lo = (lo.0.min(*x), lo.1.min(*y));
            hi = (hi.0.max(*x), hi.1.max(*y));
        }
        nums.clear();
    };
    for tok in d.split(|c: char| c.is_whitespace()).flat_map(|t| {
        let mut parts = Vec::new();
        let mut cur = String::new();
        for c in t.chars() {
            if c.is_ascii_alphabetic() {
                if !cur.is_empty() {
                    parts.push(std::mem::take(&mut cur));
                }
                parts.push(c.to_string());
            } else {
                cur.push(c);
            }
        }
        if !cur.is_empty() {
            parts.push(cur);
        }
        parts
    }) {
        match tok.as_str() {
            "M" | "l" | "z" => {
                flush(mode, &mut nums, &mut x, &mut y);
                mode = tok.chars().next().unwrap();
            }
            n => nums.push(n.parse().unwrap()),
        }
    }
    flush(mode, &mut nums, &mut x, &mut y);
    (hi.0 - lo.0, hi.1 - lo.1)
}

/// Three reaches of a 3000 × 100 channel (layer `reaches`, EPSG:3035).
fn three_reaches(dir: &Path) -> std::path::PathBuf {
    let src = dir.join("reaches.gpkg");
    make_layer(
        &src,
        "reaches",
        3035,
        &[
            Some("POLYGON((0 0,1000 0,1000 100,0 100,0 0))"),
            Some("POLYGON((1000 0,2000 0,2000 100,1000 100,1000 0))"),
            Some("POLYGON((2000 0,3000 0,3000 100,2000 100,2000 0))"),
        ],
    );
    src
}

#[test]
fn the_report_of_a_merged_feature_draws_and_scores_all_its_members() {
    // The three reaches, merged into one feature.
    let d = tmp();
    let src = three_reaches(d.path());
    let out = d.path().join("o.gpkg");
    let html = d.path().join("o.html");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=reaches",
        "--set",
        "input.merge_adjacent=true",
        "-o",
        out.to_str().unwrap(),
        "--set",
        &format!("output.report.path={}", html.display()),
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(!page.contains("lie outside this polygon"), "a false alarm");
    let d_attr = page
        .split("<path class=\"poly\" d=\"")
        .nth(1)
        .and_then(|t| t.split('"').next())
        .expect("the polygon is drawn");
    let (w, h) = path_extent(d_attr);
    assert!(
        (w / h - 30.0).abs() < 1.0,
        "the whole 3000 × 100 channel: {w} × {h}"
    );
}

#[test]
fn null_merge_by_values_are_kept_apart() {
    let d = tmp();
    let src = three_reaches(d.path());
    // `river` NULL for all three: as in SQL, NULL equals nothing.
    let ds = gdal::Dataset::open_ex(
        &src,
        gdal::DatasetOptions {
            open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE | gdal::GdalOpenFlags::GDAL_OF_VECTOR,
            ..Default::default()
        },
    )
    .unwrap();
    ds.execute_sql(
        "ALTER TABLE reaches ADD COLUMN river TEXT",
        None,
        gdal::vector::sql::Dialect::SQLITE,
    )
    .unwrap();
    drop(ds);
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=reaches",
        "--set",
        "input.merge_adjacent=true",
        "--set",
        "input.merge_by=river",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.report=null",
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let members = strings(&open(&out), "skeletons", "members");
    assert_eq!(
        members,
        [Some("1".into()), Some("2".into()), Some("3".into())]
    );
}

#[test]
fn deeply_nested_brackets_are_refused_before_the_yaml_parser_sees_them() {
    // 200 KB of `[` after a key: the YAML scanner took 18 s (quadratic)
    // before its recursion limit; the check before it answers at once, with
    // the place (its own message proves the parser never ran).
    let d = tmp();
    let text = format!("input: {}", "[".repeat(200_000));
    let p = pipeline(d.path(), "deep.yaml", &text);
    for cmd in ["validate", "run"] {
        let (code, err) = code_and_err(&skeletonise(&[cmd, p.to_str().unwrap()]));
        assert_eq!(code, 78, "{err}");
        assert!(
            err.contains("deep.yaml:1:136: invalid YAML: brackets nested deeper than 128 levels"),
            "{err}"
        );
    }
}

#[test]
fn a_crs_unit_name_is_escaped_once_in_the_report() {
    // Trinidad 1903 / Trinidad Grid: its unit is "Clarke's foot".
    let d = tmp();
    let src = d.path().join("in.gpkg");
    make_layer(
        &src,
        "bad",
        2314,
        &[Some(SQUARE), Some("POLYGON((0 0,300 0,300 20,0 20,0 0))")],
    );
    let out = d.path().join("o.gpkg");
    let html = d.path().join("o.html");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=bad",
        "-o",
        out.to_str().unwrap(),
        "--set",
        &format!("output.report.path={}", html.display()),
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains("<th>s (Clarke&#39;s foot)</th>"),
        "the score table's label"
    );
    assert!(
        page.contains("mean s (Clarke&#39;s foot)"),
        "the summary's label"
    );
    assert!(!page.contains("&amp;#39;"), "escaped twice");
}

/// The error line of a refused command: its last `ERROR` line, without the
/// timestamp.
fn error_line(err: &str) -> String {
    err.lines()
        .filter_map(|l| l.split_once(" ERROR ").map(|(_, m)| m.to_string()))
        .next_back()
        .unwrap_or_default()
}

/// `validate` refuses whatever `run` refuses before it processes a feature,
/// with the same exit code and message: every refusal below is first
/// checked to be one of `run`'s (nothing written), then `validate`'s.
#[test]
fn validate_refuses_everything_run_refuses_with_the_same_code_and_message() {
    let dir = tmp();
    let d = dir.path();
    let src = d.join("in.gpkg");
    make_layer(&src, "lakes", 32633, &[Some(SQUARE)]);
    make_layer(&src, "lines", 32633, &[Some("LINESTRING(-10 50,110 50)")]);
    make_layer(&src, "empty", 32633, &[]);
    make_layer(
        &src,
        "units",
        32633,
        &[
            Some("POLYGON((-50 -50,50 -50,50 150,-50 150,-50 -50))"),
            Some("POLYGON((50 -50,150 -50,150 150,50 150,50 -50))"),
        ],
    );
    std::fs::create_dir(d.join("a-directory.gpkg")).unwrap();
    let s = src.display().to_string();
    let out = d.join("out.gpkg");
    let partition = format!(
        "  neighbours:\n    source: {s}\n    layer: units\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - partition: {{}}\n"
    );
    let network = "steps:\n  - skeleton: { methods: [MA] }\n  - prune: { mode: network }\n";
    let connect =
        |layer: &str| format!("  connect:\n    source: {s}\n    layer: {layer}\n{network}");
    let ma_alone = "steps:\n  - skeleton: { methods: [MA] }\n";
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        (
            "neighbours where selecting no unit",
            partition.replace("layer: units\n", "layer: units\n    where: id > 99\n"),
            vec![],
        ),
        (
            "an empty neighbours layer",
            partition.replace("layer: units", "layer: empty"),
            vec![],
        ),
        (
            "a neighbours layer of lines",
            partition.replace("layer: units", "layer: lines"),
            vec![],
        ),
        (
            "a missing neighbours layer",
            partition.replace("layer: units", "layer: nowhere"),
            vec![],
        ),
        ("a connect layer of polygons", connect("lakes"), vec![]),
        ("an empty connect layer", connect("empty"), vec![]),
        ("a missing connect layer", connect("nowhere"), vec![]),
        ("network pruning without lines", network.to_string(), vec![]),
        (
            "collapse without MA",
            "steps:\n  - skeleton: { methods: [CDT] }\n  - collapse: { width: 10 }\n".into(),
            vec![],
        ),
        (
            "the output layer named as a step's layer",
            "steps:\n  - skeleton: { methods: [MA] }\n  - label: {}\n".into(),
            vec!["--set", "output.layer=labels"],
        ),
        (
            "an output path ending in a separator",
            ma_alone.into(),
            vec!["-o", "dir.gpkg/"],
        ),
        (
            "an output path that is a directory",
            ma_alone.into(),
            vec!["-o", "a-directory.gpkg"],
        ),
        (
            "a missing input layer",
            ma_alone.into(),
            vec!["-l", "nowhere"],
        ),
        (
            "an input filter that fails",
            ma_alone.into(),
            vec!["--set", "input.where=nosuchfield > 1"],
        ),
    ];
    for (name, body, extra) in cases {
        let (input, steps) = match body.split_once("steps:\n") {
            Some((i, s)) => (i.to_string(), s.to_string()),
            None => (String::new(), body.clone()),
        };
        let text = format!(
            "input:\n  source: {s}\n  layer: lakes\n{input}steps:\n{steps}output:\n  path: {}\n",
            out.display()
        );
        let p = pipeline(d, "p.yaml", &text);
        let p = p.to_str().unwrap();
        let mut run = vec!["run", p];
        run.extend(&extra);
        let mut validate = vec!["validate", p];
        validate.extend(&extra);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_skeletonise"))
            .args(&run)
            .current_dir(d)
            .output()
            .unwrap();
        let (run_code, run_err) = code_and_err(&o);
        assert_ne!(run_code, 0, "{name}: run succeeded: {run_err}");
        assert!(
            !out.exists() && !d.join("dir.gpkg").exists(),
            "{name}: run wrote"
        );
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_skeletonise"))
            .args(&validate)
            .current_dir(d)
            .output()
            .unwrap();
        let (code, err) = code_and_err(&o);
        assert_eq!(code, run_code, "{name}: validate {err}\nrun {run_err}");
        assert_eq!(error_line(&err), error_line(&run_err), "{name}");
        assert!(!error_line(&err).is_empty(), "{name}: {err}");
    }
}

/// Adds text columns `names` (filled with the column's own name) to `layer`.
fn add_columns(path: &Path, layer: &str, names: &[&str]) {
    let ds = gdal::Dataset::open_ex(
        path,
        gdal::DatasetOptions {
            open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE | gdal::GdalOpenFlags::GDAL_OF_VECTOR,
            ..Default::default()
        },
    )
    .unwrap();
    for n in names {
        for sql in [
            format!("ALTER TABLE {layer} ADD COLUMN {n} TEXT"),
            format!("UPDATE {layer} SET {n} = '{n}'"),
        ] {
            ds.execute_sql(sql, None, gdal::vector::sql::Dialect::SQLITE)
                .unwrap();
        }
    }
}

/// Source fields named as the tool's columns are written with a `src_`
/// prefix repeated until the name is free — a previous run's output (with
/// `src_fid`, and a source field `src_fid` renamed `src_src_fid`) runs
/// again — and a unit field named as a coverage column (`received`) is
/// renamed in the coverage: the run writes every feature instead of failing
/// on a duplicate column after the work.
#[test]
fn fields_named_as_the_tools_columns_are_renamed_until_free() {
    let dir = tmp();
    let d = dir.path();
    let src = d.join("in.gpkg");
    make_layer(&src, "lakes", 32633, &[Some(SQUARE)]);
    add_columns(
        &src,
        "lakes",
        &["src_fid", "src_src_fid", "kind", "src_kind", "method"],
    );
    make_layer(
        &src,
        "units",
        32633,
        &[
            Some("POLYGON((-50 -50,50 -50,50 150,-50 150,-50 -50))"),
            Some("POLYGON((50 -50,150 -50,150 150,50 150,50 -50))"),
        ],
    );
    add_columns(&src, "units", &["received", "src_received", "held"]);
    let out = d.join("out.gpkg");
    let text = format!(
        "input:\n  source: {s}\n  layer: lakes\n  neighbours:\n    source: {s}\n    layer: units\n\
         steps:\n  - skeleton: {{ methods: [MA] }}\n  - partition: {{}}\noutput:\n  path: {o}\n",
        s = src.display(),
        o = out.display()
    );
    let p = pipeline(d, "p.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    let ds = open(&out);
    let column = |name: &str| strings(&ds, "skeletons", name);
    let value = |v: &str| vec![Some(v.to_string())];
    assert_eq!(column("src_src_src_fid"), value("src_fid"));
    assert_eq!(column("src_src_fid"), value("src_src_fid"));
    assert_eq!(column("src_src_kind"), value("kind"));
    assert_eq!(column("src_kind"), value("src_kind"));
    assert_eq!(column("src_method"), value("method"));
    let coverage: Vec<String> = ds
        .layers()
        .filter_map(|l| {
            use gdal::vector::LayerAccess;
            (l.name() == "coverage")
                .then(|| l.defn().fields().map(|f| f.name()).collect::<Vec<_>>())
        })
        .flatten()
        .collect();
    for name in ["src_received", "src_src_received", "received"] {
        assert!(
            coverage.contains(&name.to_string()),
            "{name} not in {coverage:?}"
        );
    }
    // Run again on the output: its columns are the source's fields now.
    let again = d.join("again.gpkg");
    let text = format!(
        "input:\n  source: {}\n  layer: coverage\nsteps:\n  - skeleton: {{ methods: [MA] }}\noutput:\n  path: {}\n",
        out.display(),
        again.display()
    );
    let p = pipeline(d, "again.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    assert_eq!(count(&open(&again), "skeletons"), 2);
}
