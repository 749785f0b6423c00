//! A new step is one module and one registration line: a deliberately
//! trivial `toy` step — its own options (`scale`, and `near`: a side input
//! layer), its own layers (`toy`, with the chosen skeleton as geometry and
//! `scaled_length`, the skeleton's length times the option, and `near`, the
//! side layer's features whose boxes meet the polygon's; `toy_total`, one
//! row made after the last feature), a reason to reject a feature
//! (`max_length`) and one to stop the run after the last feature
//! (`min_total`) — runs through the pipeline file, its
//! JSON Schema, validation and `--set`, the run the binary makes
//! (`pipeline::run`: the GeoPackage) and the run driver the Python package
//! uses (`process::Run`, `output::columns`).

use crate::common::{open, reals, tmp, DEMO};
use gdal::vector::LayerAccess;
use skeletonise::output::{
    columns::{columns, Item, Values},
    Cell, ColumnType, GeometryKind, Rows, StepLayer, StepRow,
};
use skeletonise::process::step::{FeatureStep, FinishInput, Needs, StepEntry, StepInput, StepRows};

/// The module of the toy step: everything it is, in one place.
mod toy {
    use super::*;
    use geo::{BoundingRect, Euclidean, Length};

    /// Its options.
    #[derive(Debug, serde::Deserialize, schemars::JsonSchema)]
    #[serde(deny_unknown_fields)]
    pub struct Options {
        /// The factor.
        scale: f64,
        /// A layer whose features near each polygon are counted (read by
        /// the run, which hands it to the step: `Needs::side`).
        #[serde(default)]
        #[allow(dead_code)]
        near: Option<skeletonise::config::LayerSource>,
        /// A feature whose skeleton is longer is rejected.
        #[serde(default)]
        max_length: Option<f64>,
        /// The run fails when the scaled lengths sum to less.
        #[serde(default)]
        min_total: Option<f64>,
    }

    /// The step.
    #[derive(Debug)]
    struct Toy(Options);

    impl FeatureStep for Toy {
        fn rows(&self, input: &StepInput<'_>) -> StepRows {
            let (_, chosen) = input.outcome.chosen();
            let length: f64 = chosen.geometry.0.iter().map(|l| Euclidean.length(l)).sum();
            if let Some(max) = self.0.max_length.filter(|&m| length > m) {
                return Err(format!(
                    "the skeleton is {length:.0} m long, over `max_length` ({max} m): raise it"
                )
                .into());
            }
            let near = match (input.side, input.parts.first()) {
                (Some(side), Some(p)) => {
                    let rect = p.polygon().bounding_rect().expect("a polygon has a box");
                    Cell::Int(side.near(rect).len() as i64)
                }
                _ => Cell::Null,
            };
            Ok(vec![(
                "toy",
                StepRow {
                    geometry: Some(geo::Geometry::MultiLineString(chosen.geometry.clone())),
                    cells: vec![
                        ("scaled_length", Cell::Real(self.0.scale * length)),
                        ("near", near),
                    ],
                },
            )])
        }

        fn finish(&self, input: &FinishInput<'_>) -> StepRows {
            let total: f64 = input
                .rows
                .iter()
                .filter_map(|(_, _, r)| match r.cell("scaled_length") {
                    Cell::Real(x) => Some(x),
                    _ => None,
                })
                .sum();
            let side = input
                .side
                .map_or(Cell::Null, |s| Cell::Int(s.features().len() as i64));
            if let Some(min) = self.0.min_total.filter(|&m| total < m) {
                return Err(format!(
                    "the lengths sum to {total:.0} m, under `min_total` ({min} m)"
                )
                .into());
            }
            let cells = vec![
                ("features", Cell::Int(input.rows.len() as i64)),
                ("scaled_length", Cell::Real(total)),
                ("side_features", side),
            ];
            Ok(vec![(
                "toy_total",
                StepRow {
                    geometry: None,
                    cells,
                },
            )])
        }
    }

