//! What an unattended scheduled job must never do — destroy data, report
//! success for a run that did nothing, reject a valid polygon, hang, write
//! an empty row as a result — each through the real binary.

use crate::common::*;
use std::path::Path;

fn out_err(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn demo_copy(dir: &Path) -> String {
    let p = dir.join("in.gpkg");
    std::fs::copy(root(DEMO), &p).unwrap();
    p.display().to_string()
}

// 1. The output can destroy the input or a system file.

#[test]
fn the_output_is_never_the_input() {
    let d = tmp();
    let input = demo_copy(d.path());
    let before = std::fs::read(&input).unwrap();
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        &input,
        "-o",
        &input,
        "--set",
        "output.overwrite=true",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("it is the input"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before, "the input changed");
    // Through a symbolic link too, and in `validate`.
    let link = d.path().join("link.gpkg");
    std::os::unix::fs::symlink(&input, &link).unwrap();
    let o = skeletonise(&[
        "validate",
        "pipelines/demo.yaml",
        "-i",
        &input,
        "-o",
        link.to_str().unwrap(),
    ]);
    assert_eq!(code_and_err(&o).0, 1, "{}", out_err(&o));
    // `score` onto one of its inputs.
    let o = skeletonise(&[
        "score",
        "--polygons",
        &input,
        "--skeletons",
        &input,
        "-o",
        &input,
        "--overwrite",
    ]);
    assert_eq!(code_and_err(&o).0, 1, "{}", out_err(&o));
    assert!(
        out_err(&o).contains("it is the polygons source"),
        "{}",
        out_err(&o)
    );
    assert_eq!(std::fs::read(&input).unwrap(), before, "the input changed");
}

#[test]
fn devices_directories_and_other_formats_are_refused_before_any_work() {
    let d = tmp();
    for (out, why) in [
        ("/dev/null", "GeoPackage"),
        (d.path().to_str().unwrap(), "GeoPackage"),
        ("out.shp", "ending in `.gpkg`"),
    ] {
        let o = skeletonise(&[
            "run",
            "pipelines/demo.yaml",
            "-o",
            out,
            "--set",
            "output.overwrite=true",
        ]);
        let (code, err) = code_and_err(&o);
        assert_eq!(code, 1, "{out}: {err}");
        assert!(err.contains(why), "{out}: {err}");
        assert!(!err.contains("run started"), "{out}: work began: {err}");
    }
    let fifo = d.path().join("pipe.gpkg");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        fifo.to_str().unwrap(),
        "--set",
        "output.overwrite=true",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    assert!(Path::new("/dev/null")
        .metadata()
        .unwrap()
        .file_type()
        .is_char_device());
    let o = skeletonise(&[
        "score",
        "--polygons",
        DEMO,
        "--skeletons",
        DEMO,
        "-o",
        "x.shp",
    ]);
    assert!(out_err(&o).contains(".gpkg"), "{}", out_err(&o));
}

use std::os::unix::fs::FileTypeExt;

// 2. A run that did nothing reports success.

#[test]
fn a_bad_where_clause_on_a_geopackage_is_an_error_in_run_and_validate() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    for w in ["kind = = 1", "no_such_column > 1"] {
        for cmd in ["run", "validate"] {
            let o = skeletonise(&[
                cmd,
                "pipelines/demo.yaml",
                "--set",
                &format!("input.where={w}"),
                "--set",
                "on_error=fail",
                "-o",
                out.to_str().unwrap(),
            ]);
            let (code, err) = code_and_err(&o);
            assert_eq!(code, 1, "{cmd} `{w}`: {err}");
            assert!(err.contains("invalid `input.where`"), "{cmd} `{w}`: {err}");
            assert!(!err.contains("18446744073709551615"), "{err}");
            assert!(!out.exists(), "{cmd} wrote an output");
        }
    }
}

#[test]
fn a_bbox_with_nan_is_an_invalid_pipeline() {
    let o = skeletonise(&[
        "validate",
        "pipelines/demo.yaml",
        "--set",
        "input.bbox=[.nan, 0, 1, 1]",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 78, "{err}");
    assert!(
        err.contains("--set input.bbox") && err.contains("finite"),
        "{err}"
    );
}

// 3. A valid polygon is rejected.

#[test]
fn a_hole_touching_the_shell_inside_an_edge_is_skeletonised() {
    let d = tmp();
    let src = d.path().join("touch.gpkg");
    make_layer(
        &src,
        "touch",
        3035,
        &[Some(
            "POLYGON((0 0,100 0,100 100,0 100,0 0),(0 50,30 40,30 60,0 50))",
        )],
    );
    let out = d.path().join("o.gpkg");
    for make_valid in ["true", "false"] {
        let o = skeletonise(&[
            "run",
            "pipelines/compare-methods.yaml",
            "-i",
            src.to_str().unwrap(),
            "--set",
            "input.layer=touch",
            "--set",
            &format!("steps.prepare.make_valid={make_valid}"),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", out_err(&o));
        let ds = open(&out);
        assert_eq!(count(&ds, "skeletons"), 1, "make_valid {make_valid}");
        assert_eq!(count(&ds, "rejected"), 0, "make_valid {make_valid}");
        let errors = strings(&ds, "candidates", "error");
        assert!(errors.iter().all(Option::is_none), "{errors:?}");
    }
}

// 5. `--threads 10000` hangs.

#[test]
fn too_many_threads_is_a_clear_error_at_once() {
    let t = std::time::Instant::now();
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "--threads",
        "10000",
        "-o",
        "/tmp/never.gpkg",
    ]);
    let (code, err) = code_and_err(&o);
    // A usage error, as `--threads abc` is.
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("between 1 and 256"), "{err}");
    assert!(t.elapsed().as_secs() < 20);
}

