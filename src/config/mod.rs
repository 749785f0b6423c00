//! The pipeline file (SPEC §8): model, loading (with `--set` overrides and
//! `${ENV}` substitution), validation and JSON Schema.
//!
//! Every error names the file, `line:column` and key path, and says what to
//! do. `skeletonise validate` and `skeletonise run` share [`load`].
//!
//! ```
//! let p = skeletonise::config::load_str(
//!     "input: {source: in.gpkg}\nsteps:\n  - skeleton: {methods: [CDT]}\noutput: {path: out.gpkg}\n",
//!     "demo.yaml",
//!     &[],
//! ).unwrap();
//! assert_eq!(p.file.output.layer, "skeletons");
//! ```

mod describe;
pub mod locate;
mod parse;
mod sections;
mod validate;

pub use describe::{describe, describe_with, json_schema, json_schema_with};
pub use sections::{
    ConnectSpec, InputSpec, LayerRef, LayerSource, Measures, NeighboursSpec, OutputSpec, ReportSpec,
};

use crate::process::step::{Extra, StepRegistry};
use parse::parse;
use validate::{validate, validate_steps};

use crate::collapse::CollapseParams;
use crate::graph::extend::ExtendParams;
use crate::graph::prune::PruneParams;
use crate::methods::SkeletonParams;
use crate::process::{PrepareParams, ProcessParams};
use crate::score::select::SelectParams;
use crate::score::ScoreParams;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// What to do with features that cannot be processed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum OnError {
    /// Write them to the `rejected` layer with the reason and carry on.
    #[default]
    Reject,
    /// Stop at the first one and exit with status 65; no output is written.
    Fail,
}

/// One step of the pipeline, keyed by its name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Step {
    /// Validity repair and area filter.
    Prepare(PrepareParams),
    /// The skeleton methods to run.
    Skeleton(SkeletonParams),
    /// Removal of insignificant legs: a leg goes when it protrudes less than `ratio` radii beyond the disc at its junction and is no arm (it protrudes less than `arm_ratio` times its own width at the mouth, or its mouth radius is less than `arm_width` times the junction's radius); cut ends stay; with `structure: shared` every method gets the reference method's legs.
    Prune(PruneParams),
    /// Extension of legs to the boundary: `centred` continues along the method's own removed legs, or ends between them where they fork on both sides of the line.
    Extend(ExtendParams),
    /// Partial collapse for map production: the chosen skeleton replaces the polygon where its local width 2r is below `width` (lines in the skeleton layer with `collapsed = 1`), the wider pieces stay areas (layer `areas`), cut across the polygon where the lines meet them.
    Collapse(CollapseParams),
    /// The paper's metrics.
    Score(ScoreParams),
    /// A registered step (`process::step`), parsed by its own entry.
    #[serde(skip)]
    #[schemars(skip)]
    Extra(Extra),
    /// Choice of the best method per feature: among the candidates with hits, those with coverage ≥ min(`min_coverage`, best coverage − `coverage_slack`) are eligible; the smallest `by` wins, distortions within `tie` of it counting as equal (the method listed first wins).
    Select(SelectParams),
}

impl Step {
    /// The step's key in the pipeline file.
    pub fn name(&self) -> &'static str {
        match self {
            Step::Prepare(_) => "prepare",
            Step::Skeleton(_) => "skeleton",
            Step::Prune(_) => "prune",
            Step::Extend(_) => "extend",
            Step::Collapse(_) => "collapse",
            Step::Score(_) => "score",
            Step::Select(_) => "select",
            Step::Extra(e) => e.entry.name,
        }
    }

    /// Checks the step's options: `(key within the step, message)`.
    pub fn validate(&self) -> Result<(), (String, String)> {
        match self {
            Step::Prepare(p) => p.validate(),
            Step::Skeleton(p) => p.validate(),
            Step::Prune(p) => p.validate(),
            Step::Collapse(p) => p.validate(),
            Step::Extend(_) | Step::Score(_) | Step::Extra(_) => Ok(()),
            Step::Select(p) => p.validate(),
        }
    }

    /// What the step needs of the run beyond each feature (see
    /// [`ProcessParams::needs`], the union over a pipeline's steps).
    pub fn needs(&self) -> crate::process::step::Needs {
        use crate::process::step::Needs;
        match self {
            Step::Collapse(_) => crate::process::COLLAPSE_NEEDS,
            Step::Extra(e) => e.step.needs(e.entry.needs),
            _ => Needs::NOTHING,
        }
    }

    /// Steps in the only order they may appear in.
    pub const ORDER: [&'static str; 7] = [
        "prepare", "skeleton", "prune", "extend", "collapse", "score", "select",
    ];
}

