//! The README's example of the demo's output is generated from the real
//! output, so that it cannot drift: this test runs the demo pipeline and
//! compares the block between the README's `demo-rows` markers with what
//! the GeoPackage holds. `SKELETONISE_UPDATE_README=1 cargo test --test
//! readme` writes the block instead.

use crate::common::*;
use gdal::vector::LayerAccess;

const BEGIN: &str = "<!-- demo-rows: made by tests/all/readme.rs from out/demo.gpkg (SKELETONISE_UPDATE_README=1 cargo test --test all readme:: writes it) -->";
const END: &str = "<!-- /demo-rows -->";

/// The example block: the layers, then the first rows of `skeletons`.
fn block(out: &std::path::Path) -> String {
    let ds = open(out);
    let layers: Vec<String> = ds
        .layers()
        .map(|l| {
            let ty = l.defn().geom_fields().next().map(|g| g.field_type());
            let kind = match ty.map(gdal::vector::geometry_type_to_name) {
                Some(n) if n != "Unknown (any)" => format!(" ({n})"),
                _ => String::new(),
            };
            format!("{}{kind}", l.name())
        })
        .collect();
    let mut text = format!("layers: {}\n\n", layers.join(", "));
    let fids = ints(&ds, "skeletons", "src_fid");
    let kinds = strings(&ds, "skeletons", "kind");
    let methods = strings(&ds, "skeletons", "method");
    let bars = ints(&ds, "skeletons", "bars");
    let hits = ints(&ds, "skeletons", "hits");
    let cov = reals(&ds, "skeletons", "coverage");
    let dev = reals(&ds, "skeletons", "deviation");
    let z = reals(&ds, "skeletons", "distortion");
    let legs = ints(&ds, "skeletons", "legs");
    for i in 0..4 {
        text.push_str(&format!(
            "src_fid = {:<3} kind = {:<7} method = {:<5} bars = {:<4} hits = {:<4} coverage = {:.3}, deviation = {:<6} distortion = {:.5}, legs = {}\n",
            format!("{},", fids[i].unwrap()),
            format!("{},", kinds[i].as_deref().unwrap_or("")),
            format!("{},", methods[i].as_deref().unwrap_or("")),
            format!("{},", bars[i].unwrap()),
            format!("{},", hits[i].unwrap()),
            cov[i].unwrap(),
            format!("{:.2},", dev[i].unwrap()),
            z[i].unwrap(),
            legs[i].unwrap()
        ));
    }
    text
}

#[test]
fn the_readme_shows_the_demos_real_rows() {
    let d = tmp();
    let out = d.path().join("demo.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.report=null",
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let want = format!("{BEGIN}\n```\n{}```\n{END}", block(&out));
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let (a, b) = (
        readme.find(BEGIN).expect("the README has the markers"),
        readme.find(END).expect("the end marker"),
    );
    let have = &readme[a..b + END.len()];
    if have != want && std::env::var_os("SKELETONISE_UPDATE_README").is_some() {
        std::fs::write(&path, readme.replace(have, &want)).unwrap();
        return;
    }
    assert_eq!(have, want, "the README's demo rows are not the demo's output: SKELETONISE_UPDATE_README=1 cargo test --test all readme:: writes them");
}
