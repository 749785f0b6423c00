//! End-to-end tests through the real binary on real GeoPackage files.

use crate::common::*;
use gdal::vector::LayerAccess;

#[test]
fn demo_pipeline_runs_and_writes_every_layer() {
    let d = tmp();
    let out = d.path().join("demo.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("17 read, 17 written, 0 rejected"), "{err}");
    let ds = open(&out);
    assert_eq!(count(&ds, "skeletons"), 17);
    // Every source field is carried over, with src_fid and method.
    let kinds = strings(&ds, "skeletons", "kind");
    assert!(kinds.iter().all(|k| k.is_some()));
    let source_fids: Vec<Option<i64>> = {
        let src = open(std::path::Path::new(DEMO));
        let mut l = src.layer_by_name("demo").unwrap();
        l.features().map(|f| f.fid().map(|x| x as i64)).collect()
    };
    assert_eq!(ints(&ds, "skeletons", "src_fid"), source_fids);
    let methods = strings(&ds, "skeletons", "method");
    assert!(
        methods
            .iter()
            .all(|m| ["MA", "StSk", "DVD", "CDT", "VD"].contains(&m.as_deref().unwrap_or(""))),
        "{methods:?}"
    );
    assert!(wkts(&ds, "skeletons").iter().all(|w| w
        .as_deref()
        .is_some_and(|w| w.starts_with("MULTILINESTRING"))));
    // The output keeps the source CRS.
    let srs = ds
        .layer_by_name("skeletons")
        .unwrap()
        .spatial_ref()
        .unwrap();
    assert_eq!(srs.auth_code().unwrap(), 3035);
    // Provenance.
    assert_eq!(count(&ds, "skeletonise_runs"), 1);
    assert_eq!(ints(&ds, "skeletonise_runs", "features_read"), [Some(17)]);
    assert!(strings(&ds, "skeletonise_runs", "pipeline")[0]
        .as_deref()
        .unwrap()
        .contains("name: demo"));
    // The input as it reopens from anywhere (the report draws its polygons).
    assert_eq!(
        strings(&ds, "skeletonise_runs", "input_source"),
        [Some(root(DEMO))]
    );
    assert_eq!(
        strings(&ds, "skeletonise_runs", "input_layer"),
        [Some("demo".into())]
    );
    assert_eq!(strings(&ds, "skeletonise_runs", "input_reproject"), [None]);
    assert_eq!(
        strings(&ds, "skeletonise_runs", "skeleton_layer"),
        [Some("skeletons".into())]
    );
    assert_eq!(count(&ds, "rejected"), 0);
    assert_eq!(count(&ds, "candidates"), 17 * 5);
    // Every feature has exactly one chosen candidate, and it is the method written.
    assert_eq!(
        ints(&ds, "candidates", "chosen")
            .iter()
            .filter(|c| **c == Some(1))
            .count(),
        17
    );
    // The widths layer: the chosen skeletons segment by segment with positive widths.
    assert!(count(&ds, "widths") > 17);
    assert!(reals(&ds, "widths", "width")
        .iter()
        .all(|w| w.is_some_and(|w| w >= 0.0)));
    // Scores are written and the distortion is in [0, 1].
    assert!(reals(&ds, "skeletons", "distortion")
        .iter()
        .all(|z| z.is_some_and(|z| (0.0..=1.0).contains(&z))));
    // Every spatial layer has its R-tree, holding every feature (a GIS
    // draws and filters the layers through it).
    for layer in ["skeletons", "candidates", "widths", "rejected"] {
        let entries = format!("SELECT count(*) FROM \"rtree_{layer}_geom\"");
        assert_eq!(
            first_text(&ds, &entries),
            Some(count(&ds, layer).to_string()),
            "R-tree of {layer}"
        );
        // The tree is sound by SQLite's own check, and each row is under
        // its own id in a box around its geometry.
        let check = format!("SELECT rtreecheck('rtree_{layer}_geom')");
        assert_eq!(first_text(&ds, &check).as_deref(), Some("ok"), "{layer}");
        let covered = format!(
            "SELECT count(*) FROM \"{layer}\" t JOIN \"rtree_{layer}_geom\" r ON r.id = t.fid \
             WHERE r.minx <= ST_MinX(t.geom) AND r.maxx >= ST_MaxX(t.geom) \
             AND r.miny <= ST_MinY(t.geom) AND r.maxy >= ST_MaxY(t.geom)"
        );
        assert_eq!(
            first_text(&ds, &covered),
            Some(count(&ds, layer).to_string()),
            "{layer}"
        );
    }
    // The widths layer is large enough for a tree of several nodes.
    let nodes = first_text(&ds, "SELECT count(*) FROM rtree_widths_geom_node");
    assert!(
        nodes
            .as_deref()
            .is_some_and(|n| n.parse::<i32>().unwrap() > 1),
        "widths tree nodes: {nodes:?}"
    );
    drop(ds);
    // A row added later by any GIS is indexed as in any GeoPackage.
    let ds = gdal::Dataset::open_ex(
        &out,
        gdal::DatasetOptions {
            open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE | gdal::GdalOpenFlags::GDAL_OF_VECTOR,
            ..Default::default()
        },
    )
    .unwrap();
    let before = count(&ds, "skeletons");
    {
        let l = ds.layer_by_name("skeletons").unwrap();
        let g = gdal::vector::Geometry::from_wkt("MULTILINESTRING ((1 2, 3 4))").unwrap();
        let mut f = gdal::vector::Feature::new(l.defn()).unwrap();
        f.set_geometry(g).unwrap();
        f.create(&l).unwrap();
    }
    let indexed = first_text(
        &ds,
        "SELECT count(*) FROM rtree_skeletons_geom WHERE minx <= 1 AND maxx >= 3 AND miny <= 2 AND maxy >= 4",
    );
    assert_eq!(indexed.as_deref(), Some("1"));
    assert_eq!(
        first_text(&ds, "SELECT count(*) FROM rtree_skeletons_geom"),
        Some((before + 1).to_string())
    );
}

/// The first column of the first row of `sql`, as text.

#[test]
fn invalid_pipeline_files_exit_78_with_line_and_column_and_write_nothing() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let good = basic_pipeline(&root(DEMO), "demo", &out, "  - prune: { ratio: 1.0 }\n");
    let cases = [
        (
            good.replace("ratio: 1.0", "ratoi: 1.0"),
            "6:14",
            "unknown field `ratoi`",
        ),
        (
            good.replace("ratio: 1.0", "ratio: lots"),
            "6:21",
            "invalid type",
        ),
        (
            good.replace(
                "  - prune: { ratio: 1.0 }\n",
                "  - prune: {}\n  - prepare: {}\n",
            ),
            "7:5",
            "must come before",
        ),
        (
            good.replace("layer: demo", "layer: [demo"),
            "",
            "invalid YAML",
        ),
    ];
    for (i, (text, pos, msg)) in cases.iter().enumerate() {
        let p = pipeline(d.path(), &format!("p{i}.yaml"), text);
        let o = skeletonise(&["run", p.to_str().unwrap()]);
        let (code, err) = code_and_err(&o);
        assert_eq!(code, 78, "case {i}: {err}");
        assert!(err.contains(&format!("p{i}.yaml:{pos}")), "case {i}: {err}");
        assert!(err.contains(msg), "case {i}: {err}");
        assert!(!out.exists());
        // validate shares the checks.
        assert_eq!(
            skeletonise(&["validate", p.to_str().unwrap()])
                .status
                .code(),
            Some(78)
        );
    }
}