/// The pipeline file as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PipelineFile {
    /// A name for logs and the `skeletonise_runs` table.
    #[serde(default)]
    pub name: Option<String>,
    /// Where the polygons come from.
    pub input: InputSpec,
    /// Steps, in the order prepare → skeleton → prune → extend → collapse → score → select, each registered step after the one it follows (`skeletonise methods` lists the order); only `skeleton` is required.
    pub steps: Vec<Step>,
    /// Where the GeoPackage goes.
    pub output: OutputSpec,
    /// `reject` (default) or `fail`.
    #[serde(default)]
    pub on_error: OnError,
}

/// A loaded, validated pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct Pipeline {
    /// The file's content after overrides and substitution.
    pub file: PipelineFile,
    /// The original text (recorded in the output's `skeletonise_runs` table).
    pub text: String,
    /// Where it came from.
    pub origin: String,
    /// The `--set` overrides applied.
    pub overrides: Vec<String>,
}

/// The per-feature parameters of `steps`, keeping what `plan` writes (the
/// bars, the widths, the measures).
pub fn process_params(steps: &[Step], plan: &crate::output::Plan) -> ProcessParams {
    let mut p = ProcessParams::default();
    for s in steps {
        match s {
            Step::Prepare(x) => p.prepare = *x,
            Step::Skeleton(x) => p.skeleton = x.clone(),
            Step::Prune(x) => p.prune = Some(*x),
            Step::Extend(x) => p.extend = Some(*x),
            Step::Collapse(x) => p.collapse = Some(*x),
            Step::Score(x) => p.score = Some(*x),
            Step::Select(x) => p.select = Some(*x),
            Step::Extra(e) => p.extra.push(e.clone()),
        }
    }
    use crate::output::When;
    p.keep_bars = plan.holds(When::Bars);
    p.keep_widths = plan.holds(When::Widths);
    p.keep_measures = plan.holds(When::Measures);
    p
}

/// The output plan of `output` for `steps` reading `input` (when the
/// caller reads it: the Python package brings its own data): which of the
/// conditions layers and columns depend on hold.
pub fn plan_of(
    output: &OutputSpec,
    input: Option<&InputSpec>,
    steps: &[Step],
) -> crate::output::Plan {
    let merge = input.is_some_and(|i| i.merge_adjacent);
    let connect = input.is_some_and(|i| i.connect.is_some());
    plan_with(output, steps, merge, connect)
}

/// [`plan_of`] for a caller that brings its own data (the Python binding):
/// `merge` when adjacent polygons are merged (`input.merge_adjacent`), and
/// `connect` when a line network is given (`input.connect`).
pub fn plan_with(
    output: &OutputSpec,
    steps: &[Step],
    merge: bool,
    connect: bool,
) -> crate::output::Plan {
    use crate::output::When;
    let mut holds = Vec::new();
    let mut flag = |on: bool, w: When| {
        if on {
            holds.push(w);
        }
    };
    flag(output.explode, When::Explode);
    flag(output.candidates, When::Candidates);
    flag(output.bars, When::Bars);
    flag(output.widths, When::Widths);
    flag(output.measures == Measures::Width, When::Measures);
    flag(
        steps.iter().any(|s| matches!(s, Step::Collapse(_))),
        When::Collapse,
    );
    flag(merge || steps.iter().any(|s| s.needs().merge), When::Merge);
    flag(connect, When::Connect);
    let mut layers = Vec::new();
    for s in steps {
        if let Step::Extra(e) = s {
            holds.push(When::Step(e.entry.name));
            layers.extend(e.entry.layers.iter());
        }
    }
    crate::output::Plan::new(output.layer.clone(), holds, &layers)
}

/// The error text of a feature rejected under `on_error: fail` (`fid` as
/// text, `(no fid)` when it has none).
pub fn rejected_under_fail(fid: &str, reason: &str) -> String {
    format!("feature {fid} was rejected: {reason} (on_error: fail stops the run; no output was written; use `on_error: reject` to list such features in the `rejected` layer instead)")
}

