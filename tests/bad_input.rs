//! The bad-input corpus (SPEC §11 and the reliability issue): every case is
//! built here — a GeoPackage layer of the given WKT geometries, or a broken
//! pipeline file or path — and run through the real binary, with its exact
//! outcome: exit code, a fragment of the message, and the run's counts of
//! features read, written and rejected (from `skeletonise_runs`).

mod common;
use common::*;
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
            fails(1, "between 1 and"),
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
