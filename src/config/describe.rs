//! What a pipeline file may say: its JSON Schema (from the types and
//! their serde defaults) and `skeletonise methods`, the methods and every
//! step's options in words.

use super::PipelineFile;
use crate::process::step::StepRegistry;
use serde_json::{json, Value};

/// The JSON Schema of the pipeline file, with the registered steps every
/// pipeline file may use ([`super::builtin_steps`]).
pub fn json_schema() -> Value {
    json_schema_with(&super::builtin_steps())
}

/// The JSON Schema of the pipeline file with the registered steps of
/// `steps`: each a step of its own under `steps` (its options' schema from
/// its entry), placed after the step it runs after, as the file must list it.
pub fn json_schema_with(steps: &StepRegistry) -> Value {
    let mut schema = serde_json::to_value(schemars::schema_for!(PipelineFile)).unwrap_or_default();
    for e in steps.entries() {
        let mut own = serde_json::to_value((e.schema)()).unwrap_or_default();
        let mut renamed = Vec::new();
        if let Some(o) = own.as_object_mut() {
            o.remove("$schema");
            o.remove("title");
            if let Some(Value::Object(defs)) = o.remove("$defs") {
                for (name, def) in defs {
                    // A definition whose name a different one holds already
                    // is filed under the step's name.
                    let free = schema["$defs"].get(&name).is_none_or(|d| *d == def);
                    let to = if free {
                        name.clone()
                    } else {
                        format!("{}_{name}", e.name)
                    };
                    schema["$defs"][&to] = def;
                    renamed.push((name, to));
                }
            }
        }
        for (from, to) in renamed.iter().filter(|(f, t)| f != t) {
            let t = own
                .to_string()
                .replace(&format!("\"#/$defs/{from}\""), &format!("\"#/$defs/{to}\""));
            own = serde_json::from_str(&t).unwrap_or(own);
        }
        let def = format!("{}_options", e.name);
        schema["$defs"][&def] = own;
        let step = json!({
            "type": "object",
            "description": format!("{} (a registered step, after `{}`)", e.description, e.after),
            "properties": { e.name: { "$ref": format!("#/$defs/{def}") } },
            "required": [e.name],
            "additionalProperties": false,
        });
        if let Some(list) = schema["$defs"]["Step"]["oneOf"].as_array_mut() {
            let at = list
                .iter()
                .position(|s| s["properties"].get(e.after).is_some())
                .map_or(list.len(), |i| i + 1);
            list.insert(at, step);
        }
    }
    schema
}

/// `skeletonise methods`: the registered methods, then every step with its
/// options — their values and defaults taken from the same JSON Schema that
/// `skeletonise schema` prints (so from the types and their serde defaults).
pub fn describe(registry: &crate::methods::Registry) -> String {
    describe_with(registry, &super::builtin_steps())
}

/// [`describe`] with the registered steps of `steps` too.
pub fn describe_with(registry: &crate::methods::Registry, steps: &StepRegistry) -> String {
    use std::fmt::Write as _;
    let schema = json_schema_with(steps);
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

fn resolve<'a>(defs: &'a Value, v: &'a Value) -> &'a Value {
    match v["$ref"].as_str().and_then(|r| r.strip_prefix("#/$defs/")) {
        Some(name) => &defs[name],
        None => v,
    }
}

fn first_line(v: &Value) -> String {
    v.as_str()
        .unwrap_or_default()
        .split("\n\n")
        .next()
        .unwrap_or_default()
        .replace('\n', " ")
}

/// The values an option takes: its enumeration, or its type.
fn values(defs: &Value, prop: &Value) -> String {
    let t = resolve(defs, prop);
    let items = &t["items"];
    if let Some(list) = t["oneOf"].as_array() {
        let names: Vec<String> = list
            .iter()
            .map(|o| match (&o["const"], o["properties"].as_object()) {
                (Value::String(c), _) => c.clone(),
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
    // An option that may be left out (`Option<T>`): its alternatives.
    if let Some(list) = t["anyOf"].as_array() {
        let names: Vec<String> = list.iter().map(|o| values(defs, o)).collect();
        return names.join(" | ");
    }
    if let Some(keys) = t["properties"].as_object() {
        let keys: Vec<String> = keys.keys().map(|k| format!("{k}: …")).collect();
        return format!("{{{}}}", keys.join(", "));
    }
    match &t["type"] {
        Value::Array(types) => {
            let names: Vec<&str> = types.iter().filter_map(|x| x.as_str()).collect();
            names.join(" | ")
        }
        other => other.as_str().unwrap_or("value").to_string(),
    }
}

fn default_of(prop: &Value) -> String {
    match &prop["default"] {
        Value::Null => String::new(),
        d => format!(" (default {d})"),
    }
}