/// A pipeline file read for its steps only, by callers that bring their own
/// data (the Python binding): `input` and `output` may be left out, and
/// only `output.explode` and `on_error` are used of what is beside the
/// steps. Keys, types, step order and option ranges are checked by the same
/// code, with the same messages, as for [`PipelineFile`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StepsFile {
    /// A name for logs.
    #[serde(default)]
    pub name: Option<String>,
    /// Ignored (the caller brings the data).
    #[serde(default)]
    pub input: Option<InputSpec>,
    /// Steps, in the order prepare → skeleton → prune → extend → collapse → score → select (`Step::ORDER`), each registered step after the one it follows; only `skeleton` is required.
    pub steps: Vec<Step>,
    /// Only `explode` is used (the caller writes the data).
    #[serde(default)]
    pub output: Option<OutputSpec>,
    /// `reject` (default) or `fail`.
    #[serde(default)]
    pub on_error: OnError,
}

/// A loaded, validated [`StepsFile`].
#[derive(Debug, Clone, PartialEq)]
pub struct Steps {
    /// The file's content after overrides and substitution.
    pub file: StepsFile,
    /// The original text.
    pub text: String,
    /// Where it came from.
    pub origin: String,
}

impl Steps {
    /// The output plan of the steps: the skeleton layer and what the file's
    /// `output` section (when it has one) asks for.
    pub fn plan(&self) -> crate::output::Plan {
        plan_of(&self.output(), None, &self.file.steps)
    }

    /// The file's `output` section, or the defaults without one.
    fn output(&self) -> OutputSpec {
        self.file.output.clone().unwrap_or_else(|| OutputSpec {
            path: String::new(),
            layer: crate::output::SKELETONS.name.into(),
            overwrite: false,
            candidates: false,
            bars: false,
            explode: false,
            widths: false,
            measures: Measures::None,
            report: None,
        })
    }

    /// The output plan of one call of the steps on a caller's data (the
    /// Python binding): the candidates' columns always (the call returns
    /// them on request), `explode` as asked, and the layers of
    /// `input.connect` when lines are given — the layers and columns the
    /// command line would write for the same pipeline.
    pub fn call_plan(&self, explode: bool, connect: bool) -> crate::output::Plan {
        let mut output = self.output();
        output.layer = crate::output::SKELETONS.name.into();
        output.candidates = true;
        output.explode = explode;
        (output.bars, output.widths) = (false, false);
        output.measures = Measures::None;
        plan_with(&output, &self.file.steps, false, connect)
    }

    /// The per-feature parameters of the steps.
    pub fn process_params(&self) -> ProcessParams {
        process_params(&self.file.steps, &self.plan())
    }
}

/// Loads, overrides, substitutes and validates the steps of a pipeline file
/// whose `input` and `output` sections may be absent.
pub fn load_steps(path: &std::path::Path, overrides: &[String]) -> Result<Steps, ConfigError> {
    let origin = path.display().to_string();
    let text = read_text(path, &origin)?;
    load_steps_str(&text, &origin, overrides)
}

/// [`load_steps`] from text; `origin` names it in errors.
pub fn load_steps_str(
    text: &str,
    origin: &str,
    overrides: &[String],
) -> Result<Steps, ConfigError> {
    let file: StepsFile = parse(
        text,
        origin,
        overrides,
        &builtin_steps(),
        |f: &StepsFile| validate_steps(&f.steps),
    )?;
    Ok(Steps {
        file,
        text: text.to_string(),
        origin: origin.to_string(),
    })
}

impl Pipeline {
    /// The per-feature parameters of the steps.
    pub fn process_params(&self) -> ProcessParams {
        process_params(&self.file.steps, &self.plan())
    }

    /// The output plan: the layers and columns the run writes.
    pub fn plan(&self) -> crate::output::Plan {
        plan_of(&self.file.output, Some(&self.file.input), &self.file.steps)
    }

    /// The pipeline text with the overrides appended as comments, for provenance.
    pub fn provenance_text(&self) -> String {
        let mut t = self.text.clone();
        for o in &self.overrides {
            t.push_str(&format!("\n# --set {o}"));
        }
        t
    }
}

/// An invalid pipeline file (exit status 78).
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{origin}{}: {}{message}", .position.map(|(l, c)| format!(":{l}:{c}")).unwrap_or_default(), if .key.is_empty() { String::new() } else { format!("`{}`: ", .key) })]
pub struct ConfigError {
    /// The file (or `--set`).
    pub origin: String,
    /// `line:column`, when known.
    pub position: Option<(usize, usize)>,
    /// The key path, e.g. `steps[2].prune.ratio`.
    pub key: String,
    /// What is wrong and how to fix it.
    pub message: String,
}

