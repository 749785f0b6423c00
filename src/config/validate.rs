//! The checks of a parsed pipeline file: step order and the required
//! steps, every step's option ranges, the output's names and paths.

use super::{PipelineFile, Step};
use crate::process::step::StepRegistry;

pub(super) fn validate(f: &PipelineFile) -> Result<(), (String, String)> {
    validate_steps(&f.steps)?;
    neighbours_read(f)?;
    network_needs_connect(f)?;
    f.input
        .validate()
        .map_err(|(k, m)| (format!("input.{k}"), m))?;
    if f.output.path.trim().is_empty() {
        return Err((
            "output.path".into(),
            "give the output GeoPackage path".into(),
        ));
    }
    let plan = super::plan_of(&f.output, Some(&f.input), &f.steps);
    skeleton_layer_name(&f.output.layer, &plan).map_err(|m| ("output.layer".to_string(), m))?;
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
/// other layers — built-in or a registered step's, e.g. `labels` with a
/// `label` step (SQLite compares table names without case) — and none of
/// the names GeoPackage and SQLite keep for themselves.
fn skeleton_layer_name(name: &str, plan: &crate::output::Plan) -> Result<(), String> {
    let lower = name.to_ascii_lowercase();
    if name.trim().is_empty() {
        return Err("give the skeleton layer a name, e.g. `skeletons`".into());
    }
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
pub(super) fn validate_steps(steps: &[Step]) -> Result<(), (String, String)> {
    let mut last: Option<(usize, &str)> = None;
    for (i, s) in steps.iter().enumerate() {
        let rank = step_rank(s);
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
                        order_of(steps).join(" → ")
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
    collapse_on_ma(steps)?;
    registered_checks(steps)
}

/// Each registered step's own [checks](crate::process::step::FeatureStep::check)
/// against the rest of the pipeline.
fn registered_checks(steps: &[Step]) -> Result<(), (String, String)> {
    let methods = steps
        .iter()
        .find_map(|s| match s {
            Step::Skeleton(p) => Some(p.methods.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let names: Vec<&str> = steps.iter().map(Step::name).collect();
    let context = crate::process::step::StepContext {
        methods: &methods,
        steps: &names,
    };
    for (i, s) in steps.iter().enumerate() {
        if let Step::Extra(e) = s {
            e.step.check(&context).map_err(|(k, m)| {
                let key = match k.is_empty() {
                    true => format!("steps[{i}].{}", e.entry.name),
                    false => format!("steps[{i}].{}.{k}", e.entry.name),
                };
                (key, m)
            })?;
        }
    }
    Ok(())
}

/// `collapse` cuts the polygon by the medial axis's inscribed discs and
/// draws the lines on the medial axis: MA must be among the skeleton
/// step's methods (a step that lists none runs MA alone with `collapse`,
/// see `config::parse`). Another method's lines are not centred on those
/// discs, so collapsed lines are always MA's, whichever `select` chooses
/// for the skeleton layer.
fn collapse_on_ma(steps: &[Step]) -> Result<(), (String, String)> {
    let collapses = steps.iter().any(|s| matches!(s, Step::Collapse(_)));
    let skeleton = steps.iter().enumerate().find_map(|(i, s)| match s {
        Step::Skeleton(p) => Some((i, p)),
        _ => None,
    });
    match skeleton {
        Some((i, p)) if collapses && !p.methods.contains(&crate::methods::MethodId::MA) => Err((
            format!("steps[{i}].skeleton.methods"),
            "`collapse` cuts the polygon where the medial axis's inscribed discs meet the collapse width and draws the medial axis: add MA to the list (or leave `methods` out: with `collapse` it is MA alone); other methods' lines are not centred on those discs, so their collapsed lines would cross the kept areas".into(),
        )),
        _ => Ok(()),
    }
}

/// The place of built-in step `name` in the order: twice its index in
/// [`Step::ORDER`], so that a registered step running after it sits
/// between it and the next.
fn builtin_rank(name: &str) -> Option<usize> {
    Step::ORDER.iter().position(|n| *n == name).map(|i| 2 * i)
}

/// The place of the step `name` in the order, built-in or registered.
pub(super) fn rank(name: &str, registry: &StepRegistry) -> Option<usize> {
    builtin_rank(name).or_else(|| {
        registry
            .get(name)
            .and_then(|e| builtin_rank(e.after))
            .map(|r| r + 1)
    })
}

/// The place of a parsed step in the order.
fn step_rank(s: &Step) -> usize {
    match s {
        Step::Extra(e) => builtin_rank(e.entry.after).map_or(0, |r| r + 1),
        s => builtin_rank(s.name()).unwrap_or(0),
    }
}

/// Every step name in the order, the registered ones after the step they
/// follow.
pub(super) fn step_names(registry: &StepRegistry) -> Vec<&'static str> {
    let mut names: Vec<(usize, &'static str)> = Step::ORDER
        .iter()
        .map(|n| (builtin_rank(n).unwrap_or(0), *n))
        .chain(
            registry
                .entries()
                .iter()
                .filter_map(|e| Some((rank(e.name, registry)?, e.name))),
        )
        .collect();
    names.sort_by_key(|(r, _)| *r);
    names.into_iter().map(|(_, n)| n).collect()
}

/// The step order as the pipeline's steps know it (its registered steps in
/// their places).
fn order_of(steps: &[Step]) -> Vec<&'static str> {
    let mut names: Vec<(usize, &'static str)> = Step::ORDER
        .iter()
        .map(|n| (builtin_rank(n).unwrap_or(0), *n))
        .chain(steps.iter().filter_map(|s| match s {
            Step::Extra(e) => Some((step_rank(s), e.entry.name)),
            _ => None,
        }))
        .collect();
    names.sort_by_key(|(r, _)| *r);
    names.into_iter().map(|(_, n)| n).collect()
}

/// A step that [reads](crate::process::step::Needs::neighbours) the
/// coverage of `input.neighbours` needs it, and `input.neighbours` needs a
/// step that reads it.
fn neighbours_read(f: &PipelineFile) -> Result<(), (String, String)> {
    let reader = f
        .steps
        .iter()
        .enumerate()
        .find(|(_, s)| s.needs().neighbours);
    match (reader, &f.input.neighbours) {
        (Some((i, s)), None) => Err((
            format!("steps[{i}].{}", s.name()),
            format!(
                "`{}` reads the units of a coverage: add `input.neighbours: {{ source: …, layer: … }}`",
                s.name()
            ),
        )),
        (None, Some(_)) => {
            let readers: Vec<String> = super::builtin_steps()
                .entries()
                .iter()
                .filter(|e| e.needs.neighbours)
                .map(|e| format!("`- {}: {{}}`", e.name))
                .collect();
            Err((
                "input.neighbours".into(),
                format!(
                    "`input.neighbours` is a coverage no step of the pipeline reads: add {} to the steps (a step that reads it), or remove it",
                    readers.join(" or ")
                ),
            ))
        }
        _ => Ok(()),
    }
}

/// `prune: {mode: network}` keeps the paths between the points where the
/// lines of `input.connect` meet each polygon: without the lines it has
/// nothing to keep.
fn network_needs_connect(f: &PipelineFile) -> Result<(), (String, String)> {
    let network = f.steps.iter().position(
        |s| matches!(s, Step::Prune(p) if p.mode == crate::graph::prune::PruneMode::Network),
    );
    match (network, &f.input.connect) {
        (Some(i), None) => Err((
            format!("steps[{i}].prune.mode"),
            crate::graph::prune::NETWORK_NEEDS_CONNECT.into(),
        )),
        _ => Ok(()),
    }
}
