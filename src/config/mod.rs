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

pub mod locate;
mod sections;

pub use sections::{ConnectSpec, InputSpec, LayerRef, Measures, OutputSpec, ReportSpec};

use crate::collapse::CollapseParams;
use crate::graph::extend::ExtendParams;
use crate::graph::prune::PruneParams;
use crate::methods::SkeletonParams;
use crate::process::{PrepareParams, ProcessParams};
use crate::score::select::SelectParams;
use crate::score::ScoreParams;
use locate::Locations;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_yaml_ng::Value;
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
    /// Removal of insignificant legs: a leg goes when it protrudes less than `ratio` radii beyond the disc at its junction and is no arm (it protrudes less than `arm_ratio` times its own width at the mouth); cut ends stay; with `structure: shared` every method gets the reference method's legs.
    Prune(PruneParams),
    /// Extension of legs to the boundary: `centred` continues along the method's own removed legs, or ends between them where they fork on both sides of the line.
    Extend(ExtendParams),
    /// Partial collapse for map production: the chosen skeleton replaces the polygon where its local width 2r is below `width` (lines in the skeleton layer with `collapsed = 1`), the wider pieces stay areas (layer `areas`), cut across the polygon where the lines meet them.
    Collapse(CollapseParams),
    /// The paper's metrics.
    Score(ScoreParams),
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
        }
    }

    /// Checks the step's options: `(key within the step, message)`.
    pub fn validate(&self) -> Result<(), (String, String)> {
        match self {
            Step::Prepare(p) => p.validate(),
            Step::Skeleton(p) => p.validate(),
            Step::Prune(p) => p.validate(),
            Step::Collapse(p) => p.validate(),
            Step::Extend(_) | Step::Score(_) => Ok(()),
            Step::Select(p) => p.validate(),
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
    /// Steps, in the order prepare → skeleton → prune → extend → collapse → score → select; only `skeleton` is required.
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
    flag(input.is_some_and(|i| i.merge_adjacent), When::Merge);
    flag(input.is_some_and(|i| i.connect.is_some()), When::Connect);
    crate::output::Plan::new(output.layer.clone(), holds, &[])
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
    /// Steps, in the order prepare → skeleton → prune → extend → score → select; only `skeleton` is required.
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
        let output = self.file.output.clone().unwrap_or_else(|| OutputSpec {
            path: String::new(),
            layer: crate::output::SKELETONS.name.into(),
            overwrite: false,
            candidates: false,
            bars: false,
            explode: false,
            widths: false,
            measures: Measures::None,
            report: None,
        });
        plan_of(&output, None, &self.file.steps)
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
    let file: StepsFile = parse(text, origin, overrides, |f: &StepsFile| {
        validate_steps(&f.steps)
    })?;
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
    // Editors on Windows save UTF-8 with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file: PipelineFile = parse(text, origin, overrides, validate)?;
    Ok(Pipeline {
        file,
        text: text.to_string(),
        origin: origin.to_string(),
        overrides: overrides.to_vec(),
    })
}

/// Parses `text` as a `T` after overrides and substitution, then checks it
/// with `check`; every error located in the text, or in the `--set` that
/// gave the key.
fn parse<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
    overrides: &[String],
    check: impl Fn(&T) -> Result<(), (String, String)>,
) -> Result<T, ConfigError> {
    // An error in a key that a `--set` gave is the override's, not the file's.
    let overridden = |key: &str| {
        let plain = strip_indices(key);
        overrides.iter().find(|o| {
            let k = o.split_once('=').map_or(o.as_str(), |(k, _)| k);
            plain == k || plain.starts_with(&format!("{k}.")) || k.starts_with(&format!("{plain}."))
        })
    };
    let err = |position, key: &str, message: String| match overridden(key) {
        Some(o) if !key.is_empty() => ConfigError {
            origin: format!("--set {o}"),
            position: None,
            key: key.to_string(),
            message,
        },
        _ => ConfigError {
            origin: origin.to_string(),
            position,
            key: key.to_string(),
            message,
        },
    };
    if let Some((line, column)) = too_deep(text) {
        return Err(err(
            Some((line, column)),
            "",
            format!("invalid YAML: brackets nested deeper than {MAX_NESTING} levels; a pipeline file needs a handful"),
        ));
    }
    let mut value: Value = serde_yaml_ng::from_str(text).map_err(|e| {
        let pos = e.location().map(|l| (l.line(), l.column()));
        err(pos, "", format!("invalid YAML: {e}"))
    })?;
    if value.is_null() {
        return Err(err(
            None,
            "",
            "the pipeline file is empty; see `skeletonise schema` or pipelines/demo.yaml".into(),
        ));
    }
    let locs = Locations::index(text);
    for o in overrides {
        apply_override(&mut value, o).map_err(|m| ConfigError {
            origin: "--set".into(),
            position: None,
            key: o.clone(),
            message: m,
        })?;
    }
    let mut typed = Typed::new();
    substitute_env(&mut value, "", &mut typed).map_err(|(k, m)| err(locs.value(&k), &k, m))?;
    unknown_skeleton_keys(&value).map_err(|(k, m)| err(locs.key(&k), &k, m))?;
    let file: T = loop {
        // Enums are written as single-key maps (`prune: {...}`, `densify: {factor: 4}`).
        let mut track = serde_path_to_error::Track::new();
        let de = serde_path_to_error::Deserializer::new(value.clone(), &mut track);
        let parsed: Result<T, _> = serde_yaml_ng::with::singleton_map_recursive::deserialize(de);
        let e = match parsed {
            Ok(file) => break file,
            Err(e) => e,
        };
        let key = path_string(&track.path());
        // A substituted number or boolean where a string does not do.
        if let Some(t) = typed.remove(&key) {
            if let Some(slot) = value_at(&mut value, &key) {
                *slot = t;
                continue;
            }
        }
        let inner = e.to_string();
        // Point unknown keys at the key itself.
        let pos = match unknown_field(&inner) {
            Some(f) if key.ends_with(&f) => locs.key(&key),
            Some(f) => locs.key(&locate::join(&key, &f)),
            None => locs.value(&key),
        };
        return Err(err(pos, &key, hint(&inner)));
    };
    check(&file).map_err(|(k, m)| err(locs.key(&k), &k, m))?;
    Ok(file)
}