/// Loads, overrides, substitutes and validates a pipeline file.
pub fn load(path: &std::path::Path, overrides: &[String]) -> Result<Pipeline, ConfigError> {
    let origin = path.display().to_string();
    let text = read_text(path, &origin)?;
    load_str(&text, &origin, overrides)
}

fn read_text(path: &std::path::Path, origin: &str) -> Result<String, ConfigError> {
    std::fs::read_to_string(path).map_err(|e| ConfigError {
        origin: origin.to_string(),
        position: None,
        key: String::new(),
        message: format!("cannot read the pipeline file: {e}"),
    })
}

/// [`load`] from text; `origin` names it in errors.
pub fn load_str(text: &str, origin: &str, overrides: &[String]) -> Result<Pipeline, ConfigError> {
    load_str_with(text, origin, overrides, &builtin_steps())
}

/// The registered steps every pipeline file may use, assembled here, above
/// the steps and the registry's own module.
pub fn builtin_steps() -> StepRegistry {
    StepRegistry::default()
        .with(crate::partition::ENTRY)
        .with(crate::label::ENTRY)
        .with(crate::streets::ENTRY)
}

/// [`load_str`] with the registered steps of `registry` (library use: a
/// step of one's own beside the built-in ones).
pub fn load_str_with(
    text: &str,
    origin: &str,
    overrides: &[String],
    registry: &StepRegistry,
) -> Result<Pipeline, ConfigError> {
    // Editors on Windows save UTF-8 with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file: PipelineFile = parse(text, origin, overrides, registry, validate)?;
    Ok(Pipeline {
        file,
        text: text.to_string(),
        origin: origin.to_string(),
        overrides: overrides.to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = "input:\n  source: in.gpkg\nsteps:\n  - prepare: { make_valid: true }\n  - skeleton: { methods: [CDT] }\n  - prune: { ratio: 1.5 }\noutput:\n  path: out.gpkg\n";

    #[test]
    fn loads_and_applies_overrides() {
        let p = load_str(
            OK,
            "p.yaml",
            &[
                "steps.prune.ratio=2".into(),
                "steps.extend.mode=nearest".into(),
                "output.overwrite=true".into(),
            ],
        )
        .unwrap();
        let pp = p.process_params();
        assert_eq!(pp.prune.unwrap().ratio, 2.0);
        assert_eq!(
            pp.extend.unwrap().mode,
            crate::graph::extend::ExtendMode::Nearest
        );
        assert!(p.file.output.overwrite);
    }

    #[test]
    fn unknown_key_names_line_column_and_path() {
        let t = OK.replace("ratio: 1.5", "ratoi: 1.5");
        let e = load_str(&t, "p.yaml", &[]).unwrap_err();
        assert_eq!(e.position, Some((6, 14)), "{e}");
        assert_eq!(e.key, "steps[2].prune.ratoi");
        assert!(
            e.to_string()
                .starts_with("p.yaml:6:14: `steps[2].prune.ratoi`: unknown field `ratoi`"),
            "{e}"
        );
    }

    #[test]
    fn wrong_type_and_wrong_order() {
        let e = load_str(&OK.replace("ratio: 1.5", "ratio: lots"), "p.yaml", &[]).unwrap_err();
        assert_eq!(e.key, "steps[2].prune.ratio");
        assert_eq!(e.position, Some((6, 21)));
        let t = "input: {source: a}\nsteps:\n  - skeleton: {}\n  - prepare: {}\noutput: {path: o.gpkg}\n";
        let e = load_str(t, "p.yaml", &[]).unwrap_err();
        assert_eq!(e.key, "steps[1].prepare");
        assert_eq!(e.position, Some((4, 5)));
        assert!(e.message.contains("must come before"), "{e}");
    }

    #[test]
    fn env_substitution() {
        std::env::set_var("SKELETONISE_TEST_SRC", "from-env.gpkg");
        let t = OK
            .replace("in.gpkg", "${SKELETONISE_TEST_SRC}")
            .replace("out.gpkg", "${SKELETONISE_NOPE:-fallback.gpkg}");
        let p = load_str(&t, "p.yaml", &[]).unwrap();
        assert_eq!(p.file.input.source, "from-env.gpkg");
        assert_eq!(p.file.output.path, "fallback.gpkg");
        let e = load_str(&OK.replace("in.gpkg", "${SKELETONISE_NOPE}"), "p.yaml", &[]).unwrap_err();
        assert_eq!(e.key, "input.source");
        assert_eq!(e.position, Some((2, 11)));
    }

    #[test]
    fn substituted_values_stay_strings_unless_the_key_needs_a_number_or_boolean() {
        std::env::set_var("SKELETONISE_TEST_LAYER", "7");
        std::env::set_var("SKELETONISE_TEST_RATIO", "2.5");
        std::env::set_var("SKELETONISE_TEST_OW", "true");
        std::env::set_var("SKELETONISE_TEST_EMPTY", "");
        let t = OK
            .replace(
                "source: in.gpkg",
                "source: in.gpkg\n  layer: \"${SKELETONISE_TEST_LAYER}\"",
            )
            .replace("ratio: 1.5", "ratio: \"${SKELETONISE_TEST_RATIO}\"")
            .replace(
                "path: out.gpkg",
                "path: out.gpkg\n  overwrite: ${SKELETONISE_TEST_OW}\n  layer: ${SKELETONISE_TEST_EMPTY:-lines}",
            );
        let p = load_str(&t, "p.yaml", &[]).unwrap();
        assert_eq!(p.file.input.layer, Some(LayerRef::Name("7".into())));
        assert_eq!(p.process_params().prune.unwrap().ratio, 2.5);
        assert!(p.file.output.overwrite);
        assert_eq!(p.file.output.layer, "lines");
        let e = load_str(
            &OK.replace("ratio: 1.5", "ratio: \"${SKELETONISE_TEST_EMPTY}\""),
            "p.yaml",
            &[],
        )
        .unwrap_err();
        assert_eq!(e.key, "steps[2].prune.ratio");
        assert!(
            e.message
                .contains("`SKELETONISE_TEST_EMPTY` is set but empty"),
            "{e}"
        );
    }

    #[test]
    fn deep_brackets_are_refused_before_parsing_and_quoted_ones_do_not_count() {
        let deep = format!("input: {}", "[".repeat(100_000));
        let e = load_str(&deep, "p.yaml", &[]).unwrap_err();
        assert_eq!(e.position, Some((1, 8 + parse::MAX_NESTING)), "{e}");
        assert!(e.message.contains("nested deeper than 128"), "{e}");
        let quoted = OK.replace(
            "path: out.gpkg",
            &format!(
                "path: out.gpkg\n  layer: \"{}\" # {}",
                "[".repeat(300),
                "{".repeat(300)
            ),
        );
        assert!(load_str(&quoted, "p.yaml", &[]).is_ok());
    }

    #[test]
    fn description_lists_methods_steps_and_defaults() {
        let d = describe(&crate::methods::Registry::builtin());
        for needle in [
            "MA    medial axis",
            "prune ",
            "arm_ratio        number (default 1.0)",
            "mode             centred | ray | nearest | none (default \"centred\")",
            "coverage_slack   number (default 0.25)",
            "methods          list of VD, DVD, CDT, StSk, MA (default [\"MA\",\"StSk\",\"DVD\",\"CDT\",\"VD\"])",
        ] {
            assert!(d.contains(needle), "`{needle}` missing from:\n{d}");
        }
    }

    #[test]
    fn steps_files_need_no_input_or_output_and_share_the_messages() {
        let s = load_steps_str(
            "steps:\n  - skeleton: {methods: [CDT]}\n  - prune: {ratio: 2}\n",
            "s.yaml",
            &["steps.extend.mode=ray".into()],
        )
        .unwrap();
        let pp = s.process_params();
        assert_eq!(pp.prune.unwrap().ratio, 2.0);
        assert_eq!(
            pp.extend.unwrap().mode,
            crate::graph::extend::ExtendMode::Ray
        );
        let e = load_steps_str(
            "steps:\n  - prepare: {}\n  - skeleton: {}\n  - prune: {ratoi: 1.5}\n",
            "s.yaml",
            &[],
        )
        .unwrap_err();
        let full = load_str(&OK.replace("ratio: 1.5", "ratoi: 1.5"), "p.yaml", &[]).unwrap_err();
        assert_eq!(
            (e.key.as_str(), e.position),
            ("steps[2].prune.ratoi", Some((4, 13)))
        );
        assert_eq!(e.message, full.message);
        let e = load_steps_str("steps:\n  - prune: {}\n", "s.yaml", &[]).unwrap_err();
        assert!(e.message.contains("`skeleton` step is required"), "{e}");
        // A full pipeline file is a steps file too.
        assert!(load_steps_str(OK, "p.yaml", &[]).is_ok());
    }

    #[test]
    fn schema_lists_steps() {
        let s = json_schema().to_string();
        assert!(s.contains("skeleton") && s.contains("min_coverage"));
    }
}
