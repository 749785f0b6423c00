//! The outputs of every pipeline in `pipelines/` and of `skeletonise score`
//! on the training data, fingerprinted: a change to what any of them writes
//! fails here. The fingerprints in `tests/golden.txt` come from the real
//! binary; after an intended change of the output, regenerate them with
//! `SKELETONISE_BLESS=1 cargo test --test all golden::` and say why in the commit.

use crate::common::{canonical, fingerprint, root, skeletonise, tmp, TRAIN};
use std::collections::BTreeMap;

/// Every run: its name and its command-line arguments (the output is added).
fn runs() -> Vec<(String, Vec<String>)> {
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let mut runs = vec![
        ("demo".to_string(), s(&["run", "pipelines/demo.yaml"])),
        ("islands".to_string(), s(&["run", "pipelines/islands.yaml"])),
    ];
    for l in ["river_lena", "river_st_lawrence", "river_danube"] {
        runs.push((
            format!("rivers-{l}"),
            s(&[
                "run",
                "pipelines/rivers.yaml",
                "--set",
                &format!("input.layer={l}"),
            ]),
        ));
    }
    for l in crate::common::LAYERS {
        runs.push((
            format!("compare-{l}"),
            s(&[
                "run",
                "pipelines/compare-methods.yaml",
                "--set",
                &format!("input.layer={l}"),
                "--set",
                "output.bars=true",
                "--set",
                "output.widths=true",
            ]),
        ));
    }
    runs.push((
        "compare-explode".into(),
        s(&[
            "run",
            "pipelines/compare-methods.yaml",
            "--set",
            "input.layer=river_lena",
            "--set",
            "output.explode=true",
        ]),
    ));
    runs
}

fn golden_path() -> String {
    root("tests/golden.txt")
}

#[test]
fn every_pipeline_and_score_writes_what_it_wrote_before() {
    let dir = tmp();
    let mut got: BTreeMap<String, String> = BTreeMap::new();
    for (name, mut args) in runs() {
        let out = dir.path().join(format!("{name}.gpkg"));
        args.extend(["-o".into(), out.display().to_string(), "-q".into()]);
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = skeletonise(&argv);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let c = canonical(&out);
        got.insert(
            name,
            format!("{:016x} {}", fingerprint(&c), c.lines().count()),
        );
    }
    // `score` on the demo run's own skeletons, joined by src_fid.
    let out = dir.path().join("score.gpkg");
    let demo = dir.path().join("demo.gpkg");
    let o = skeletonise(&[
        "score",
        "--polygons",
        "examples/data/demo.gpkg",
        "--skeletons",
        demo.to_str().unwrap(),
        "--skeletons-layer",
        "skeletons",
        "--skeleton-key",
        "src_fid",
        "--label",
        "demo",
        "--bars",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(
        o.status.success(),
        "score: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let c = canonical(&out);
    got.insert(
        "score".into(),
        format!("{:016x} {}", fingerprint(&c), c.lines().count()),
    );
    let text: String = got.iter().map(|(k, v)| format!("{k} {v}\n")).collect();
    if std::env::var_os("SKELETONISE_BLESS").is_some() {
        std::fs::write(golden_path(), &text).unwrap();
        return;
    }
    let want = std::fs::read_to_string(golden_path()).expect("tests/golden.txt");
    let _ = TRAIN;
    assert_eq!(
        text, want,
        "outputs changed; if intended, regenerate with SKELETONISE_BLESS=1 cargo test --test all golden::"
    );
}
