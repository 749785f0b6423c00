//! A new step is one module and one registration line: a deliberately
//! trivial `toy` step — its own option (`scale`), its own layer (`toy`)
//! and column (`scaled_length`: the chosen skeleton's length times the
//! option) — runs through the pipeline file, its validation and `--set`,
//! the run the binary makes (`pipeline::run`: the GeoPackage) and the
//! table the Python package builds (`output::columns`).

use crate::common::{open, reals, tmp, DEMO};
use gdal::vector::LayerAccess;
use skeletonise::output::{
    columns::{columns, Item, Values},
    Cell, ColumnType, GeometryKind, Rows, StepLayer, StepRow,
};
use skeletonise::process::step::{FeatureStep, StepEntry, StepInput};

/// The module of the toy step: everything it is, in one place.
mod toy {
    use super::*;
    use geo::{Euclidean, Length};

    /// Its options.
    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Options {
        scale: f64,
    }

    /// The step.
    #[derive(Debug)]
    struct Toy(f64);

    impl FeatureStep for Toy {
        fn rows(&self, input: &StepInput<'_>) -> Vec<(&'static str, StepRow)> {
            let (_, chosen) = input.outcome.chosen();
            let length: f64 = chosen.geometry.0.iter().map(|l| Euclidean.length(l)).sum();
            vec![(
                "toy",
                StepRow {
                    geometry: Some(geo::Geometry::MultiLineString(chosen.geometry.clone())),
                    cells: vec![Cell::Real(self.0 * length)],
                },
            )]
        }
    }

    /// Its layer.
    pub const LAYERS: &[StepLayer] = &[StepLayer {
        name: "toy",
        geometry: GeometryKind::MultiLineString,
        attributes: true,
        columns: &[("scaled_length", ColumnType::Real)],
    }];

    /// Its registry entry.
    pub const ENTRY: StepEntry = StepEntry {
        name: "toy",
        after: "select",
        description: "the chosen skeleton's length times `scale` (a test step)",
        options: &[("scale", "the factor")],
        layers: LAYERS,
        build: |v| {
            let o: Options =
                serde_json::from_value(v.clone()).map_err(|e| (String::new(), e.to_string()))?;
            if !(o.scale.is_finite() && o.scale > 0.0) {
                return Err(("scale".into(), "scale must be a positive number".into()));
            }
            Ok(std::sync::Arc::new(Toy(o.scale)))
        },
    };
}

fn pipeline_text(out: &std::path::Path, toy: &str) -> String {
    format!(
        "input: {{ source: {}, layer: demo }}\nsteps:\n  - skeleton: {{ methods: [MA, CDT] }}\n  - prune: {{}}\n  - extend: {{}}\n  - score: {{}}\n  - select: {{}}\n{toy}output: {{ path: {}, overwrite: true }}\n",
        crate::common::root(DEMO),
        out.display()
    )
}