/// Deepest nesting of flow collections (`[`, `{`) a pipeline file may have
/// (the YAML deserialiser's own recursion limit).
const MAX_NESTING: usize = 128;

/// Where the flow brackets of `text` first nest deeper than
/// [`MAX_NESTING`] (line and column, from 1), if they do. Checked before
/// the YAML parser sees the text: its scanner takes time quadratic in the
/// depth (200 KB of `[` took 18 s) before it reports its recursion limit.
/// Brackets inside quotes and comments do not count; one in a plain scalar
/// does, which only matters past a hundred of them.
fn too_deep(text: &str) -> Option<(usize, usize)> {
    let (mut depth, mut line, mut column) = (0usize, 1usize, 0usize);
    let mut quote: Option<char> = None;
    let (mut comment, mut escaped, mut prev) = (false, false, '\n');
    for c in text.chars() {
        column += 1;
        if c == '\n' {
            (line, column, comment) = (line + 1, 0, false);
            prev = c;
            continue;
        }
        match quote {
            Some('"') if escaped => escaped = false,
            Some('"') if c == '\\' => escaped = true,
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if comment => {}
            None => match c {
                '#' if prev.is_whitespace() => comment = true,
                '"' | '\'' => quote = Some(c),
                '[' | '{' => {
                    depth += 1;
                    if depth > MAX_NESTING {
                        return Some((line, column));
                    }
                }
                ']' | '}' => depth = depth.saturating_sub(1),
                _ => {}
            },
        }
        prev = c;
    }
    None
}

