//! What a pipeline file may say: its JSON Schema (from the types and
//! their serde defaults) and `skeletonise methods`, the methods and every
//! step's options in words.

use super::PipelineFile;

/// The JSON Schema of the pipeline file.
pub fn json_schema() -> serde_json::Value {
    serde_json::to_value(schemars::schema_for!(PipelineFile)).unwrap_or_default()
}

/// `skeletonise methods`: the registered methods, then every step with its
/// options — their values and defaults taken from the same JSON Schema that
/// `skeletonise schema` prints (so from the types and their serde defaults).
pub fn describe(registry: &crate::methods::Registry) -> String {
    describe_with(registry, &super::builtin_steps())
}

/// [`describe`] with the registered steps of `steps` too.
pub fn describe_with(
    registry: &crate::methods::Registry,
    steps: &crate::process::step::StepRegistry,
) -> String {
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
    for e in steps.entries() {
        let _ = writeln!(
            out,
            "  {:<9} {} (after `{}`)",
            e.name, e.description, e.after
        );
        for (key, meaning) in e.options {
            let _ = writeln!(out, "    {key:<16} {meaning}");
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
