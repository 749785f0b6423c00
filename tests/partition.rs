//! The `partition` step from the command line: its pipeline file's rules
//! (located errors, exit code 78, nothing written) and a run on a training
//! river with its generated coverage (`tests/data/coverage-train.gpkg`):
//! every unit written once, in FID order, those that received nothing bit
//! for bit, the summary line. The geometric checks — a valid coverage
//! (GEOS), conserved area, nearest banks, centred boundaries, the
//! constructed cases — are in `python/tests/test_partition.py`, which has
//! GEOS's coverage validation at hand.

mod common;
use common::{code_and_err, first_text, ints, open, pipeline, reals, skeletonise, tmp, wkts};
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