#[test]
fn a_registered_step_writes_its_own_layer_through_the_run_and_the_python_table() {
    let registry = skeletonise::config::builtin_steps().with(toy::ENTRY);
    let d = tmp();
    let out = d.path().join("toy.gpkg");
    let text = pipeline_text(&out, "  - toy: { scale: 2 }\n");
    let p = skeletonise::config::load_str_with(
        &text,
        "toy.yaml",
        &["steps.toy.scale=3".into()],
        &registry,
    )
    .unwrap();
    let s = skeletonise::pipeline::run(&p, &skeletonise::pipeline::RunOptions::default()).unwrap();
    assert_eq!((s.read, s.written), (17, 17));
    // The GeoPackage: one `toy` row per feature, the source fields kept,
    // `scaled_length` three times (the override) the skeleton's length.
    let ds = open(&out);
    let layer = ds.layer_by_name("toy").unwrap();
    let fields: Vec<String> = layer.defn().fields().map(|f| f.name()).collect();
    assert!(
        fields.contains(&"kind".to_string())
            && fields.ends_with(&["src_fid".into(), "scaled_length".into()]),
        "{fields:?}"
    );
    let scaled = reals(&ds, "toy", "scaled_length");
    let fids = crate::common::ints(&ds, "toy", "src_fid");
    assert_eq!(scaled.len(), 17);
    let mut l = ds.layer_by_name("skeletons").unwrap();
    let at = l.defn().field_index("src_fid").unwrap();
    let lengths: Vec<(i64, f64)> = l
        .features()
        .map(|f| {
            (
                f.field_as_integer64(at).unwrap().unwrap(),
                f.geometry().unwrap().length(),
            )
        })
        .collect();
    for ((fid, len), (tf, ts)) in lengths.iter().zip(fids.iter().zip(&scaled)) {
        assert_eq!(Some(*fid), *tf);
        assert!(
            (ts.unwrap() - 3.0 * len).abs() < 1e-6 * len,
            "{fid}: {ts:?} vs 3 × {len}"
        );
    }
    // The same rows as the Python package's table: the per-feature path
    // in memory, the layer's columns from the plan.
    let plan = p.plan();
    let params = p.process_params();
    let features = skeletonise::io::reader::Reader::open(&p.file.input).unwrap();
    let mut all = Vec::new();
    let mut reader = features;
    reader
        .read::<skeletonise::io::IoError>(64, true, |b| {
            all.extend(b);
            Ok(())
        })
        .unwrap();
    let mut rows = Rows::default();
    for f in &all {
        let r = skeletonise::process::feature_rows(
            f,
            skeletonise::process::Skeletons::Computed,
            &params,
            skeletonise::process::RowOptions::of(&plan),
        );
        rows.append(r.rows);
    }
    let layer = plan
        .layers()
        .into_iter()
        .find(|l| l.name() == "toy")
        .expect("the plan has the toy layer");
    let items: Vec<Item> = (0..layer.count(&rows)).map(Item::Row).collect();
    let table = columns(layer, &plan, &rows, &items);
    let names: Vec<&str> = table.iter().map(|c| c.name).collect();
    assert_eq!(names, ["src_fid", "scaled_length"]);
    let Values::Real(v) = &table[1].values else {
        panic!("a real column")
    };
    let from_gpkg: Vec<f64> = scaled.iter().map(|x| x.unwrap()).collect();
    assert_eq!(v, &from_gpkg);
}

#[test]
fn a_registered_steps_options_and_place_are_checked_like_the_others() {
    let registry = skeletonise::config::builtin_steps().with(toy::ENTRY);
    let d = tmp();
    let out = d.path().join("toy.gpkg");
    let load = |toy: &str| {
        skeletonise::config::load_str_with(&pipeline_text(&out, toy), "toy.yaml", &[], &registry)
    };
    let e = load("  - toy: { scael: 2 }\n").unwrap_err();
    assert_eq!(
        (e.key.as_str(), e.position),
        ("steps[5].toy.scael", Some((8, 12))),
        "{e}"
    );
    assert!(e.message.contains("unknown field `scael`"), "{e}");
    let e = load("  - toy: { scale: -1 }\n").unwrap_err();
    assert_eq!(e.key, "steps[5].toy.scale", "{e}");
    // Before `select`, which it runs after.
    let text = pipeline_text(&out, "").replace(
        "  - select: {}\n",
        "  - toy: { scale: 1 }\n  - select: {}\n",
    );
    let e = skeletonise::config::load_str_with(&text, "toy.yaml", &[], &registry).unwrap_err();
    assert!(e.message.contains("must come before"), "{e}");
    // Without the entry the step is unknown, as any misspelt step.
    let e = skeletonise::config::load_str(
        &pipeline_text(&out, "  - toy: { scale: 2 }\n"),
        "toy.yaml",
        &[],
    )
    .unwrap_err();
    assert!(e.message.contains("unknown variant `toy`"), "{e}");
    // `skeletonise methods` lists it with its option.
    let d =
        skeletonise::config::describe_with(&skeletonise::methods::Registry::builtin(), &registry);
    assert!(d.contains("toy") && d.contains("scale"), "{d}");
}