/// The `skeleton` step takes its own keys and every registered method's
/// options flat (so that serde cannot reject unknown ones itself): a key
/// that none of them owns is an error.
fn unknown_skeleton_keys(root: &Value) -> Result<(), (String, String)> {
    let Some(steps) = root.get("steps").and_then(Value::as_sequence) else {
        return Ok(());
    };
    // The step's keys as its type declares them (methods' options flattened in).
    let schema = serde_json::to_value(schemars::schema_for!(SkeletonParams)).unwrap_or_default();
    let mut allowed: Vec<&str> = schema["properties"]
        .as_object()
        .map(|p| p.keys().map(String::as_str).collect())
        .unwrap_or_default();
    for e in crate::methods::BUILTIN {
        allowed.extend(e.options.iter().copied());
    }
    allowed.sort_unstable();
    allowed.dedup();
    for (i, step) in steps.iter().enumerate() {
        let Some(opts) = step.get("skeleton").and_then(Value::as_mapping) else {
            continue;
        };
        for k in opts.keys() {
            let k = k.as_str().unwrap_or_default();
            if !allowed.contains(&k) {
                let list: Vec<String> = allowed.iter().map(|a| format!("`{a}`")).collect();
                return Err((
                    format!("steps[{i}].skeleton.{k}"),
                    format!(
                        "unknown field `{k}`, expected one of {}; `skeletonise schema` lists every key",
                        list.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A key path without list indices: `steps[2].prune.ratio` → `steps.prune.ratio`.
fn strip_indices(key: &str) -> String {
    let mut out = String::with_capacity(key.len());
    let mut depth = 0;
    for c in key.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out
}

fn path_string(p: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut s = String::new();
    for seg in p.iter() {
        match seg {
            Segment::Seq { index } => s.push_str(&format!("[{index}]")),
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(key);
            }
            Segment::Unknown => {}
        }
    }
    s
}

fn unknown_field(msg: &str) -> Option<String> {
    let rest = msg
        .strip_prefix("unknown field `")
        .or_else(|| msg.strip_prefix("unknown variant `"))?;
    Some(rest[..rest.find('`')?].to_string())
}

fn hint(msg: &str) -> String {
    if msg.starts_with("unknown variant") && msg.contains("prepare") {
        format!("{msg}; steps are prepare, skeleton, prune, extend, score, select")
    } else if msg.starts_with("unknown field") {
        format!("{msg}; `skeletonise schema` lists every key")
    } else {
        msg.to_string()
    }
}

fn validate(f: &PipelineFile) -> Result<(), (String, String)> {
    validate_steps(&f.steps)?;
    f.input
        .validate()
        .map_err(|(k, m)| (format!("input.{k}"), m))?;
    if f.output.path.trim().is_empty() {
        return Err((
            "output.path".into(),
            "give the output GeoPackage path".into(),
        ));
    }
    skeleton_layer_name(&f.output.layer).map_err(|m| ("output.layer".to_string(), m))?;
    if let Some(r) = &f.output.report {
        r.features
            .validate()
            .map_err(|(k, m)| (format!("output.report.features.{k}"), m))?;
        if f.output.report_path() == Some(std::path::PathBuf::from(&f.output.path)) {
            return Err((
                "output.report.path".into(),
                "the report would overwrite the GeoPackage; give a path ending in .html".into(),
            ));
        }
    }
    Ok(())
}

/// Checks the name of the skeleton layer: not empty, none of the tool's
/// other layers (SQLite compares table names without case) and none of the
/// names GeoPackage and SQLite keep for themselves.
fn skeleton_layer_name(name: &str) -> Result<(), String> {
    let lower = name.to_ascii_lowercase();
    if name.trim().is_empty() {
        return Err("give the skeleton layer a name, e.g. `skeletons`".into());
    }
    let plan = crate::output::Plan::new(name, [], &[]);
    if let Some(taken) = plan
        .tool_layer_names()
        .into_iter()
        .find(|t| t.eq_ignore_ascii_case(name))
    {
        return Err(format!(
            "`{name}` is the name of the tool's own layer `{taken}`; choose another name for the skeleton layer"
        ));
    }
    if ["gpkg_", "rtree_", "sqlite_"]
        .iter()
        .any(|p| lower.starts_with(p))
    {
        return Err(format!(
            "`{name}` starts with a prefix GeoPackage and SQLite keep for their own tables; choose another name"
        ));
    }
    Ok(())
}

/// Step order, the required `skeleton`, `select` after `score`, and every
/// step's option ranges: `(key path, message)` of the first that is wrong.
fn validate_steps(steps: &[Step]) -> Result<(), (String, String)> {
    let mut last: Option<(usize, &str)> = None;
    for (i, s) in steps.iter().enumerate() {
        let rank = Step::ORDER.iter().position(|n| *n == s.name()).unwrap_or(0);
        if let Some((r, name)) = last {
            if rank == r {
                return Err((
                    format!("steps[{i}].{}", s.name()),
                    format!(
                        "step `{}` appears twice; merge its options into one entry",
                        s.name()
                    ),
                ));
            }
            if rank < r {
                return Err((
                    format!("steps[{i}].{}", s.name()),
                    format!(
                        "step `{}` must come before `{name}`; steps run in the order {}",
                        s.name(),
                        Step::ORDER.join(" → ")
                    ),
                ));
            }
        }
        last = Some((rank, s.name()));
    }
    let pos = |name: &str| steps.iter().position(|s| s.name() == name);
    let Some(_) = pos("skeleton") else {
        return Err((
            "steps".into(),
            "the `skeleton` step is required, e.g. `- skeleton: { methods: [MA, CDT] }`".into(),
        ));
    };
    if let (Some(sel), None) = (pos("select"), pos("score")) {
        return Err((
            format!("steps[{sel}].select"),
            "`select` needs the `score` step before it: add `- score: {}`".into(),
        ));
    }
    for (i, s) in steps.iter().enumerate() {
        s.validate()
            .map_err(|(k, m)| (format!("steps[{i}].{}.{k}", s.name()), m))?;
    }
    collapse_on_ma(steps)
}

/// `collapse` cuts the polygon by the medial axis's inscribed discs and
/// draws the lines on the medial axis: the skeleton step must list MA
/// alone. Another method's lines are not centred on those discs, so its
/// collapsed lines would cross the kept areas.
fn collapse_on_ma(steps: &[Step]) -> Result<(), (String, String)> {
    let collapses = steps.iter().any(|s| matches!(s, Step::Collapse(_)));
    let skeleton = steps.iter().enumerate().find_map(|(i, s)| match s {
        Step::Skeleton(p) => Some((i, p)),
        _ => None,
    });
    match skeleton {
        Some((i, p)) if collapses && p.methods != [crate::methods::MethodId::MA] => Err((
            format!("steps[{i}].skeleton.methods"),
            "`collapse` cuts the polygon where the medial axis's inscribed discs meet the collapse width and draws the medial axis: list MA alone (`skeleton: { methods: [MA] }`); other methods' lines are not centred on those discs, so their collapsed lines would cross the kept areas".into(),
        )),
        _ => Ok(()),
    }
}

/// Applies `KEY=VALUE` (dotted path; `steps.NAME.key` addresses a step by name
/// and adds the step when absent; the value is parsed as YAML).
fn apply_override(root: &mut Value, o: &str) -> Result<(), String> {
    let (key, val) = o
        .split_once('=')
        .ok_or_else(|| "expected KEY=VALUE, e.g. --set steps.prune.ratio=2".to_string())?;
    let new: Value =
        serde_yaml_ng::from_str(val).map_err(|e| format!("value is not valid YAML: {e}"))?;
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err("empty key segment".into());
    }
    let mut cur = root;
    let mut i = 0;
    while i < parts.len() {
        let seg = parts[i];
        let last = i + 1 == parts.len();
        cur = match cur {
            Value::Mapping(m) => {
                let k = Value::String(seg.to_string());
                if last {
                    m.insert(k, new);
                    return Ok(());
                }
                if !m.contains_key(&k) {
                    m.insert(k.clone(), Value::Mapping(Default::default()));
                }
                m.get_mut(&k).expect("inserted")
            }
            Value::Sequence(seq) => {
                if let Ok(idx) = seg.parse::<usize>() {
                    let len = seq.len();
                    let slot = seq.get_mut(idx).ok_or_else(|| {
                        format!("index {idx} is out of range (the list has {len} entries)")
                    })?;
                    if last {
                        *slot = new;
                        return Ok(());
                    }
                    slot
                } else {
                    // A step addressed by name.
                    let k = Value::String(seg.to_string());
                    let idx = step_index(seq, seg)?;
                    let m = seq[idx].as_mapping_mut().expect("a step is a mapping");
                    if last {
                        m.insert(k, new);
                        return Ok(());
                    }
                    let v = m.get_mut(&k).expect("present");
                    if v.is_null() {
                        *v = Value::Mapping(Default::default());
                    }
                    v
                }
            }
            _ => {
                return Err(format!(
                    "`{}` is not a mapping or list",
                    parts[..i].join(".")
                ))
            }
        };
        i += 1;
    }
    Ok(())
}

/// The index of step `name` in the `steps` list, inserting an empty step in
/// its place in the step order when it is absent.
fn step_index(seq: &mut Vec<Value>, name: &str) -> Result<usize, String> {
    let k = Value::String(name.to_string());
    if let Some(idx) = seq
        .iter()
        .position(|v| v.as_mapping().is_some_and(|m| m.contains_key(&k)))
    {
        return Ok(idx);
    }
    let rank = Step::ORDER
        .iter()
        .position(|n| *n == name)
        .ok_or_else(|| format!("no step `{name}`; steps are {}", Step::ORDER.join(", ")))?;
    let at = seq
        .iter()
        .position(|v| {
            v.as_mapping()
                .and_then(|m| m.keys().next())
                .and_then(Value::as_str)
                .and_then(|n| Step::ORDER.iter().position(|o| *o == n))
                .is_some_and(|r| r > rank)
        })
        .unwrap_or(seq.len());
    let mut m = serde_yaml_ng::Mapping::new();
    m.insert(k, Value::Mapping(Default::default()));
    seq.insert(at, Value::Mapping(m));
    Ok(at)
}

/// A value that was one `${…}` as a whole, by key path, with the value its
/// text has in YAML: it stays a string unless the key needs a number or a
/// boolean ([`parse`] retries with the typed value where the string fails).
type Typed = std::collections::HashMap<String, Value>;

/// Replaces `${NAME}` and `${NAME:-default}` in every string; records the
/// values that were one `${…}` as a whole in `typed`.
fn substitute_env(v: &mut Value, path: &str, typed: &mut Typed) -> Result<(), (String, String)> {
    match v {
        Value::String(s) if s.contains("${") => {
            let whole = s.starts_with("${") && s.ends_with('}') && s.matches("${").count() == 1;
            let text = expand(s).map_err(|m| (path.to_string(), m))?;
            if whole {
                let t = serde_yaml_ng::from_str::<Value>(&text)
                    .ok()
                    .filter(|t| matches!(t, Value::Number(_) | Value::Bool(_)));
                if let Some(t) = t {
                    typed.insert(path.to_string(), t);
                }
            }
            *v = Value::String(text);
        }
        Value::Mapping(m) => {
            for (k, val) in m.iter_mut() {
                let key = k.as_str().map(str::to_string).unwrap_or_default();
                substitute_env(val, &locate::join(path, &key), typed)?;
            }
        }
        Value::Sequence(s) => {
            for (i, val) in s.iter_mut().enumerate() {
                substitute_env(val, &format!("{path}[{i}]"), typed)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// The value at key path `path` (`a.b[2].c`, as [`substitute_env`] names
/// them).
fn value_at<'v>(v: &'v mut Value, path: &str) -> Option<&'v mut Value> {
    let mut cur = v;
    for seg in path.split('.') {
        let (key, indices) = match seg.find('[') {
            Some(i) => (&seg[..i], &seg[i..]),
            None => (seg, ""),
        };
        if !key.is_empty() {
            cur = cur.as_mapping_mut()?.get_mut(key)?;
        }
        for idx in indices.split('[').filter(|x| !x.is_empty()) {
            let i: usize = idx.trim_end_matches(']').parse().ok()?;
            cur = cur.as_sequence_mut()?.get_mut(i)?;
        }
    }
    Some(cur)
}

/// `${NAME}` and `${NAME:-default}` in `s` replaced by the environment. A
/// variable that is not set, or set but empty, is an error naming it,
/// unless the expression gives a default (`:-`, as in the shell: used when
/// the variable is unset or empty).
fn expand(s: &str) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = s;
    while let Some(start) = rest.find("${") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        let end = after
            .find('}')
            .ok_or_else(|| format!("unclosed `${{` in \"{s}\""))?;
        let expr = &after[..end];
        let (name, default) = match expr.split_once(":-") {
            Some((n, d)) => (n, Some(d)),
            None => (expr, None),
        };
        match (std::env::var(name), default) {
            (Ok(v), _) if !v.is_empty() => out.push_str(&v),
            (_, Some(d)) => out.push_str(d),
            (Ok(_), None) => {
                return Err(format!(
                    "environment variable `{name}` is set but empty; give it a value, or write `${{{name}:-default}}` for a default"
                ))
            }
            (Err(_), None) => {
                return Err(format!(
                    "environment variable `{name}` is not set; export it or write `${{{name}:-default}}`"
                ))
            }
        }
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The JSON Schema of the pipeline file.
pub fn json_schema() -> serde_json::Value {
    serde_json::to_value(schemars::schema_for!(PipelineFile)).unwrap_or_default()
}

/// `skeletonise methods`: the registered methods, then every step with its
/// options — their values and defaults taken from the same JSON Schema that
/// `skeletonise schema` prints (so from the types and their serde defaults).
pub fn describe(registry: &crate::methods::Registry) -> String {
    use std::fmt::Write as _;
    let schema = json_schema();
    let defs = &schema["$defs"];
    let mut out = String::from("Methods (skeleton step, `methods: [...]`):\n");
    for e in registry.entries() {
        let _ = writeln!(out, "  {:<5} {} — {}", e.id.as_str(), e.name, e.description);
    }
    out.push_str("\nSteps (in this order; only `skeleton` is required):\n");
    for step in defs["Step"]["oneOf"].as_array().into_iter().flatten() {
        let Some((name, body)) = step["properties"].as_object().and_then(|p| p.iter().next())
        else {
            continue;
        };
        let params = resolve(defs, body);
        let _ = writeln!(out, "  {name:<9} {}", first_line(&step["description"]));
        for (key, prop) in params["properties"].as_object().into_iter().flatten() {
            let _ = writeln!(
                out,
                "    {key:<16} {}{}",
                values(defs, prop),
                default_of(prop)
            );
            let _ = writeln!(out, "    {:<16} {}", "", first_line(&prop["description"]));
        }
    }
    out.push_str("\n`skeletonise schema` prints the full JSON Schema; README.md explains pruning,\nextension and selection.\n");
    out
}

fn resolve<'a>(defs: &'a serde_json::Value, v: &'a serde_json::Value) -> &'a serde_json::Value {
    match v["$ref"].as_str().and_then(|r| r.strip_prefix("#/$defs/")) {
        Some(name) => &defs[name],
        None => v,
    }
}

fn first_line(v: &serde_json::Value) -> String {
    v.as_str()
        .unwrap_or_default()
        .split("\n\n")
        .next()
        .unwrap_or_default()
        .replace('\n', " ")
}

/// The values an option takes: its enumeration, or its type.
fn values(defs: &serde_json::Value, prop: &serde_json::Value) -> String {
    let t = resolve(defs, prop);
    let items = &t["items"];
    if let Some(list) = t["oneOf"].as_array() {
        let names: Vec<String> = list
            .iter()
            .map(|o| match (&o["const"], o["properties"].as_object()) {
                (serde_json::Value::String(c), _) => c.clone(),
                (_, Some(p)) => p
                    .keys()
                    .map(|k| format!("{{{k}: …}}"))
                    .collect::<Vec<_>>()
                    .join(" | "),
                _ => "…".into(),
            })
            .collect();
        return names.join(" | ");
    }
    if let Some(e) = resolve(defs, items)["enum"].as_array() {
        let names: Vec<&str> = e.iter().filter_map(|x| x.as_str()).collect();
        return format!("list of {}", names.join(", "));
    }
    if let Some(e) = t["enum"].as_array() {
        let names: Vec<&str> = e.iter().filter_map(|x| x.as_str()).collect();
        return names.join(" | ");
    }
    t["type"].as_str().unwrap_or("value").to_string()
}

fn default_of(prop: &serde_json::Value) -> String {
    match &prop["default"] {
        serde_json::Value::Null => String::new(),
        d => format!(" (default {d})"),
    }
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
        assert_eq!(e.position, Some((1, 8 + MAX_NESTING)), "{e}");
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