// 6. Degenerate scoring.

#[test]
fn a_polygon_too_thin_to_score_gets_a_skeleton_and_a_note() {
    let d = tmp();
    let src = d.path().join("thin.gpkg");
    make_layer(
        &src,
        "thin",
        3035,
        &[Some("POLYGON((0 0,1000000 0,1000000 0.001,0 0.001,0 0))")],
    );
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=thin",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    let ds = open(&out);
    assert_eq!(count(&ds, "skeletons"), 1);
    let g = wkts(&ds, "skeletons");
    assert!(
        g[0].as_deref().is_some_and(|w| !w.contains("EMPTY")),
        "{g:?}"
    );
    let note = strings(&ds, "skeletons", "note");
    assert!(
        note[0].as_deref().is_some_and(|n| n.contains("too thin")),
        "{note:?}"
    );
    assert_eq!(reals(&ds, "skeletons", "distortion"), vec![None]);
}

// 7. `validate` passes what `run` then fails.

#[test]
fn validate_fails_where_run_would() {
    let o = skeletonise(&[
        "validate",
        "pipelines/demo.yaml",
        "-o",
        "/proc/skeletonise.gpkg",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("cannot be written"), "{err}");
    let d = tmp();
    let src = d.path().join("nocrs.gpkg");
    let drv = gdal::DriverManager::get_driver_by_name("GPKG").unwrap();
    let mut ds = drv.create_vector_only(&src).unwrap();
    ds.create_layer(gdal::vector::LayerOptions {
        name: "p",
        ty: gdal::vector::OGRwkbGeometryType::wkbPolygon,
        ..Default::default()
    })
    .unwrap();
    drop(ds);
    let o = skeletonise(&[
        "validate",
        "pipelines/demo.yaml",
        "-i",
        src.to_str().unwrap(),
        "--set",
        "input.layer=p",
        "--set",
        "input.reproject=EPSG:3035",
        "-o",
        d.path().join("o.gpkg").to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("no CRS to reproject from"), "{err}");
}

// 8. The small ones.

#[test]
fn score_refuses_skeletons_in_another_crs() {
    let d = tmp();
    let lines = d.path().join("lines.gpkg");
    make_layer(&lines, "l", 32630, &[Some("LINESTRING(0 0,1 1)")]);
    let o = skeletonise(&[
        "score",
        "--polygons",
        DEMO,
        "--skeletons",
        lines.to_str().unwrap(),
        "-o",
        d.path().join("o.gpkg").to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("different CRSs"), "{err}");
}

#[test]
fn a_pipeline_file_with_a_byte_order_mark_and_typed_variables_loads() {
    let d = tmp();
    let text = format!(
        "\u{feff}input:\n  source: {}\nsteps:\n  - skeleton: {{ methods: [CDT] }}\n  - prune:\n      ratio: ${{RATIO}}\n  - score: {{}}\n  - select: {{ min_coverage: \"${{MINCOV:-0.5}}\" }}\noutput:\n  path: {}\n",
        root(DEMO),
        d.path().join("o.gpkg").display()
    );
    let p = pipeline(d.path(), "bom.yaml", &text);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_skeletonise"))
        .args(["run", p.to_str().unwrap()])
        .env("RATIO", "2")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", out_err(&o));
}

#[test]
fn json_logs_have_no_raw_gdal_lines() {
    let o = skeletonise(&[
        "--log-format",
        "json",
        "run",
        "pipelines/demo.yaml",
        "--set",
        "input.where=no_such_column > 1",
        "-o",
        "/tmp/never.gpkg",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.is_empty());
    for line in err.lines() {
        assert!(
            serde_json::from_str::<serde_json::Value>(line).is_ok(),
            "not JSON: {line}"
        );
    }
}

#[test]
fn a_wrong_override_is_blamed_on_the_override() {
    let o = skeletonise(&[
        "validate",
        "pipelines/demo.yaml",
        "--set",
        "steps.prune.ratio=-1",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 78);
    assert!(err.contains("--set steps.prune.ratio=-1"), "{err}");
    assert!(!err.contains("demo.yaml:"), "{err}");
}

#[test]
fn budgets_reject_a_feature_or_stop_a_method_with_the_reason() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "--set",
        "steps.prepare.max_vertices=20",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    let ds = open(&out);
    let reasons = strings(&ds, "rejected", "reason");
    assert!(!reasons.is_empty());
    assert!(reasons
        .iter()
        .all(|r| r.as_deref().is_some_and(|r| r.contains("max_vertices"))));
    assert_eq!(count(&ds, "skeletons") + count(&ds, "rejected"), 17);
    // A budget of a millisecond per method stops every method on a
    // 12 000-vertex river reach: the feature is rejected with the reasons.
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "--set",
        "input.layer=river_lena",
        "--set",
        "input.where=fid = 2",
        "--set",
        "steps.skeleton.timeout_s=0.001",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.overwrite=true",
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    let ds = open(&out);
    let reasons = strings(&ds, "rejected", "reason");
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    let r = reasons[0].clone().unwrap_or_default();
    // MA, DVD, CDT and VD are stopped when the budget has passed; StSk
    // predicts its cost and declines before it starts.
    assert!(
        r.contains("MA stopped after 0.001 s") && r.contains("timeout_s"),
        "{r}"
    );
    assert!(r.contains("StSk skipped: it would need about"), "{r}");
}

#[test]
fn the_memory_budget_covers_pruning_and_scoring_too() {
    // MA's raw skeleton of a 12 000-vertex reach is made (the method does
    // not predict its memory), but its pruning would need more than a
    // megabyte: the method fails for the feature with the stage and the
    // option in the reason, and the feature is listed, never dropped.
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "--set",
        "input.layer=river_lena",
        "--set",
        "input.where=fid = 2",
        "--set",
        "steps.skeleton.max_memory_mb=1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    let ds = open(&out);
    let reasons = strings(&ds, "rejected", "reason");
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    let r = reasons[0].clone().unwrap_or_default();
    assert!(
        r.contains("MA skipped: it would need about")
            && r.contains("for pruning and extending this polygon")
            && r.contains("`skeleton.max_memory_mb` = 1"),
        "{r}"
    );
    // With a budget that holds, the same reach goes through.
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "--set",
        "input.layer=river_lena",
        "--set",
        "input.where=fid = 2",
        "--set",
        "steps.skeleton.max_memory_mb=64",
        "-o",
        out.to_str().unwrap(),
        "--overwrite",
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    assert_eq!(count(&open(&out), "skeletons"), 1);
}

#[test]
fn a_memory_budget_out_of_range_is_a_clear_error() {
    let o = skeletonise(&[
        "validate",
        "pipelines/demo.yaml",
        "--set",
        "steps.skeleton.max_memory_mb=-1",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 78, "{err}");
    assert!(
        err.contains("max_memory_mb") && err.contains("megabytes ≥ 0"),
        "{err}"
    );
}

#[test]
fn the_run_record_holds_every_methods_step_times() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "--set",
        "input.layer=islands_hebrides",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    let stages = strings(&open(&out), "skeletonise_runs", "stage_seconds");
    let text = stages[0].clone().expect("stage_seconds is set");
    let v: serde_json::Value = serde_json::from_str(&text).expect("stage_seconds is JSON");
    for m in ["MA", "StSk", "DVD", "CDT", "VD"] {
        let steps = &v[m];
        for step in ["skeleton", "prune_extend", "score"] {
            let t = steps[step].as_f64().unwrap_or(-1.0);
            assert!(t >= 0.0, "{m}.{step} in {text}");
        }
        // Every method made and scored 1192 skeletons: time was spent
        // (the record keeps milliseconds).
        let spent = steps["skeleton"].as_f64().unwrap() + steps["score"].as_f64().unwrap();
        assert!(spent > 0.0, "{m} in {text}");
    }
}

#[test]
fn progress_lines_appear_in_logs_without_a_terminal() {
    let o = skeletonise(&[
        "run",
        "pipelines/islands.yaml",
        "--set",
        "steps.skeleton.methods=[CDT]",
        "--progress-every",
        "0",
        "-o",
        "/tmp/skeletonise-progress.gpkg",
        "--set",
        "output.overwrite=true",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("progress: ") && err.contains("of 1192 features"),
        "{err}"
    );
    let _ = std::fs::remove_file("/tmp/skeletonise-progress.gpkg");
}

#[test]
fn a_run_longer_than_one_commit_writes_and_indexes_every_row() {
    // 1 192 islands with candidates: skeleton and candidate rows together
    // span several of the writer's commits (every 1 024 rows) and the last
    // one after the last batch; none may be lost or left out of an R-tree.
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/islands.yaml",
        "--set",
        "steps.skeleton.methods=[CDT,VD]",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", out_err(&o));
    let ds = open(&out);
    assert_eq!(count(&ds, "skeletons") + count(&ds, "rejected"), 1192);
    assert_eq!(count(&ds, "candidates"), 2 * 1192);
    for layer in ["skeletons", "candidates"] {
        let entries = format!("SELECT count(*) FROM \"rtree_{layer}_geom\"");
        assert_eq!(
            first_text(&ds, &entries),
            Some(count(&ds, layer).to_string()),
            "R-tree of {layer}"
        );
    }
}

/// One feature's run for a budget test: the pipeline `text` (its `{out}`
/// replaced) → the rejection reasons, the skeleton rows and the seconds.
fn budget_run(dir: &Path, name: &str, text: &str) -> (Vec<String>, u64, f64) {
    let out = dir.join(format!("{name}.gpkg"));
    let p = pipeline(
        dir,
        &format!("{name}.yaml"),
        &text.replace("{out}", &out.display().to_string()),
    );
    let started = std::time::Instant::now();
    let o = skeletonise(&["run", p.to_str().unwrap()]);
    let seconds = started.elapsed().as_secs_f64();
    assert!(o.status.success(), "{name}: {}", out_err(&o));
    let ds = open(&out);
    let reasons = strings(&ds, "rejected", "reason")
        .into_iter()
        .flatten()
        .collect();
    (reasons, count(&ds, "skeletons"), seconds)
}

/// Every step after `select` keeps `skeleton.timeout_s` (a clock of its
/// own, as long as a method's): on a polygon each method handles well
/// within the budget, a step with far more work — connection legs to
/// 80 000 crossings, `collapse` of a 20 km snake at 4 m (two million
/// samples), `partition` between 20 000 units, `label` of a 50 000-vertex
/// rough lake with its own medial axis — rejects the feature soon after the
/// budget runs out, naming the step, and the same pipeline without the step
/// writes it within the same budget.
#[test]
fn every_step_after_select_keeps_the_time_budget() {
    let dir = tmp();
    let src = dir.path().join("work.gpkg");
    let (lake, line) = shapes::zig_zag_lake(80_000);
    make_layer(&src, "lake", 32633, &[Some(&lake)]);
    make_layer(&src, "lines", 32633, &[Some(&line)]);
    make_layer(&src, "snake", 32633, &[Some(&shapes::snake(200, 20_000.0))]);
    make_layer(&src, "rough", 32633, &[Some(&shapes::rough_lobes(50_000))]);
    let (river, units) = shapes::river_between_strips(10_000);
    make_layer(&src, "river", 32633, &[Some(&river)]);
    let units: Vec<Option<&str>> = units.iter().map(|u| Some(u.as_str())).collect();
    make_layer(&src, "units", 32633, &units);
    let src = src.display().to_string();
    let side =
        |kind: &str, layer: &str| format!("  {kind}:\n    source: {src}\n    layer: {layer}\n");
    // (step, input, side input, methods, timeout, the step's YAML)
    let cases = [
        (
            "input.connect",
            "lake",
            side("connect", "lines"),
            "MA",
            "0.3",
            "",
        ),
        (
            "collapse",
            "snake",
            String::new(),
            "MA",
            "0.5",
            "  - collapse: { width: 4 }\n",
        ),
        (
            "partition",
            "river",
            side("neighbours", "units"),
            "MA",
            "0.1",
            "  - partition: {}\n",
        ),
        (
            "label",
            "rough",
            String::new(),
            "CDT",
            "0.5",
            "  - label: {}\n",
        ),
    ];
    for (step, layer, second, methods, timeout, yaml) in cases {
        let text = |with: bool| {
            let (second, yaml) = if with {
                (second.as_str(), yaml)
            } else {
                ("", "")
            };
            format!(
                "input:\n  source: {src}\n  layer: {layer}\n{second}steps:\n  - skeleton:\n      methods: [{methods}]\n      timeout_s: {timeout}\n{yaml}output:\n  path: {{out}}\non_error: reject\n"
            )
        };
        let (reasons, written, seconds) =
            budget_run(dir.path(), &format!("{layer}-with"), &text(true));
        assert_eq!(written, 0, "{step}: {reasons:?}");
        assert!(
            reasons.len() == 1
                && reasons[0].contains(&format!("`{step}` ran past `skeleton.timeout_s`")),
            "{step}: {reasons:?}"
        );
        assert!(seconds < 60.0, "{step}: the run took {seconds} s");
        let (reasons, written, _) =
            budget_run(dir.path(), &format!("{layer}-without"), &text(false));
        assert_eq!(
            (written, reasons.len()),
            (1, 0),
            "{step} left out: {reasons:?}"
        );
    }
}