    /// Its layers.
    pub const LAYERS: &[StepLayer] = &[
        StepLayer {
            name: "toy",
            geometry: GeometryKind::MultiLineString,
            fields: Some(skeletonise::layer::Fields::Input),
            columns: &[
                ("scaled_length", ColumnType::Real),
                ("near", ColumnType::Int32),
            ],
        },
        StepLayer {
            name: "toy_total",
            geometry: GeometryKind::None,
            fields: None,
            columns: &[
                ("features", ColumnType::Int32),
                ("scaled_length", ColumnType::Real),
                ("side_features", ColumnType::Int32),
            ],
        },
    ];

    /// Its registry entry.
    pub const ENTRY: StepEntry = StepEntry {
        name: "toy",
        after: "select",
        description: "the chosen skeleton's length times `scale` (a test step)",
        schema: || schemars::schema_for!(Options),
        needs: Needs {
            medial_axis: false,
            lonlat: false,
            side: Some("near"),
            finish: true,
            ..Needs::NOTHING
        },
        layers: LAYERS,
        build: |v| {
            let o: Options = skeletonise::process::step::step_options(v)?;
            if !(o.scale.is_finite() && o.scale > 0.0) {
                return Err(("scale".into(), "scale must be a positive number".into()));
            }
            Ok(std::sync::Arc::new(Toy(o)))
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

/// The boxes of the demo's lakes.
fn demo_boxes() -> Vec<geo::Rect<f64>> {
    use geo::BoundingRect;
    let ds = open(std::path::Path::new(&crate::common::root(DEMO)));
    let mut l = ds.layer_by_name("demo").unwrap();
    l.set_attribute_filter("kind = 'lake'").unwrap();
    l.features()
        .map(|f| {
            let g: geo::Geometry<f64> = f.geometry().unwrap().to_geo().unwrap();
            g.bounding_rect().unwrap()
        })
        .collect()
}

/// Every feature of the pipeline's input, as the reader gives them.
fn features(p: &skeletonise::config::Pipeline) -> Vec<skeletonise::feature::Feature> {
    let mut reader = skeletonise::io::reader::Reader::open(&p.file.input).unwrap();
    let mut all = Vec::new();
    reader
        .read::<skeletonise::io::IoError>(64, true, |b| {
            all.extend(b);
            Ok(())
        })
        .unwrap();
    all
}

#[test]
fn a_registered_step_writes_its_own_layers_through_the_run_and_the_python_table() {
    let registry = skeletonise::config::builtin_steps().with(toy::ENTRY);
    let d = tmp();
    let out = d.path().join("toy.gpkg");
    let near = format!(
        "{{ source: {}, layer: demo, where: \"kind = 'lake'\" }}",
        crate::common::root(DEMO)
    );
    let text = pipeline_text(&out, &format!("  - toy: {{ scale: 2, near: {near} }}\n"));
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
            && fields.ends_with(&["src_fid".into(), "scaled_length".into(), "near".into()]),
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
    // The side input: read with its own `where`, each feature given the
    // number of those features whose boxes meet its own.
    use geo::Intersects;
    let boxes = demo_boxes();
    assert_eq!(boxes.len(), 4);
    let mut demo = ds.layer_by_name("toy").unwrap();
    let near_at = demo.defn().field_index("near").unwrap();
    let near: Vec<i64> = demo
        .features()
        .map(|f| f.field_as_integer64(near_at).unwrap().unwrap())
        .collect();
    let src = open(std::path::Path::new(&crate::common::root(DEMO)));
    let mut srcl = src.layer_by_name("demo").unwrap();
    let expected: Vec<i64> = srcl
        .features()
        .map(|f| {
            use geo::BoundingRect;
            let g: geo::Geometry<f64> = f.geometry().unwrap().to_geo().unwrap();
            let r = g.bounding_rect().unwrap();
            boxes.iter().filter(|b| b.intersects(&r)).count() as i64
        })
        .collect();
    assert_eq!(near, expected);
    assert!(near.contains(&0) && near.iter().any(|&n| n > 0), "{near:?}");
    // The finish: one row after the last feature, from every feature's rows
    // and the side input, without source fields.
    let total = ds.layer_by_name("toy_total").unwrap();
    let fields: Vec<String> = total.defn().fields().map(|f| f.name()).collect();
    assert_eq!(
        fields,
        ["src_fid", "features", "scaled_length", "side_features"]
    );
    assert_eq!(
        crate::common::ints(&ds, "toy_total", "features"),
        [Some(17)]
    );
    assert_eq!(
        crate::common::ints(&ds, "toy_total", "side_features"),
        [Some(4)]
    );
    assert_eq!(crate::common::ints(&ds, "toy_total", "src_fid"), [None]);
    let sum: f64 = scaled.iter().map(|x| x.unwrap()).sum();
    let t = reals(&ds, "toy_total", "scaled_length")[0].unwrap();
    assert!((t - sum).abs() < 1e-9 * sum, "{t} vs {sum}");
    // The same rows through the run driver the Python package uses: the
    // per-feature path in memory, `Run` (its finish included), the
    // layers' columns from the plan.
    let plan = p.plan();
    let mut params = p.process_params();
    params.extra[0].side = Some(std::sync::Arc::new(
        skeletonise::process::step::SideLayer::new(Vec::new()),
    ));
    let all = features(&p);
    let mut run = skeletonise::process::Run::new(&params, false);
    let mut rows = Rows::default();
    for f in &all {
        let r = skeletonise::process::feature_rows(
            f,
            skeletonise::process::Skeletons::Computed,
            &params,
            skeletonise::process::RowOptions::of(&plan),
        );
        rows.append(run.add(f, r).unwrap());
    }
    rows.append(run.finish().unwrap().0);
    let table = |name: &str| {
        let layer = plan
            .layers()
            .into_iter()
            .find(|l| l.name() == name)
            .expect("the plan has the toy's layers");
        let items: Vec<Item> = (0..layer.count(&rows)).map(Item::Row).collect();
        columns(layer, &plan, &rows, &items)
    };
    let toy = table("toy");
    let names: Vec<&str> = toy.iter().map(|c| c.name).collect();
    assert_eq!(names, ["src_fid", "scaled_length", "near"]);
    let Values::Real(v) = &toy[1].values else {
        panic!("a real column")
    };
    let from_gpkg: Vec<f64> = scaled.iter().map(|x| x.unwrap()).collect();
    assert_eq!(v, &from_gpkg);
    // Here the side layer given was empty: no feature has one near.
    let Values::Int(n, null) = &toy[2].values else {
        panic!("an integer column")
    };
    assert!(n.iter().all(|x| *x == 0) && !null.contains(&true), "{n:?}");
    let total = table("toy_total");
    let Values::Int(side, _) = &total[3].values else {
        panic!("an integer column")
    };
    assert_eq!(side, &[0]);
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
    // `skeletonise methods` lists it with its options, from its schema.
    let d =
        skeletonise::config::describe_with(&skeletonise::methods::Registry::builtin(), &registry);
    assert!(
        d.contains("toy") && d.contains("scale") && d.contains("The factor."),
        "{d}"
    );
    // The pipeline file's JSON Schema has it as a step, after `select`.
    let schema = skeletonise::config::json_schema_with(&registry);
    let steps = schema["$defs"]["Step"]["oneOf"].as_array().unwrap();
    let at = |name: &str| {
        steps
            .iter()
            .position(|s| s["properties"].get(name).is_some())
            .unwrap()
    };
    assert_eq!(at("toy"), at("select") + 1);
    let options = &schema["$defs"]["toy_options"];
    assert_eq!(options["required"], serde_json::json!(["scale"]));
    assert!(
        options["properties"]["near"]
            .to_string()
            .contains("LayerSource"),
        "{options}"
    );
    // A side input that is not there: the run says which key to fix.
    let text = pipeline_text(
        &out,
        &format!(
            "  - toy: {{ scale: 1, near: {{ source: {}, layer: nope }} }}\n",
            crate::common::root(DEMO)
        ),
    );
    let p = skeletonise::config::load_str_with(&text, "toy.yaml", &[], &registry).unwrap();
    let e = skeletonise::pipeline::run(&p, &skeletonise::pipeline::RunOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`steps.toy.near`: layer `nope` not found")
            && e.contains("`steps.toy.near.layer`"),
        "{e}"
    );
    assert!(
        !out.exists(),
        "no output for a run that could not read its side input"
    );
}

#[test]
fn a_registered_step_rejects_a_feature_or_stops_the_run_with_its_reason_and_has_its_time() {
    let registry = skeletonise::config::builtin_steps().with(toy::ENTRY);
    let d = tmp();
    let out = d.path().join("toy.gpkg");
    let run = |toy: &str| {
        let p = skeletonise::config::load_str_with(
            &pipeline_text(&out, toy),
            "toy.yaml",
            &[],
            &registry,
        )
        .unwrap();
        skeletonise::pipeline::run(&p, &skeletonise::pipeline::RunOptions::default())
    };
    // The lakes' skeletons are long, the rivers' short or long: every
    // feature over 20 km is rejected naming the step, the others written.
    let s = run("  - toy: { scale: 1, max_length: 20000 }\n").unwrap();
    assert_eq!(s.read, 17);
    assert!(s.rejected > 0 && s.written > 0, "{s:?}");
    assert_eq!(s.written + s.rejected, 17);
    let ds = open(&out);
    let reasons: Vec<String> = crate::common::strings(&ds, "rejected", "reason")
        .into_iter()
        .flatten()
        .collect();
    assert_eq!(reasons.len() as u64, s.rejected);
    assert!(
        reasons
            .iter()
            .all(|r| r.starts_with("`toy`: the skeleton is ")
                && r.ends_with("over `max_length` (20000 m): raise it")),
        "{reasons:?}"
    );
    // A rejected feature has no row in any layer, the step's included.
    assert_eq!(crate::common::count(&ds, "toy"), s.written);
    assert_eq!(crate::common::count(&ds, "skeletons"), s.written);
    // Its CPU time is in the run record, under its name.
    let stages: serde_json::Value = serde_json::from_str(
        &crate::common::strings(&ds, "skeletonise_runs", "stage_seconds")[0]
            .clone()
            .unwrap(),
    )
    .unwrap();
    assert!(stages["toy"].as_f64().is_some_and(|t| t >= 0.0), "{stages}");
    drop(ds);
    // A finish that fails stops the run with its reason (exit 65), and
    // nothing is written: not the output, not a temporary file.
    std::fs::remove_file(&out).unwrap();
    let e = run("  - toy: { scale: 1, min_total: 1.0e12 }\n").unwrap_err();
    assert!(
        e.to_string().starts_with("`toy`: the lengths sum to ")
            && e.to_string()
                .ends_with("under `min_total` (1000000000000 m)"),
        "{e}"
    );
    assert!(matches!(e, skeletonise::pipeline::RunError::Finish(_)));
    let left: Vec<_> = std::fs::read_dir(d.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// A step that makes rows its layers cannot hold: its feature rows give a
/// text to a number column, its finish a row of a layer it never declared.
mod wrong {
    use super::*;

    #[derive(Debug)]
    struct Wrong;

    impl FeatureStep for Wrong {
        fn rows(&self, _: &StepInput<'_>) -> StepRows {
            let cells = vec![("length", Cell::Text("long".into()))];
            Ok(vec![(
                "wrong",
                StepRow {
                    geometry: None,
                    cells,
                },
            )])
        }

        fn finish(&self, _: &FinishInput<'_>) -> StepRows {
            let cells = vec![("length", Cell::Real(1.0))];
            Ok(vec![(
                "elsewhere",
                StepRow {
                    geometry: None,
                    cells,
                },
            )])
        }
    }

    pub const ENTRY: StepEntry = StepEntry {
        name: "wrong",
        after: "select",
        description: "rows that do not fit its layer (a test step)",
        schema: || schemars::json_schema!({ "type": ["object", "null"] }),
        needs: Needs::NOTHING,
        layers: &[StepLayer {
            name: "wrong",
            geometry: GeometryKind::None,
            fields: None,
            columns: &[("length", ColumnType::Real)],
        }],
        build: |_| Ok(std::sync::Arc::new(Wrong)),
    };
}

#[test]
fn rows_that_do_not_fit_a_steps_layers_are_an_error_naming_the_step_never_a_column_written_wrong() {
    let registry = skeletonise::config::builtin_steps().with(wrong::ENTRY);
    let d = tmp();
    let out = d.path().join("wrong.gpkg");
    let p = skeletonise::config::load_str_with(
        &pipeline_text(&out, "  - wrong: {}\n"),
        "wrong.yaml",
        &[],
        &registry,
    )
    .unwrap();
    // The finish's row of an undeclared layer stops the run, naming the
    // step and the layer; nothing is written.
    let e = skeletonise::pipeline::run(&p, &skeletonise::pipeline::RunOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("`wrong`: internal error in the step: a row of layer `elsewhere`, which it does not declare"),
        "{e}"
    );
    assert!(!out.exists());
    // Through the run driver: the rows are checked before they are kept,
    // and the finish's row of an undeclared layer stops the run.
    let params = p.process_params();
    let all = features(&p);
    let mut run = skeletonise::process::Run::new(&params, false);
    for f in &all {
        let r = skeletonise::process::feature_rows(
            f,
            skeletonise::process::Skeletons::Computed,
            &params,
            skeletonise::process::RowOptions::of(&p.plan()),
        );
        // Each feature's row is refused before it is kept: the feature is
        // rejected naming the step, the column and the value.
        let rows = run.add(f, r).unwrap();
        assert!(rows.extra.is_empty() && rows.skeletons.is_empty());
        assert_eq!(rows.rejected.len(), 1);
        assert_eq!(
            rows.rejected[0].reason,
            "`wrong`: internal error in the step: column `length` of layer `wrong` is Real, and a row gives it Text(\"long\"); please report it"
        );
    }
    assert_eq!(run.counts().rejected, 17);
    let e = run.finish().unwrap_err().to_string();
    assert!(
        e.starts_with("`wrong`: internal error in the step: a row of layer `elsewhere`, which it does not declare"),
        "{e}"
    );
}

#[test]
fn a_registered_steps_layer_of_the_features_carries_their_parts_and_members_as_the_skeletons_do() {
    // With `explode` and `merge_adjacent`, a step layer that carries the
    // input's fields gets `polygon_part` and `members` after `src_fid`,
    // with the skeleton layer's values row for row; its own columns
    // follow, and a layer without the input's fields (`toy_total`) gets
    // neither.
    let registry = skeletonise::config::builtin_steps().with(toy::ENTRY);
    let d = tmp();
    let out = d.path().join("toy.gpkg");
    let text = pipeline_text(&out, "  - toy: { scale: 1 }\n");
    let sets = [
        "output.explode=true".to_string(),
        "input.merge_adjacent=true".to_string(),
    ];
    let p = skeletonise::config::load_str_with(&text, "toy.yaml", &sets, &registry).unwrap();
    skeletonise::pipeline::run(&p, &skeletonise::pipeline::RunOptions::default()).unwrap();
    let ds = open(&out);
    let names = |layer: &str| -> Vec<String> {
        let l = ds.layer_by_name(layer).unwrap();
        let names = l.defn().fields().map(|f| f.name()).collect();
        names
    };
    let toy = names("toy");
    let at = toy.iter().position(|n| n == "src_fid").unwrap();
    assert_eq!(
        toy[at..],
        [
            "src_fid",
            "polygon_part",
            "members",
            "scaled_length",
            "near"
        ],
        "{toy:?}"
    );
    let total = names("toy_total");
    assert!(
        !total.contains(&"polygon_part".into()) && !total.contains(&"members".into()),
        "{total:?}"
    );
    let ints = |layer: &str, c: &str| crate::common::ints(&ds, layer, c);
    assert!(ints("skeletons", "polygon_part")
        .iter()
        .any(|p| p.is_some()));
    for c in ["src_fid", "polygon_part"] {
        assert_eq!(ints("toy", c), ints("skeletons", c), "{c}");
    }
    let members = |layer: &str| crate::common::strings(&ds, layer, "members");
    assert_eq!(members("toy"), members("skeletons"));
}
