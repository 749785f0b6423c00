//! The `partition` step from the command line: its pipeline file's rules
//! (located errors, exit code 78, nothing written) and a run on a training
//! river with its generated coverage (`tests/data/coverage-train.gpkg`):
//! every unit written once, in FID order, those that received nothing bit
//! for bit, the summary line. The geometric checks — a valid coverage
//! (GEOS), conserved area, nearest banks, centred boundaries, the
//! constructed cases — are in `python/tests/test_partition.py`, which has
//! GEOS's coverage validation at hand.

use crate::common::{
    code_and_err, first_text, ints, open, pipeline, reals, skeletonise, tmp, wkts,
};
use gdal::vector::LayerAccess;

const COVERAGE: &str = "tests/data/coverage-train.gpkg";

/// A pipeline on the Danube reaches with `input.neighbours` (when
/// `neighbours`) and `steps`.
fn danube(
    dir: &std::path::Path,
    neighbours: bool,
    steps: &str,
) -> (std::path::PathBuf, std::path::PathBuf) {
    let out = dir.join("o.gpkg");
    let n = if neighbours {
        format!("\n  neighbours: {{ source: {COVERAGE}, layer: units_danube }}")
    } else {
        String::new()
    };
    let text = format!(
        "input:\n  source: {COVERAGE}\n  layer: rivers_danube{n}\nsteps:\n{steps}output: {{ path: {} }}\n",
        out.display()
    );
    (pipeline(dir, "p.yaml", &text), out)
}

#[test]
fn the_pipeline_files_rules_are_located_and_refused_before_anything_runs() {
    let dir = tmp();
    let cases = [
        (
            false,
            "  - skeleton: { methods: [MA] }\n  - partition: {}\n",
            "steps[1].partition",
            "add `input.neighbours",
        ),
        (
            true,
            "  - skeleton: { methods: [MA] }\n",
            "input.neighbours",
            "add `- partition: {}`",
        ),
        (
            true,
            "  - skeleton: { methods: [MA] }\n  - collapse: { width: 100 }\n  - partition: {}\n",
            "partition",
            "not both",
        ),
        (
            true,
            "  - skeleton: { methods: [CDT] }\n  - partition: { width: 100 }\n",
            "steps[1].partition.width",
            "add MA",
        ),
        (
            true,
            "  - skeleton: { methods: [MA] }\n  - partition: { min_length: 10 }\n",
            "steps[1].partition.width",
            "give `width` too",
        ),
        (
            true,
            "  - skeleton: { methods: [MA] }\n  - partition: { width: -1 }\n",
            "steps[1].partition.width",
            "positive",
        ),
        (
            true,
            "  - skeleton: { methods: [MA] }\n  - partition: { unowned: sea }\n",
            "unowned",
            "keep",
        ),
    ];
    for (neighbours, steps, key, text) in cases {
        let (p, out) = danube(dir.path(), neighbours, steps);
        for cmd in ["validate", "run"] {
            let (code, err) = code_and_err(&skeletonise(&[cmd, p.to_str().unwrap()]));
            assert_eq!(code, 78, "{cmd} {steps}: {err}");
            assert!(err.contains(key) && err.contains(text), "{steps}: {err}");
            assert!(!out.exists());
        }
    }
}