#[test]
fn missing_input_and_missing_layer_are_clear_errors() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let p = pipeline(
        d.path(),
        "a.yaml",
        &basic_pipeline("/nonexistent/rivers.gpkg", "x", &out, ""),
    );
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1);
    assert!(
        err.contains("cannot open input `/nonexistent/rivers.gpkg`"),
        "{err}"
    );
    let p = pipeline(
        d.path(),
        "b.yaml",
        &basic_pipeline(&root(TRAIN), "rivers", &out, ""),
    );
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1);
    assert!(
        err.contains("layer `rivers` not found") && err.contains("river_lena"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn geographic_crs_needs_reproject() {
    let d = tmp();
    let src = d.path().join("geo.gpkg");
    make_layer(
        &src,
        "lakes",
        4326,
        &[Some(
            "POLYGON ((10 50, 10.02 50, 10.02 50.005, 10 50.005, 10 50))",
        )],
    );
    let out = d.path().join("o.gpkg");
    let text = basic_pipeline(src.to_str().unwrap(), "lakes", &out, "");
    let p = pipeline(d.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1);
    assert!(
        err.contains("geographic CRS") && err.contains("input.reproject"),
        "{err}"
    );
    assert!(!out.exists());
    // With reproject the same file works, in metres.
    let o = skeletonise(&[
        "run",
        p.to_str().unwrap(),
        "--set",
        "input.reproject=EPSG:32632",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    let w = wkts(&ds, "skeletons")[0].clone().unwrap();
    // UTM eastings near 10°E are around 500 km.
    assert!(w.contains("(5") || w.contains("(4"), "{w}");
    assert_eq!(
        ds.layer_by_name("skeletons")
            .unwrap()
            .spatial_ref()
            .unwrap()
            .auth_code()
            .unwrap(),
        32632
    );
}

#[test]
fn existing_output_without_overwrite_is_left_untouched() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    std::fs::write(&out, b"precious").unwrap();
    let p = pipeline(
        d.path(),
        "p.yaml",
        &basic_pipeline(&root(DEMO), "demo", &out, ""),
    );
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1);
    assert!(
        err.contains("already exists") && err.contains("overwrite"),
        "{err}"
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        2,
        "no temporary file left behind"
    );
    // The same run with overwrite replaces it.
    let o = skeletonise(&["run", p.to_str().unwrap(), "--set", "output.overwrite=true"]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(count(&open(&out), "skeletons"), 17);
}

#[test]
fn unwritable_output_fails_before_any_work() {
    let d = tmp();
    let out = d.path().join("no/such/dir/o.gpkg");
    let p = pipeline(
        d.path(),
        "p.yaml",
        &basic_pipeline(&root(DEMO), "demo", &out, ""),
    );
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1);
    assert!(err.contains("does not exist"), "{err}");
    assert!(!err.contains("run started"), "failed before reading: {err}");
    let (code, _) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
    assert_eq!(code, 1);
}

const BAD: &[Option<&str>] = &[
    None,
    Some("POLYGON EMPTY"),
    Some("POINT (1 2)"),
    Some("LINESTRING (0 0, 10 10)"),
    Some("POLYGON ((0 0, 100 0, 100 20, 0 20, 0 0))"),
    Some("POLYGON ((0 0, 40 40, 40 0, 0 60, 0 0))"),
    Some("POLYGON Z ((0 0 5, 100 0 5, 100 20 5, 0 20 5, 0 0 5))"),
    Some("CURVEPOLYGON (COMPOUNDCURVE (CIRCULARSTRING (0 0, 50 50, 100 0), (100 0, 0 0)))"),
    Some("MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 30 0, 30 10, 20 10, 20 0)))"),
    Some("POLYGON ((0 0, 10 0, 10 10, 10 10, 0 10, 0 0))"),
];

#[test]
fn bad_geometries_are_rejected_with_reasons_and_nothing_is_lost() {
    let d = tmp();
    let src = d.path().join("bad.gpkg");
    make_layer(&src, "bad", 32630, BAD);
    let out = d.path().join("o.gpkg");
    let extra = "  - prune: {}\n  - extend: {}\n  - score: {}\n  - select: {}\n";
    let text = basic_pipeline(src.to_str().unwrap(), "bad", &out, extra)
        .replace("steps:\n", "steps:\n  - prepare: { make_valid: false }\n");
    let p = pipeline(d.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    let written = count(&ds, "skeletons");
    let rejected = count(&ds, "rejected");
    assert_eq!(
        written + rejected,
        BAD.len() as u64,
        "read = written + rejected"
    );
    let reasons: Vec<(i64, String)> = ints(&ds, "rejected", "src_fid")
        .into_iter()
        .zip(strings(&ds, "rejected", "reason"))
        .map(|(f, r)| (f.unwrap(), r.unwrap()))
        .collect();
    let reason = |fid: i64| {
        reasons
            .iter()
            .find(|(f, _)| *f == fid)
            .map(|(_, r)| r.clone())
            .unwrap_or_default()
    };
    assert!(reason(1).contains("NULL geometry"), "{reasons:?}");
    assert!(reason(2).contains("empty"), "{reasons:?}");
    assert!(reason(3).contains("point geometry"), "{reasons:?}");
    assert!(reason(4).contains("line geometry"), "{reasons:?}");
    assert!(
        reason(6).contains("invalid polygon") && reason(6).contains("make_valid"),
        "{reasons:?}"
    );
    assert_eq!(rejected, 5, "{reasons:?}");
    // Z dropped, curve linearised, multipolygon processed part by part, duplicate vertex cleaned.
    let fids = ints(&ds, "skeletons", "src_fid");
    assert_eq!(fids, [Some(5), Some(7), Some(8), Some(9), Some(10)]);
    // The rejected layer keeps the input geometry.
    let geoms = wkts(&ds, "rejected");
    assert!(geoms
        .iter()
        .any(|g| g.as_deref().is_some_and(|g| g.starts_with("POINT"))));
    // With make_valid the bow-tie is repaired instead.
    let text = text.replace("make_valid: false", "make_valid: true");
    let p = pipeline(d.path(), "q.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap(), "--set", "output.overwrite=true"]);
    assert_eq!(o.status.code(), Some(0));
    let ds = open(&out);
    assert_eq!(count(&ds, "rejected"), 4);
    let repaired = ints(&ds, "skeletons", "repaired");
    let fids = ints(&ds, "skeletons", "src_fid");
    let i = fids
        .iter()
        .position(|f| *f == Some(6))
        .expect("bow-tie written");
    assert_eq!(repaired[i], Some(1));
}

#[test]
fn on_error_fail_exits_65_and_writes_nothing() {
    let d = tmp();
    let src = d.path().join("bad.gpkg");
    make_layer(&src, "bad", 32630, BAD);
    let out = d.path().join("o.gpkg");
    let text = basic_pipeline(src.to_str().unwrap(), "bad", &out, "") + "on_error: fail\n";
    let p = pipeline(d.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 65, "{err}");
    assert!(
        err.contains("feature 1 was rejected: NULL geometry"),
        "{err}"
    );
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(d.path()).unwrap().count(),
        2,
        "no temporary file left behind"
    );
}

/// Reading, working and writing overlap on their own threads; what is
/// written must not depend on how many workers there are: every layer,
/// row for row, over several batches (600 islands, batches of 256).
#[test]
fn output_is_identical_for_one_two_and_three_threads() {
    let d = tmp();
    let mut results = Vec::new();
    for t in ["1", "2", "3"] {
        let out = d.path().join(format!("o{t}.gpkg"));
        let o = skeletonise(&[
            "run",
            &root("pipelines/islands.yaml"),
            "--set",
            &format!("input.source={}", root(TRAIN)),
            "--set",
            "input.where=fid <= 600",
            "-o",
            out.to_str().unwrap(),
            "--threads",
            t,
        ]);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        results.push(crate::common::canonical(&out));
    }
    assert!(
        results[0].matches('\n').count() > 600 * 5,
        "candidates are written"
    );
    assert_eq!(results[0], results[1]);
    assert_eq!(results[0], results[2]);
}

#[test]
fn validate_checks_without_writing_and_json_logs_for_scheduled_jobs() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let p = pipeline(
        d.path(),
        "p.yaml",
        &basic_pipeline(&root(TRAIN), "river_danube", &out, ""),
    );
    let o = skeletonise(&["validate", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(
        s.contains("valid") && s.contains("EPSG:32634") && s.contains("area_m2"),
        "{s}"
    );
    assert!(!out.exists());
    let o = skeletonise(&["run", p.to_str().unwrap(), "--log-format", "json"]);
    assert_eq!(o.status.code(), Some(0));
    let last = String::from_utf8_lossy(&o.stderr)
        .lines()
        .last()
        .unwrap()
        .to_string();
    let v: serde_json::Value = serde_json::from_str(&last).expect("JSON log line");
    assert_eq!(v["read"], 1);
    assert_eq!(v["written"], 1);
}

#[test]
fn schema_and_methods_describe_the_pipeline_file() {
    let o = skeletonise(&["schema"]);
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["properties"]["steps"].is_object());
    let o = skeletonise(&["methods"]);
    let s = String::from_utf8_lossy(&o.stdout);
    for m in ["VD", "DVD", "CDT", "StSk", "MA", "prune", "min_coverage"] {
        assert!(s.contains(m), "{m}");
    }
    assert_eq!(
        skeletonise(&["run"]).status.code(),
        Some(2),
        "usage errors exit 2"
    );
}

#[test]
fn score_subcommand_scores_another_tools_skeletons_by_key_and_by_location() {
    let d = tmp();
    let polys = d.path().join("p.gpkg");
    // A 100 × 20 rectangle and a 100 × 20 rectangle far away.
    make_layer(
        &polys,
        "polys",
        32630,
        &[
            Some("POLYGON ((0 0, 100 0, 100 20, 0 20, 0 0))"),
            Some("POLYGON ((1000 0, 1100 0, 1100 20, 1000 20, 1000 0))"),
        ],
    );
    let lines = d.path().join("s.gpkg");
    // Centre line of the first (Δd = 0), a line offset by 5 in the second.
    make_layer(
        &lines,
        "lines",
        32630,
        &[
            Some("LINESTRING (10 10, 90 10)"),
            Some("LINESTRING (1010 15, 1090 15)"),
        ],
    );
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "score",
        "--polygons",
        polys.to_str().unwrap(),
        "--skeletons",
        lines.to_str().unwrap(),
        "--label",
        "other",
        "-o",
        out.to_str().unwrap(),
        "--bars",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    assert_eq!(
        strings(&ds, "skeletons", "method"),
        [Some("other".into()), Some("other".into())]
    );
    let z = reals(&ds, "skeletons", "distortion");
    assert_eq!(z[0], Some(0.0));
    // Offset by 5 in a 20-wide strip: d = 15 and 5 → z = 10 / 20.
    assert!((z[1].unwrap() - 0.5).abs() < 1e-9, "{z:?}");
    assert!(count(&ds, "bars") > 0);
    // By key: the `id` field of the lines holds 0 and 1, the polygons' `id` too.
    let o = skeletonise(&[
        "score",
        "--polygons",
        polys.to_str().unwrap(),
        "--skeletons",
        lines.to_str().unwrap(),
        "--skeleton-key",
        "id",
        "--polygon-key",
        "id",
        "-o",
        out.to_str().unwrap(),
        "--overwrite",
    ]);
    assert_eq!(o.status.code(), Some(0));
    let z2 = reals(&open(&out), "skeletons", "distortion");
    assert_eq!(z, z2);
}

/// SPEC §11: huge coordinates, tiny and sliver polygons, touching rings,
/// spikes and duplicate vertices go through every method without a panic and
/// without losing a feature.
#[test]
fn awkward_polygons_go_through_every_method() {
    let d = tmp();
    let src = d.path().join("awkward.gpkg");
    let wkts: &[Option<&str>] = &[
        // Huge coordinates (1e7 and more): a 300 × 40 m strip.
        Some("POLYGON ((12345678 23456789, 12345978 23456789, 12345978 23456829, 12345678 23456829, 12345678 23456789))"),
        // Tiny: a 1 mm triangle.
        Some("POLYGON ((0 0, 0.001 0, 0 0.001, 0 0))"),
        // Sliver: 1000 m long, 1 mm wide.
        Some("POLYGON ((0 0, 1000 0, 1000 0.001, 0 0.001, 0 0))"),
        // A hole touching the exterior at one vertex.
        Some("POLYGON ((0 0, 100 0, 100 100, 0 100, 0 0), (0 0, 40 20, 20 40, 0 0))"),
        // A spike (invalid; repaired by make_valid).
        Some("POLYGON ((0 0, 100 0, 100 50, 150 50, 100 50, 100 100, 0 100, 0 0))"),
        // Duplicate consecutive vertices.
        Some("POLYGON ((0 0, 100 0, 100 0, 100 30, 0 30, 0 30, 0 0))"),
        // Nearly collinear vertices.
        Some("POLYGON ((0 0, 50 0.0000001, 100 0, 100 30, 0 30, 0 0))"),
    ];
    make_layer(&src, "awkward", 32630, wkts);
    let out = d.path().join("o.gpkg");
    let extra = "  - prune: {}\n  - extend: {}\n  - score: {}\n  - select: {}\n";
    let text = basic_pipeline(src.to_str().unwrap(), "awkward", &out, extra)
        .replace("methods: [CDT]", "methods: [MA, StSk, DVD, CDT, VD]")
        .replace("path: ", "candidates: true\n  path: ");
    let p = pipeline(d.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    let (written, rejected) = (count(&ds, "skeletons"), count(&ds, "rejected"));
    assert_eq!(written + rejected, wkts.len() as u64);
    assert_eq!(rejected, 0, "{:?}", strings(&ds, "rejected", "reason"));
    // Huge coordinates keep their precision: the strip's centre line is at y = 23456809.
    let w = wkts_of(&ds, 1);
    assert!(w.contains("23456809"), "{w}");
    // Every method either succeeded or says why.
    for (ok, e) in ints(&ds, "candidates", "chosen")
        .iter()
        .zip(strings(&ds, "candidates", "error"))
    {
        assert!(ok.is_some() && (e.is_none() || !e.unwrap().is_empty()));
    }
}

fn wkts_of(ds: &gdal::Dataset, fid: i64) -> String {
    let fids = ints(ds, "skeletons", "src_fid");
    let i = fids.iter().position(|f| *f == Some(fid)).unwrap();
    wkts(ds, "skeletons")[i].clone().unwrap()
}

/// SPEC §11: a polygon of a million vertices is processed (CDT) without
/// running out of memory or time.
#[test]
fn a_polygon_of_a_million_vertices() {
    let d = tmp();
    let src = d.path().join("big.gpkg");
    let n = 1_000_000;
    let mut w = String::from("POLYGON ((");
    for i in 0..=n {
        let t = (i % n) as f64 / n as f64 * std::f64::consts::TAU;
        let r = 1000.0 + 30.0 * (t * 50.0).sin() + 5.0 * (t * 3000.0).sin();
        if i > 0 {
            w.push(',');
        }
        w.push_str(&format!(
            "{:.4} {:.4}",
            500000.0 + 3.0 * r * t.cos(),
            6000000.0 + r * t.sin()
        ));
    }
    w.push_str("))");
    make_layer(&src, "big", 32630, &[Some(&w)]);
    let out = d.path().join("o.gpkg");
    let p = pipeline(
        d.path(),
        "p.yaml",
        &basic_pipeline(src.to_str().unwrap(), "big", &out, ""),
    );
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    assert_eq!(count(&ds, "skeletons"), 1);
    assert_eq!(count(&ds, "rejected"), 0);
    // Its report draws it within the display budget.
    let html = d.path().join("o.html");
    let (code, err) = code_and_err(&skeletonise(&["report", out.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    let size = std::fs::metadata(&html).unwrap().len() as usize;
    assert!(
        size < skeletonise::report::section_bound(1) + 100_000,
        "{size} bytes"
    );
}

/// Any OGR data source string: a GeoPackage inside a zip archive, read through
/// GDAL's `/vsizip/` virtual file system, and a layer chosen by index.
#[test]
fn reads_a_zipped_source_by_layer_index() {
    let d = tmp();
    let zip = d.path().join("demo.zip");
    let status = std::process::Command::new("python3")
        .args([
            "-c",
            "import sys, zipfile; zipfile.ZipFile(sys.argv[1], 'w').write(sys.argv[2], 'demo.gpkg')",
            zip.to_str().unwrap(),
            &root(DEMO),
        ])
        .status()
        .unwrap();
    assert!(status.success());
    let out = d.path().join("o.gpkg");
    let source = format!("/vsizip/{}/demo.gpkg", zip.display());
    let text = basic_pipeline(&source, "0", &out, "");
    let p = pipeline(d.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    assert_eq!(count(&open(&out), "skeletons"), 17);
}

#[test]
fn a_where_filter_the_source_rejects_stops_the_run_with_the_reason() {
    // GeoPackage hands the filter to SQLite, which rejects it only when it
    // runs: the run must not go on and select nothing.
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "input.where=\"no_such_field = 1\"",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("invalid `input.where` filter `no_such_field = 1`")
            && err.contains("no such column"),
        "{err}"
    );
    assert!(!out.exists());
}

/// The rows a user compares: source fid, method, scores and geometry.
fn rows(out: &std::path::Path) -> Vec<String> {
    let ds = open(out);
    let fids = ints(&ds, "skeletons", "src_fid");
    let methods = strings(&ds, "skeletons", "method");
    let z = reals(&ds, "skeletons", "distortion");
    let w = wkts(&ds, "skeletons");
    (0..fids.len())
        .map(|i| format!("{:?} {:?} {:?} {:?}", fids[i], methods[i], z[i], w[i]))
        .collect()
}

#[test]
fn runs_without_a_pipeline_file_like_the_default_pipeline() {
    let d = tmp();
    let a = d.path().join("a.gpkg");
    let b = d.path().join("b.gpkg");
    let o = skeletonise(&[
        "run",
        "-i",
        TRAIN,
        "-l",
        "lakes_scotland",
        "-o",
        a.to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("18 read, 18 written"), "{err}");
    let o = skeletonise(&[
        "run",
        "pipelines/default.yaml",
        "-i",
        TRAIN,
        "--layer",
        "lakes_scotland",
        "-o",
        b.to_str().unwrap(),
    ]);
    assert_eq!(code_and_err(&o).0, 0);
    let (ra, rb) = (rows(&a), rows(&b));
    assert_eq!(ra.len(), 18);
    assert_eq!(ra, rb);
    // The built-in pipeline is recorded as the run's provenance.
    assert!(strings(&open(&a), "skeletonise_runs", "pipeline")[0]
        .as_deref()
        .unwrap()
        .contains("name: default"));
    // `--set` works there too.
    let c = d.path().join("c.gpkg");
    let o = skeletonise(&[
        "run",
        "-i",
        TRAIN,
        "-l",
        "lakes_scotland",
        "-o",
        c.to_str().unwrap(),
        "--set",
        "steps.skeleton.methods=[CDT]",
    ]);
    assert_eq!(code_and_err(&o).0, 0);
    assert!(strings(&open(&c), "skeletons", "method")
        .iter()
        .all(|m| m.as_deref() == Some("CDT")));
    // Without `-l`, the first layer (GDAL's order) is read.
    let f = d.path().join("f.gpkg");
    let o = skeletonise(&["run", "-i", TRAIN, "-o", f.to_str().unwrap()]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("layer=islands_hebrides"), "{err}");
    // No pipeline file and no output: a usage error that says what to give.
    let o = skeletonise(&["run", "-i", TRAIN]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 2);
    assert!(err.contains("-i SOURCE -o OUT.gpkg"), "{err}");
}

#[test]
fn a_pipelines_layer_missing_from_another_source_points_to_dash_l() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        TRAIN,
        "-o",
        out.to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1);
    assert!(
        err.contains("layer `demo` not found")
            && err.contains("lakes_scotland")
            && err.contains("-l LAYER"),
        "{err}"
    );
    assert!(!out.exists());
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        TRAIN,
        "-l",
        "river_danube",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code_and_err(&o).0, 0);
    assert_eq!(
        count(&open(&out), "skeletons"),
        count(&open(std::path::Path::new(TRAIN)), "river_danube")
    );
}

#[test]
fn overwrite_flag_replaces_an_output_but_never_the_input() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    std::fs::write(&out, b"precious").unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec!["run", "-i", DEMO, "-o", out.to_str().unwrap()];
        a.extend_from_slice(extra);
        skeletonise(&a.iter().map(|s| &**s).collect::<Vec<_>>())
    };
    let (code, err) = code_and_err(&args(&[]));
    assert_eq!(code, 1);
    assert!(err.contains("--overwrite"), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
    let (code, err) = code_and_err(&args(&["--overwrite"]));
    assert_eq!(code, 0, "{err}");
    assert_eq!(count(&open(&out), "skeletons"), 17);
    // `--overwrite` never makes the input a target.
    let input = d.path().join("in.gpkg");
    std::fs::copy(DEMO, &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let o = skeletonise(&[
        "run",
        "-i",
        input.to_str().unwrap(),
        "-o",
        input.to_str().unwrap(),
        "--overwrite",
    ]);
    let (code, err) = code_and_err(&o);
    assert_ne!(code, 0);
    assert!(err.contains("input"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
}