#[test]
fn a_missing_neighbours_layer_is_named_with_the_layers_there_are() {
    let dir = tmp();
    let out = dir.path().join("o.gpkg");
    let text = format!(
        "input:\n  source: {COVERAGE}\n  layer: rivers_danube\n  neighbours: {{ source: {COVERAGE}, layer: units_rhine }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - partition: {{}}\noutput: {{ path: {} }}\n",
        out.display()
    );
    let p = pipeline(dir.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("units_rhine") && err.contains("units_danube"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn every_unit_is_written_once_in_fid_order_and_those_that_received_nothing_bit_for_bit() {
    let dir = tmp();
    let (p, out) = danube(
        dir.path(),
        true,
        "  - skeleton: { methods: [MA] }\n  - prune: {}\n  - extend: {}\n  - partition: {}\n",
    );
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 0, "{err}");
    let src = open(std::path::Path::new(COVERAGE));
    let ds = open(&out);
    let mut units = src.layer_by_name("units_danube").unwrap();
    let input: Vec<(u64, Vec<u8>)> = units
        .features()
        .map(|f| (f.fid().unwrap(), f.geometry().unwrap().wkb().unwrap()))
        .collect();
    let fids = ints(&ds, "coverage", "src_fid");
    let received = reals(&ds, "coverage", "received");
    let mut cov = ds.layer_by_name("coverage").unwrap();
    let written: Vec<(u64, f64, gdal::vector::Geometry)> = cov
        .features()
        .zip(fids.iter().zip(&received))
        .map(|(f, (fid, r))| {
            (
                fid.unwrap() as u64,
                r.unwrap(),
                f.geometry().unwrap().clone(),
            )
        })
        .collect();
    assert_eq!(
        written.iter().map(|w| w.0).collect::<Vec<_>>(),
        input.iter().map(|i| i.0).collect::<Vec<_>>()
    );
    let mut grown = 0;
    for ((_, received, g), (_, wkb)) in written.iter().zip(&input) {
        if *received == 0.0 {
            assert_eq!(&g.wkb().unwrap(), wkb);
        } else {
            grown += 1;
        }
    }
    assert!(grown > 10, "{grown}");
    assert!(
        err.contains(&format!("partition: {grown} of {} units grew", input.len())),
        "{err}"
    );
    // One boundaries row per pair of units, with both FIDs.
    assert!(!wkts(&ds, "boundaries").is_empty());
    // The step's own time is in the run record.
    let stages = first_text(&ds, "SELECT stage_seconds FROM skeletonise_runs").unwrap();
    assert!(stages.contains("\"partition\":"), "{stages}");
}

#[test]
fn the_neighbours_source_is_never_the_output() {
    // As a path and through a hard link: refused before any work, the
    // coverage left as it was.
    let dir = tmp();
    let units = dir.path().join("units.gpkg");
    std::fs::copy(COVERAGE, &units).unwrap();
    let link = dir.path().join("link.gpkg");
    std::fs::hard_link(&units, &link).unwrap();
    let before = std::fs::read(&units).unwrap();
    for out in [&units, &link] {
        let text = format!(
            "input:\n  source: {COVERAGE}\n  layer: rivers_danube\n  neighbours: {{ source: {}, layer: units_danube }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - partition: {{}}\noutput: {{ path: {}, overwrite: true }}\n",
            units.display(),
            out.display()
        );
        let p = pipeline(dir.path(), "p.yaml", &text);
        for cmd in ["validate", "run"] {
            let (code, err) = code_and_err(&skeletonise(&[cmd, p.to_str().unwrap()]));
            assert_eq!(code, 1, "{cmd}: {err}");
            assert!(err.contains("neighbours source"), "{err}");
        }
        assert_eq!(std::fs::read(&units).unwrap(), before);
    }
}

const BORDER: &str = "tests/data/border-waters.gpkg";

/// The areas of the `coverage` rows of a partition run on a real border
/// water of `tests/data/border-waters.gpkg`, with the units of `units`,
/// and the run's stderr.
fn border_run(dir: &std::path::Path, water: &str, units: &str) -> (Vec<f64>, String) {
    let out = dir.join(format!("{units}.gpkg"));
    let (code, err) = code_and_err(&skeletonise(&[
        "run",
        "pipelines/partition-border-waters.yaml",
        "--set",
        &format!("input.source={BORDER}"),
        "--set",
        &format!("input.neighbours.source={BORDER}"),
        "--set",
        &format!("input.layer={water}"),
        "--set",
        &format!("input.neighbours.layer={units}"),
        "-o",
        out.to_str().unwrap(),
    ]));
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    assert!(
        ds.layer_by_name("rejected").is_err() || crate::common::count(&ds, "rejected") == 0,
        "{err}"
    );
    let mut cov = ds.layer_by_name("coverage").unwrap();
    let areas = cov
        .features()
        .map(|f| f.geometry().map_or(0.0, |g| g.area()))
        .collect();
    (areas, err)
}

#[test]
fn units_that_cover_a_real_lake_are_cut_and_the_same_in_longitude_latitude() {
    // Switzerland and France (DCW) around Lake Geneva (GSHHG): the border
    // runs inside the lake, the countries' coasts are not its shore.
    let dir = tmp();
    let (utm, err) = border_run(dir.path(), "waters_geneva", "units_geneva");
    assert!(err.contains("units held"), "{err}");
    let out = open(&dir.path().join("units_geneva.gpkg"));
    let held: f64 = reals(&out, "given", "held").iter().flatten().sum();
    let given: f64 = reals(&out, "given", "area").iter().flatten().sum();
    // The lake is 538 km²: held before (but for slivers of it outside both
    // countries), given again whole.
    assert!((given - 538.2e6).abs() < 0.1e6, "{given}");
    assert!(
        held <= given * (1.0 + 1e-9) && held > 0.99 * given,
        "{given} {held}"
    );
    assert!(reals(&out, "coverage", "held")
        .iter()
        .all(|h| h.unwrap() > 0.0));
    let (lonlat, _) = border_run(dir.path(), "waters_geneva", "units_geneva_4326");
    assert_eq!(utm.len(), lonlat.len());
    for (a, b) in utm.iter().zip(&lonlat) {
        assert!((a - b).abs() <= 1e-6 * a, "{a} {b}");
    }
}

#[test]
fn a_unit_with_a_nan_coordinate_is_named_and_nothing_panics() {
    let dir = tmp();
    let src = dir.path().join("case.gpkg");
    crate::common::make_layer(
        &src,
        "rivers",
        3857,
        &[Some("POLYGON((0 0,100 0,100 10,0 10,0 0))")],
    );
    crate::common::make_layer(
        &src,
        "units",
        3857,
        &[
            Some("POLYGON((0 -20,100 -20,100 0,0 0,0 -20))"),
            Some("POLYGON((0 10,100 10,100 30,7 30,0 10))"),
        ],
    );
    // The second unit's 7 made NaN (WKT has no NaN): an UPDATE of its WKB.
    let mut wkb: Vec<u8> = vec![1, 3, 0, 0, 0, 1, 0, 0, 0, 5, 0, 0, 0];
    for (x, y) in [
        (0.0, 10.0),
        (100.0, 10.0),
        (100.0, 30.0),
        (f64::NAN, 30.0),
        (0.0, 10.0),
    ] {
        wkb.extend(f64::to_le_bytes(x));
        wkb.extend(f64::to_le_bytes(y));
    }
    {
        let ds = gdal::Dataset::open_ex(
            &src,
            gdal::DatasetOptions {
                open_flags: gdal::GdalOpenFlags::GDAL_OF_UPDATE
                    | gdal::GdalOpenFlags::GDAL_OF_VECTOR,
                ..Default::default()
            },
        )
        .unwrap();
        let l = ds.layer_by_name("units").unwrap();
        let mut f = l.feature(2).unwrap();
        f.set_geometry(gdal::vector::Geometry::from_wkb(&wkb).unwrap())
            .unwrap();
        l.set_feature(f).unwrap();
    }
    let out = dir.path().join("o.gpkg");
    let text = format!(
        "input: {{ source: {s}, layer: rivers, neighbours: {{ source: {s}, layer: units }} }}\nsteps: [ {{ skeleton: {{ methods: [MA] }} }}, {{ partition: {{}} }} ]\noutput: {{ path: {} }}\n",
        out.display(),
        s = src.display()
    );
    let p = pipeline(dir.path(), "p.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["run", p.to_str().unwrap()]));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("feature 2 has a coordinate that is not a finite number"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_negative_snap_is_refused_with_its_key_before_anything_runs() {
    let dir = tmp();
    let (p, out) = danube(
        dir.path(),
        true,
        "  - skeleton: { methods: [MA] }\n  - partition: {}\n",
    );
    for cmd in ["validate", "run"] {
        let (code, err) = code_and_err(&skeletonise(&[
            cmd,
            p.to_str().unwrap(),
            "--set",
            "input.neighbours.snap=-1",
        ]));
        assert_eq!(code, 78, "{cmd}: {err}");
        assert!(
            err.contains("input.neighbours.snap") && err.contains("snap must be ≥ 0"),
            "{err}"
        );
    }
    assert!(!out.exists());
}
